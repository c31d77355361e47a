"""`fsw dump --force` replaces an existing `flight-N.log`, and docs/cli.md
promised "only when it is a link log": a file of the user's that happened
to have the name (notes, a CSV, a renamed export) was replaced all the
same, gone. Every flight's file is now checked before the first is
written: one that is not a link log is refused, `--force` or not, and
nothing is written; a flight log from an earlier dump is replaced with
`--force` as before."""

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


def _ground():
    p = plan(load_app(str(RIG / "logged.app"), Diagnostics()))
    t = 100
    recs = {0: start_record(p, 0, 1, t), 1: start_record(p, 1, 2, 5000),
            2: data_record(p, 2, 2, 5000, 20, [[b"\x02", (5000 + 20 * k).to_bytes(4, "little", signed=True),
                                                b"\x00\x00"] for k in range(3)])}
    return FakeGround(p, image(p, recs), head=3, seq=3, flight=2)


def test_a_file_of_the_users_is_never_replaced(tmp_path, monkeypatch):
    out = tmp_path / "d"
    out.mkdir()
    notes = out / "flight-2.log"
    notes.write_text("flight 2: the chute opened late\n")
    with fake_target(monkeypatch, _ground()):
        r = run_fsw("dump", str(RIG), "--port", "fake", "-o", str(out), "--all", "--force")
    assert r.code == 1, r.out + r.err
    assert notes.read_text() == "flight 2: the chute opened late\n"
    assert "not a flight log" in r.err and str(notes) in r.err, r.err
    assert not (out / "flight-1.log").exists()  # nothing written before every file was checked


def test_a_flight_log_is_replaced_with_force(tmp_path, monkeypatch):
    out = tmp_path / "d"
    with fake_target(monkeypatch, _ground()):
        assert run_fsw("dump", str(RIG), "--port", "fake", "-o", str(out)).code == 0
        r = run_fsw("dump", str(RIG), "--port", "fake", "-o", str(out))
        assert r.code == 1 and "exists" in r.err
        r = run_fsw("dump", str(RIG), "--port", "fake", "-o", str(out), "--force")
        assert r.code == 0, r.err
