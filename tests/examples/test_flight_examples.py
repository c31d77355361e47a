"""What every flight example holds (examples/rocket, examples/hpr): its
configs check clean with --strict; every state script passes in binary64,
in the Uno's binary32 and through the generated C++; and together the
scripts enter every state and take every transition of both machines."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES

# example -> the scripts it must have
EXPECTED = {
    "rocket": {"mission_flight.ss", "mission_backup.ss", "mission_pad.ss", "mission_continuity.ss", "nav.ss",
               "mission_high.ss", "mission_frozen.ss",
               "nav_spikes.ss"},
    "hpr": {"nav.ss", "mission_flight.ss", "mission_pad.ss", "mission_lockout.ss", "mission_backup.ss",
            "mission_stuck.ss", "mission_ballistic.ss", "nav_fault.ss"},
}
SCRIPTS = {name: sorted(p.name for p in (EXAMPLES / name).glob("*.ss")) for name in EXPECTED}
CASES = [(name, script) for name in EXPECTED for script in SCRIPTS[name]]


@pytest.mark.parametrize("example", EXPECTED)
def test_the_example_has_its_scripts(example):
    assert EXPECTED[example] <= set(SCRIPTS[example])


@pytest.mark.parametrize("example", EXPECTED)
def test_configs_check_clean(fsw, example):
    r = fsw("check", "--strict", str(EXAMPLES / example))
    assert r.code == 0, r.err
    assert "0 errors, 0 warnings" in r.err


@pytest.mark.parametrize("mode", [(), ("--board", "uno"), ("--native", "--board", "uno")],
                         ids=["f64", "uno", "native-uno"])
@pytest.mark.parametrize("example, script", CASES, ids=[f"{e}/{s}" for e, s in CASES])
def test_script_passes(fsw, example, script, mode):
    r = fsw("test", str(EXAMPLES / example / script), *mode)
    assert r.code == 0, r.out + r.err
    assert "assertion failed" not in r.out and " 0 asserts passed" not in r.out


@pytest.mark.parametrize("example", EXPECTED)
def test_scripts_cover_every_state_and_transition(fsw, example):
    r = fsw("test", "--coverage", str(EXAMPLES / example))
    assert r.code == 0, r.out + r.err
    transitions = {"rocket": 16, "hpr": 15}[example]  # the rocket's: and its disarming on an open igniter
    assert f"coverage of mission.sm: 10/10 states, {transitions}/{transitions} transitions" in r.out
    assert "coverage of nav.sm: 1/1 states, 0/0 transitions" in r.out
    n = len(SCRIPTS[example])
    assert f"{n} scripts: {n} passed, 0 failed" in r.out
