"""A record damaged in the middle of a flight (its CRC fails: a bad
EEPROM cell, a flash bit gone, or a slot written while it was read) was
left out of the dumped flight without a word: `fsw dump` said "flight 1:
42 samples, 0.10–1.20 s" over a 0.28 s hole. Records are numbered one
more each, across flights, so a hole in the numbers is a lost record:
the dump now says how many records a flight lost and between which
times, and still writes the samples it has."""

from __future__ import annotations

import sys
from pathlib import Path

from conftest import run_fsw

from fswkit.autocode.app import load_app
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.recorder import decode, plan

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from support.recorder_image import FakeGround, data_record, fake_target, image, start_record  # noqa: E402

RIG = Path(__file__).resolve().parent.parent / "recorder" / "logged"


def _plan():
    return plan(load_app(str(RIG / "logged.app"), Diagnostics()))


def _sample(t: int) -> list[bytes]:
    """The rig's sample at t ms: Run, the level t / 4 in counts of 0.25, the count."""
    return [b"\x02", (t // 4 * 4).to_bytes(4, "little", signed=True), (t // 10).to_bytes(2, "little")]


def _flight(p, seq: int, number: int, t0: int, records: int) -> list[bytes]:
    out = [start_record(p, seq, number, t0)]
    for i in range(records):
        t = t0 + i * 280
        out.append(data_record(p, seq + 1 + i, number, t, 20, [_sample(t + 20 * k) for k in range(14)]))
    return out


def _damaged(raw: bytes) -> bytes:
    return raw[:5] + bytes((raw[5] ^ 0x40,)) + raw[6:]  # in t0: the CRC fails


def test_decode_counts_the_records_a_flight_lost():
    p = _plan()
    recs = _flight(p, 0, 1, 100, 4)
    recs[2] = _damaged(recs[2])  # the flight's second record of samples: 0.38 .. 0.64 s
    flights, _ = decode(p, image(p, dict(enumerate(recs))))
    (f,) = flights
    assert [(n, a, b) for n, a, b in f.lost] == [(1, 360, 660)]
    clean, _ = decode(p, image(p, dict(enumerate(_flight(p, 0, 1, 100, 4)))))
    assert clean[0].lost == []


def test_dump_says_the_lost_record_and_writes_the_rest(tmp_path, monkeypatch):
    p = _plan()
    recs = _flight(p, 0, 1, 100, 4)
    recs[2] = _damaged(recs[2])
    with fake_target(monkeypatch, FakeGround(p, image(p, dict(enumerate(recs))), head=5, seq=5)):
        r = run_fsw("dump", str(RIG), "--port", "fake", "-o", str(tmp_path / "d"))
    assert r.code == 0, r.err
    assert "flight 1: 42 samples" in r.out
    assert "1 record lost between 0.36 s and 0.66 s" in r.out, r.out
    assert (tmp_path / "d" / "flight-1.log").exists()


def test_a_record_lost_between_two_flights_is_said_too(tmp_path, monkeypatch):
    """The second flight's start record damaged: the record before its
    samples is missing (not overwritten: the store never filled)."""
    p = _plan()
    recs = _flight(p, 0, 1, 100, 1) + _flight(p, 2, 2, 5000, 2)
    recs[2] = _damaged(recs[2])
    with fake_target(monkeypatch, FakeGround(p, image(p, dict(enumerate(recs))), head=5, seq=5, flight=2)):
        r = run_fsw("dump", str(RIG), "--port", "fake", "-o", str(tmp_path / "d"))
    assert r.code == 0, r.err
    assert "flight 2:" in r.out and "1 record lost before 5.00 s" in r.out, r.out
    assert "start record overwritten" not in r.out
