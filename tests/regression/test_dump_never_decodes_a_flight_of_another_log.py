"""The firmware keeps every record whose CRC holds across a re-flash, so a
store can hold flights recorded with another `[log]` (other elements or
encodings, the same record size) before the flights of the firmware on
the board. `fsw dump` decoded those with this project's layout: numbers
that were never recorded, written as flight-N.log without a word (or, when
a record did not parse, the whole dump refused, the good flights too).
Each flight's start record carries the log hash it was recorded with:
a flight of another log is now said and not decoded, the others are
dumped, the status is 1 when a flight asked for was not written, and
`--erase` is refused while such a flight is on the target."""

from __future__ import annotations

import sys
from pathlib import Path

from conftest import run_fsw

from fswkit.autocode.app import load_app
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.recorder import decode, plan

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from support.recorder_image import FakeGround, data_record, fake_target, image, seal, start_record  # noqa: E402

RIG = Path(__file__).resolve().parent.parent / "recorder" / "logged"
OTHER = 0x12345678


def _plan():
    return plan(load_app(str(RIG / "logged.app"), Diagnostics()))


def _sample(t: int) -> list[bytes]:
    return [b"\x02", (t // 4 * 4).to_bytes(4, "little", signed=True), (t // 10).to_bytes(2, "little")]


def _flight(p, seq: int, number: int, t0: int, records: int, log_hash=None) -> list[bytes]:
    out = [start_record(p, seq, number, t0, log_hash)]
    for i in range(records):
        t = t0 + i * 280
        out.append(data_record(p, seq + 1 + i, number, t, 20, [_sample(t + 20 * k) for k in range(14)]))
    return out


def _store(p) -> bytes:
    recs = _flight(p, 0, 1, 100, 2, OTHER) + _flight(p, 3, 2, 5000, 2)
    return image(p, dict(enumerate(recs)))


def test_decode_marks_the_flight_of_another_log_and_decodes_none_of_it():
    p = _plan()
    flights, _ = decode(p, _store(p))
    assert [f.number for f in flights] == [1, 2]
    assert flights[0].foreign == OTHER and flights[0].samples == []
    assert flights[1].foreign is None and len(flights[1].samples) == 28


def test_a_record_of_another_log_that_does_not_parse_refuses_only_its_flight():
    p = _plan()
    recs = _flight(p, 0, 1, 100, 2, OTHER) + _flight(p, 3, 2, 5000, 2)
    recs[1] = seal(p, recs[1][:9], 20)  # a record this layout cannot parse (no whole first sample)
    flights, _ = decode(p, image(p, dict(enumerate(recs))))  # no RecordError: it is not this log's record
    assert [f.foreign for f in flights] == [OTHER, None]


def test_dump_all_says_it_and_writes_only_this_logs_flights(tmp_path, monkeypatch):
    p = _plan()
    out = tmp_path / "d"
    with fake_target(monkeypatch, FakeGround(p, _store(p), head=6, seq=6, flight=2)):
        r = run_fsw("dump", str(RIG), "--port", "fake", "-o", str(out), "--all")
    assert r.code == 1, r.out + r.err
    assert f"log hash {OTHER:08x}" in r.err and "flight 1" in r.err, r.err
    assert not (out / "flight-1.log").exists()
    assert (out / "flight-2.log").exists() and "flight 2: 28 samples" in r.out


def test_the_newest_flight_alone_is_dumped_with_status_0(tmp_path, monkeypatch):
    p = _plan()
    with fake_target(monkeypatch, FakeGround(p, _store(p), head=6, seq=6, flight=2)):
        r = run_fsw("dump", str(RIG), "--port", "fake", "-o", str(tmp_path / "d"))
    assert r.code == 0, r.err
    assert (tmp_path / "d" / "flight-2.log").exists()


def test_erase_is_refused_while_a_flight_of_another_log_is_on_the_target(tmp_path, monkeypatch):
    p = _plan()
    g = FakeGround(p, _store(p), head=6, seq=6, flight=2)
    with fake_target(monkeypatch, g):
        r = run_fsw("dump", str(RIG), "--port", "fake", "-o", str(tmp_path / "d"), "--all", "--erase", "--yes")
    assert r.code == 1 and not g.erased, r.out + r.err
    assert "not erased" in r.err or "erase" in r.err


def test_a_delta_past_the_32_bit_count_is_no_record_of_this_log():
    """The firmware's counts are i32; a record whose deltas run past them
    (one written by another layout, whose bytes happen to parse) was an
    OverflowError out of the decoder."""
    from fswkit.autocode.recorder import RecordError

    p = _plan()
    top = (2**31 - 1).to_bytes(4, "little", signed=True)
    over = [[b"\x02", top, b"\x00\x00"], [b"\x02", top, b"\x00\x00"]]
    raw = bytearray(data_record(p, 1, 1, 100, 20, over))
    raw[15] = 1  # the second sample's delta: +1 count, past 2**31 - 1
    raw = seal(p, bytes(raw[:raw[p.record - 3]]), 20)
    try:
        decode(p, image(p, {0: start_record(p, 0, 1, 100), 1: raw}))
    except RecordError as e:
        assert "record 1" in str(e)
    else:
        raise AssertionError("a delta past the 32-bit count was decoded")


def test_the_simulators_record_check_takes_only_this_logs_flights():
    """`fsw sim -E FILE` keeps the EEPROM between runs: a run that recorded
    nothing found the earlier [log]'s flight the newest and checked it."""
    from types import SimpleNamespace

    from fswkit.recorder.check import newest_flight

    app = load_app(str(RIG / "logged.app"), Diagnostics())
    p = plan(app)
    store = image(p, dict(enumerate(_flight(p, 0, 1, 100, 2) + _flight(p, 3, 2, 5000, 2, OTHER))))
    _, flight, flights, _ = newest_flight(app, SimpleNamespace(eeprom=bytes(p.base) + store))
    assert len(flights) == 2 and flight is flights[0] and flight.number == 1
