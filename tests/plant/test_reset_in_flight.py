"""Resets of the MCU during closed-loop runs (fswkit.plant.cosim): at a
simulated second (`reset_at`, a study's brown-out) or at a phase of the
flight (`reset_state`, `reset_after_s`, `reset_cause` in plant.toml's
[scenario] or set from Python). Each reset is recorded with its time,
cause and the state telemetry showed before it, and the telemetry decoder
finds the new boot's time base whether the firmware's clock started again
or went on.

The keys are checked on plant.toml copies; the decoder's time base on its
own; three short flights of examples/rocket's firmware (about 15 simulated
seconds in all) check the resets end to end."""

from __future__ import annotations

import os
import re
import shutil
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from conftest import EXAMPLES
from fswkit.plant.cosim import CosimError, ResetEvent, Run, Telemetry, _reset_plan
from fswkit.plant.run import SetupError, prepare

ROCKET, TANK = EXAMPLES / "rocket", EXAMPLES / "tank"
FLAGS = {"power": 0x01, "external": 0x02, "brownout": 0x04, "watchdog": 0x08}


def _with_scenario_keys(tmp_path: Path, project: Path, keys: str) -> Path:
    """The project's plant.toml with `keys` at the top of its [scenario] table."""
    text = (project / "plant.toml").read_text()
    text = re.sub(r"^\[scenario\][^\n]*\n", lambda m: m.group(0) + keys + "\n", text, count=1, flags=re.M)
    path = tmp_path / "plant.toml"
    path.write_text(text)
    return path


def _line(path: Path, key: str) -> int:
    return next(i for i, line in enumerate(path.read_text().splitlines(), 1) if line.startswith(key))


def test_the_keys_default_to_no_reset():
    _app, _layout, sc = prepare(str(ROCKET), "rocket", seed=1)
    assert (sc.reset_state, sc.reset_after_s, sc.reset_cause) == (None, 0.2, "brownout")
    assert getattr(sc, "reset_at", None) is None


@pytest.mark.parametrize("project", [ROCKET, TANK])
def test_the_keys_are_read(tmp_path, project):
    state = "Coast" if project == ROCKET else "Abort"
    params = _with_scenario_keys(tmp_path, project, f'reset_state = "{state}"\nreset_after_s = 0.5\n'
                                                    'reset_cause = "watchdog"')
    _app, _layout, sc = prepare(str(project), project.name, seed=1, params=str(params))
    assert (sc.reset_state, sc.reset_after_s, sc.reset_cause) == (state, 0.5, "watchdog")


@pytest.mark.parametrize("keys, key, message", [
    ('reset_state = "Orbit"', "reset_state", "[scenario] reset_state: machine `mission` has no state `Orbit` "
                                              "(its states: Safe, Armed, Boost, "),
    ('reset_state = "Coast"\nreset_cause = "lightning"', "reset_cause",
     "[scenario] reset_cause: `lightning` is not a reset cause (one of brownout, watchdog, external, power)"),
    ("reset_after_s = 1.0", "reset_after_s", "[scenario] reset_after_s: needs reset_state"),
    ('reset_cause = "power"', "reset_cause", "[scenario] reset_cause: needs reset_state"),
    ('reset_state = "Coast"\nreset_after_s = -1', "reset_after_s",
     "[scenario] reset_after_s: -1 is out of range (0 to 3600)"),
])
def test_bad_keys_are_located(tmp_path, keys, key, message):
    params = _with_scenario_keys(tmp_path, ROCKET, keys)
    with pytest.raises(SetupError) as e:
        prepare(str(ROCKET), "rocket", seed=1, params=str(params))
    assert f"{params}:{_line(params, key)}: {message}" in str(e.value), str(e.value)


def test_a_scenario_set_from_python_is_checked():
    _app, layout, sc = prepare(str(ROCKET), "rocket", seed=1)
    tm = Telemetry(Run(columns=()), layout, sc.state_element, None)
    sc.reset_state = "Coast"
    assert _reset_plan(sc, tm) == (None, "brownout", "Coast", "brownout", 0.2)
    sc.reset_state = "Orbit"
    with pytest.raises(CosimError, match="reset_state `Orbit`: telemetry's `state` has no such state"):
        _reset_plan(sc, tm)
    sc.reset_state, sc.reset_cause = "Coast", "lightning"
    with pytest.raises(CosimError, match="reset cause `lightning`: one of brownout, watchdog, external, power"):
        _reset_plan(sc, tm)


def test_the_new_boots_time_base():
    """The first frame after a reset at 10 s, read by 10.002 s: a clock that
    started again reads about 0, one that went on about 10 (a little less
    if it lost time across the reset); anything else is timed at arrival."""
    _app, layout, sc = prepare(str(ROCKET), "rocket", seed=1)
    tm = Telemetry(Run(columns=()), layout, sc.state_element, None)
    for fw_s, offset in ((0.001, -10.0), (10.001, 0.0), (9.6, 0.0), (500.0, 500.0 - 10.002), (8.5, 8.5 - 10.002)):
        tm.offset = 0.0
        tm.restarted(10.0)
        tm._rebase(fw_s, 10.002)
        assert tm.offset == pytest.approx(offset) and tm.reset_t is None, fw_s
    # a second reset, the clock having started again at the first: offsets add up
    tm.offset = -10.0
    tm.restarted(20.0)
    tm._rebase(0.001, 20.002)
    assert tm.offset == -20.0
    tm.restarted(30.0)
    tm._rebase(10.001, 30.002)  # this time it went on (10 s since it started again)
    assert tm.offset == -20.0


needs_board = pytest.mark.skipif(shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                 reason="gcc-avr and libsimavr-dev are needed (make setup)")


@pytest.fixture(scope="module")
def flights():
    from fswkit.plant.cosim import fly
    from support.simfw import kept_sim

    project = ROCKET  # its igniters' continuity driven intact by its plant
    elf, board = kept_sim(project)  # built into build/sim-tests/, once for every test file

    def flight(max_s, **attrs):
        _app, layout, sc = prepare(str(project), "rocket", seed=1)
        sc.max_s = max_s
        for k, v in attrs.items():
            setattr(sc, k, v)
        return sc, fly(sc, elf, board, layout)

    jobs = {"coast": (7.0, dict(reset_state="Coast", reset_after_s=0.2, reset_cause="brownout")),
            "armed-power": (3.5, dict(reset_state="Armed", reset_after_s=0.5, reset_cause="power")),
            "at": (3.0, dict(reset_at=2.0))}
    with ThreadPoolExecutor(2) as pool:
        futures = {k: pool.submit(flight, m, **a) for k, (m, a) in jobs.items()}
        return {k: f.result() for k, f in futures.items()}


def _said_why(run, cause: str) -> None:
    """The new boot's hello gave the reset's cause (MCUSR in its low bits;
    the firmware's own above): the link starts each boot with a delimiter,
    so a frame the reset cut short does not take the hello down with it."""
    assert run.session.stats.restarts == 1
    assert run.session.hello["reset_cause"] & 0x0F == FLAGS[cause]


def _after(run, t):
    return [(tt, row) for tt, row in run.samples if tt >= t]


@needs_board
def test_a_reset_at_a_phase_of_the_flight(flights):
    sc, run = flights["coast"]
    coast = next(t for t, _, n in run.transitions if n == "Coast")
    [ev] = run.reset_events
    assert run.resets == [ev.t]
    assert (ev.cause, ev.state, ev.trigger) == ("brownout", "Coast", "state")
    assert coast + 0.2 <= ev.t <= coast + 0.2 + 0.001  # at the first plant step from then
    _said_why(run, "brownout")
    # telemetry after the reset is timed after it, in order, whatever the firmware's clock did
    after = [t for t, row in _after(run, ev.t) if "state" in row]  # one stream's samples, in its order
    assert after and after[0] <= ev.t + 0.1
    assert all(0.015 <= b - a <= 0.025 for a, b in zip(after, after[1:]))  # 50 Hz on
    assert max(t for t, _ in run.samples) <= run.sim_s + 1e-9


@needs_board
def test_a_power_on_reset_starts_the_firmware_afresh(flights):
    sc, run = flights["armed-power"]
    [ev] = run.reset_events
    armed = next(t for t, _, n in run.transitions if n == "Armed")
    assert (ev.cause, ev.state, ev.trigger) == ("power", "Armed", "state")
    assert armed + 0.5 <= ev.t <= armed + 0.501
    _said_why(run, "power")
    # nothing in RAM survives: the machine starts in Safe again, its clock from 0, timed from the reset
    t_safe, _, name = next(x for x in run.transitions if x[0] >= ev.t)
    assert name == "Safe" and ev.t <= t_safe <= ev.t + 0.05
    after = _after(run, ev.t)
    # (the `time` element is G as the executor's cycle began; a frame is stamped a little later)
    bad = [(t, row["time"]) for t, row in after if "time" in row and not 0 <= t - (row["time"] / 1000 + ev.t) <= 0.002]
    assert after and not bad, bad[:5]


@needs_board
def test_reset_at_is_a_brownout(flights):
    sc, run = flights["at"]
    assert run.resets == [2.0]
    assert run.reset_events == [ResetEvent(2.0, "brownout", "Armed", "time")]
    _said_why(run, "brownout")
    after = [t for t, row in _after(run, 2.0) if "state" in row]
    assert after and 2.0 < after[0] <= 2.1 and all(0.015 <= b - a <= 0.025 for a, b in zip(after, after[1:]))
