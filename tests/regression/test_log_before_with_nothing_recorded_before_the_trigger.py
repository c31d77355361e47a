"""`before 0.5` keeps the half second before the trigger out of the
samples taken in the states that lead to it; with those states at rate 0
(`rate 50 Run` and no other `rate` line) nothing is ever taken there, and
every flight began at its trigger with no word: `fsw check` said "0
errors, 0 warnings". It is now a warning at `before` naming the states
(`fsw check --strict` fails on it)."""

from __future__ import annotations

import shutil

from conftest import ROOT, run_fsw

RIG = ROOT / "tests" / "recorder" / "logged"


def _project(tmp_path, rates: str):
    proj = tmp_path / "p"
    shutil.copytree(RIG, proj)
    app = (proj / "logged.app").read_text()
    log = (f"[log]\nstore eeprom\nmachine logged\ntrigger Run\nbefore 0.5\n{rates}"
           "element level delta=0.25\nelement count\n")
    (proj / "logged.app").write_text(app[:app.index("[log]")] + log)
    return proj / "logged.app"


def test_before_with_the_states_before_the_trigger_at_rate_0_is_a_warning(tmp_path):
    app = _project(tmp_path, "rate 50 Run\n")
    r = run_fsw("check", str(app))
    text = r.out + r.err
    assert r.code == 0 and "1 warning" in text, text
    assert "logged.app:29:8" in text and "Idle" in text and "rate 0" in text, text
    assert run_fsw("check", "--strict", str(app)).code != 0


def test_before_with_a_rate_before_the_trigger_is_quiet(tmp_path):
    r = run_fsw("check", str(_project(tmp_path, "rate 50\nrate 0 Done\n")))
    assert r.code == 0 and "0 warnings" in r.out + r.err, r.out + r.err
