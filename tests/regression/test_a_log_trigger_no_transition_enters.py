"""The flight recorder starts a flight when its machine enters the
`trigger` state (fsw_log.cpp: the state differs from the last run's). A
`[log]` whose trigger no transition enters passed `fsw check` in silence,
and the firmware never recorded: examples/hpr with `trigger Orphan`, a
state no transition leads to, or with `trigger` on the machine's first
state when nothing leads back to it (the machine starts there at boot,
which is no entering). The check now warns at the trigger (`fsw check
--strict` fails on it); a trigger some transition enters, the first
state's included, is not warned about."""

from __future__ import annotations

import shutil

import pytest

from conftest import EXAMPLES


def hpr(tmp_path, trigger: str, machine_tail: str = "", rates: str | None = None):
    shutil.copytree(EXAMPLES / "hpr", tmp_path / "hpr")
    d = tmp_path / "hpr"
    (d / "mission.sm").write_text((d / "mission.sm").read_text() + machine_tail)
    app = d / "hpr.app"
    text = app.read_text()
    old = "trigger Boost          # launch starts a flight ..."
    assert old in text
    text = text.replace(old, f"trigger {trigger}")
    if rates is not None:
        assert "rate    0 Safe Landed Abort" in text
        text = text.replace("rate    0 Safe Landed Abort", rates)
    app.write_text(text)
    return app


ORPHAN = "\n[Orphan]\n.step\n    T >= 1000: -> Descent\n"


def test_a_trigger_no_transition_leads_to_is_warned_about(fsw, tmp_path):
    app = hpr(tmp_path, "Orphan", ORPHAN)
    r = fsw("check", str(app))
    assert r.code == 0, r.err
    assert "hpr.app:43:9:" in r.err and "application config warning" in r.err
    assert "the trigger state `Orphan` is never entered: no transition that can run from the machine's first " \
           "state (`Safe`) leads to it, so the recorder never starts a flight" in r.err
    assert fsw("check", "--strict", str(app)).code != 0


def test_a_trigger_behind_a_constant_false_guard_is_warned_about(fsw, tmp_path):
    app = hpr(tmp_path, "Orphan", ORPHAN)
    sm = app.parent / "mission.sm"
    text = sm.read_text()
    old = "    abortCmd: -> Abort\n    armSwitch: -> Armed\n"
    assert old in text
    sm.write_text(text.replace(old, old + "    1 < 0: -> Orphan\n", 1))
    r = fsw("check", str(app))
    assert r.code == 0, r.err
    assert "the trigger state `Orphan` is never entered" in r.err


def test_the_first_state_as_trigger_warns_only_when_nothing_leads_back(fsw, tmp_path):
    # Safe is entered again from Armed and from Abort: a trigger there records
    r = fsw("check", str(hpr(tmp_path / "a", "Safe", rates="rate    0 Landed Abort")))
    assert r.code == 0 and "never entered" not in r.err, r.err
    # the tank's controller never returns to its first state
    shutil.copytree(EXAMPLES / "tank", tmp_path / "tank")
    app = tmp_path / "tank" / "tank.app"
    sm = (tmp_path / "tank" / "tank.sm").read_text()
    first = next(line[1:-1] for line in sm.splitlines() if line.startswith("[") and line != "[state_vector]"
                 and line not in ("[local]", "[parameters]"))
    if f"-> {first}" in sm:
        pytest.skip(f"the tank's first state `{first}` is entered again")
    text = app.read_text().replace("[tasks]\n", "[tasks]\nrec recorder rate=10\n", 1)
    app.write_text(text + f"\n[log]\nstore eeprom\nmachine tank\ntrigger {first}\nrate 1\nelement tankPressure\n")
    r = fsw("check", str(app))
    assert r.code == 0, r.err
    assert f"the trigger state `{first}` is never entered: it is the machine's first state, where it starts at " \
           "boot, and no transition leads back to it" in r.err


def test_the_examples_triggers_are_entered(fsw):
    for name in ("hpr", "rocket"):
        r = fsw("check", "--strict", str(EXAMPLES / name / f"{name}.app"))
        assert r.code == 0, r.err
