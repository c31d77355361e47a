"""The rocket example's state scripts as `fsw test` reports them: one
script's coverage names what it misses, several scripts fail together, and
option conflicts are refused (what every flight example holds is in
test_flight_examples.py)."""

from __future__ import annotations

from conftest import EXAMPLES

ROCKET = EXAMPLES / "rocket"


def test_coverage_names_what_one_script_misses(fsw):
    r = fsw("test", "--coverage", str(ROCKET / "mission_flight.ss"))
    assert r.code == 1
    assert "coverage of mission.sm: 9/10 states, 9/16 transitions" in r.out
    assert "mission.sm:138: state Abort never entered" in r.out
    assert "transition Safe -> Abort never taken" in r.out
    assert "transition Coast -> Apogee never taken" in r.out  # the backup timer's
    assert "mission.sm:116:41: transition Drogue -> Main never taken" in r.out  # and the main's
    # one report, unchanged, for one script
    assert r.out.startswith("state script ran for 4349 steps\n")


def test_several_scripts_fail_together(fsw, tmp_path):
    bad = tmp_path / "mission_bad.ss"
    bad.write_text("[options]\ndelta_t 10\n\n[all_states]\ntrue: @assert drogue\nG == 100: @stop\n")
    for name in ("mission.sm", "rocket.sv"):
        (tmp_path / name).write_text((ROCKET / name).read_text())
    r = fsw("test", str(ROCKET / "mission_pad.ss"), str(bad))
    assert r.code == 1
    assert f"== {bad}" in r.out and "assertion failed" in r.out
    assert "2 scripts: 1 passed, 1 failed" in r.out


def test_coverage_refuses_native_and_trace_needs_one_script(fsw, tmp_path):
    r = fsw("test", "--coverage", "--native", str(ROCKET / "nav.ss"))
    assert r.code == 2 and "--coverage" in r.err
    r = fsw("test", "--trace", str(tmp_path / "t.csv"), str(ROCKET))
    assert r.code == 2 and "one script" in r.err
    empty = tmp_path / "empty"
    empty.mkdir()
    r = fsw("test", str(empty))
    assert r.code == 2 and "no state scripts" in r.err
