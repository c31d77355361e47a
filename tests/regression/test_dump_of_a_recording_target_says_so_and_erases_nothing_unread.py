"""`fsw dump` of a target still recording: the records are read one by
one while the firmware writes more, so the dump has the flight up to
some moment, and records written after their slot was read are not in
it. The dump said nothing of this (the flight's line read as a whole
flight), and with `--erase` a flight that ended during the read was
erased with its last records never read. LOG_INFO is now asked again
after the read and before erasing: a flight still recorded is said on
its line, records written during the read are said, and `--erase` is
refused when the target wrote records the dump did not read."""

from __future__ import annotations

import sys
from pathlib import Path

from conftest import run_fsw

from fswkit.autocode.app import load_app
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.recorder import plan

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from support.recorder_image import FakeGround, data_record, fake_target, image, start_record  # noqa: E402

RIG = Path(__file__).resolve().parent.parent / "recorder" / "logged"


def _sample(t: int) -> list[bytes]:
    return [b"\x02", (t // 4 * 4).to_bytes(4, "little", signed=True), (t // 10).to_bytes(2, "little")]


def _rec(p, seq: int, t: int) -> bytes:
    return data_record(p, seq, 1, t, 20, [_sample(t + 20 * k) for k in range(14)])


def _target(p, end_mode: int):
    """Flight 1 recording: a start and two records; while the dump reads
    slot 5 the firmware seals a third record in slot 3 (already read) and
    is in `end_mode` after."""
    recs = {0: start_record(p, 0, 1, 100), 1: _rec(p, 1, 100), 2: _rec(p, 2, 380)}

    def write_more(g, slot):
        if slot == 5 and g.seq == 3:
            g.store[3 * p.record:4 * p.record] = _rec(p, 3, 660)
            g.seq, g.head, g.mode = 4, 4, end_mode

    return FakeGround(p, image(p, recs), mode=1, head=3, seq=3, on_read=write_more)


def test_a_flight_still_recorded_is_said(tmp_path, monkeypatch):
    p = plan(load_app(str(RIG / "logged.app"), Diagnostics()))
    with fake_target(monkeypatch, _target(p, end_mode=1)):
        r = run_fsw("dump", str(RIG), "--port", "fake", "-o", str(tmp_path / "d"))
    assert r.code == 0, r.err
    line = next(x for x in r.out.splitlines() if x.startswith("flight 1:"))
    assert "still being recorded" in line, r.out
    assert "1 record was written while the records were read" in r.err, r.err


def test_erase_is_refused_when_records_came_after_the_read(tmp_path, monkeypatch):
    p = plan(load_app(str(RIG / "logged.app"), Diagnostics()))
    g = _target(p, end_mode=0)  # the flight ended during the read: the firmware would accept the erase
    with fake_target(monkeypatch, g):
        r = run_fsw("dump", str(RIG), "--port", "fake", "-o", str(tmp_path / "d"), "--erase", "--yes")
    assert r.code == 1, r.out + r.err
    assert not g.erased
    assert "dump again" in r.err, r.err


def test_a_quiet_target_is_dumped_and_erased_as_before(tmp_path, monkeypatch):
    p = plan(load_app(str(RIG / "logged.app"), Diagnostics()))
    recs = {0: start_record(p, 0, 1, 100), 1: _rec(p, 1, 100), 2: _rec(p, 2, 380)}
    g = FakeGround(p, image(p, recs), mode=0, head=3, seq=3)
    with fake_target(monkeypatch, g):
        r = run_fsw("dump", str(RIG), "--port", "fake", "-o", str(tmp_path / "d"), "--erase", "--yes")
    assert r.code == 0 and g.erased, r.out + r.err
    assert "still being recorded" not in r.out and "while the records were read" not in r.err


def test_a_flight_begun_with_no_record_written_yet_is_said(tmp_path, monkeypatch):
    """Flight 2 has just started (its `before` seconds still in RAM): the
    store holds flight 1 alone, which is not the flight being recorded."""
    p = plan(load_app(str(RIG / "logged.app"), Diagnostics()))
    recs = {0: start_record(p, 0, 1, 100), 1: _rec(p, 1, 100)}
    with fake_target(monkeypatch, FakeGround(p, image(p, recs), mode=1, flight=2, head=2, seq=2)):
        r = run_fsw("dump", str(RIG), "--port", "fake", "-o", str(tmp_path / "d"))
    assert r.code == 0, r.err
    assert "flight 2 is being recorded" in r.err and "still being recorded" not in r.out, r.out + r.err
