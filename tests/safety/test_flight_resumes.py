"""A reset in flight, closed loop (docs/safety.md, "A reset in flight" and
"Continuity"): examples/rocket's real firmware on the simulated Uno, its
plant flying it, the MCU reset once in each phase of the flight.

After a brown-out on the pad, in boost, in coast, under the drogue and
under the main, and after a watchdog reset in coast and one in the first
50 ms of the drogue's pulse, the firmware must be back in the phase it
was in within 100 ms simulated, go on through the same sequence of states
(never back to the pad), fire each charge exactly once over the flight and
none before liftoff, pass every check of the flight, say that it resumed
(the hello's reset cause: the MCU's cause + 0x80), and keep recording the
same flight (a second start record of the same flight number). A
power-on reset on the pad starts afresh. A broken igniter is reported
(the health frame: continuity OPEN) before arming, and the machine refuses
to arm: nothing fires, the vehicle never leaves the pad.

Nine flights, two at a time, on one build of the firmware."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES
from support.closed_loop import build_project, fly_all, needs_avr_sim

pytestmark = [needs_avr_sim, pytest.mark.costly(11)]

ROCKET = EXAMPLES / "rocket"
SEQUENCE = ["Safe", "Armed", "Boost", "Coast", "Apogee", "Drogue", "Main", "Descent", "Landed"]
CAUSE = {"brownout": 0x04, "watchdog": 0x08, "power": 0x01}
RESUMED = 0x80

# name: (state, seconds after telemetry first showed it, cause)
RESETS = {
    "pad": ("Armed", 0.5, "brownout"),
    "boost": ("Boost", 0.3, "brownout"),
    "coast": ("Coast", 1.0, "brownout"),
    "coast-watchdog": ("Coast", 2.0, "watchdog"),
    "drogue-pulse": ("Apogee", 0.05, "brownout"),  # the drogue's pin high: the pulse is cut, not restarted
    "under-drogue": ("Drogue", 2.0, "brownout"),
    "under-main": ("Descent", 2.0, "brownout"),
}


@pytest.fixture(scope="module")
def flights(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("resumes")
    short = tmp / "short-hold.toml"
    text = (ROCKET / "plant.toml").read_text()
    assert "hold_s     = 20" in text
    short.write_text(text.replace("hold_s     = 20", "hold_s     = 4"))
    jobs = {name: {"reset": spec} for name, spec in RESETS.items()}
    jobs["pad-power"] = {"reset": ("Armed", 0.5, "power")}
    jobs["open-igniter"] = {"fault": "open-igniter", "params": str(short)}
    return fly_all(ROCKET, build_project(ROCKET), jobs)


def _states(run) -> list[str]:
    """The mission machine's states as telemetry showed them, each once in a row."""
    out = []
    for _, _, name in run.transitions:
        if not out or out[-1] != name:
            out.append(name)
    return out


def _rises(run, role: str) -> list[float]:
    return [e.t for e in run.pin_events if e.role == role and e.level]


@pytest.mark.parametrize("name", list(RESETS))
def test_the_flight_resumes_in_its_phase(flights, name):
    state, after, cause = RESETS[name]
    _app, flight = flights[name]
    run = flight.run
    [ev] = run.reset_events
    assert (ev.state, ev.cause) == (state, cause)
    # back in the same phase within 100 ms simulated, as telemetry shows it
    first = next((t, row["state"]) for t, row in run.samples if t > ev.t and "state" in row)
    assert first[0] <= ev.t + 0.1, first
    assert run.session.layout.show("state", first[1]).endswith(f"({state})"), first
    # the same flight, never back on the pad
    assert _states(run) == SEQUENCE, _states(run)
    # the new boot said why, and that it resumed
    assert run.session.stats.restarts == 1
    assert run.session.hello["reset_cause"] == CAUSE[cause] | RESUMED
    # each charge exactly once, none before liftoff, every check of the flight
    ignition = flight.scenario.ignition_s
    drogue, main = _rises(run, "drogue"), _rises(run, "main")
    assert len(drogue) == 1 and len(main) == 1, (drogue, main)
    assert min(drogue + main) > ignition
    # every check of the flight; a reset after launch loses the record that was open then (as a power
    # cut does), so the record may then miss its first seconds
    failed = [c.name for c in flight.report.checks if not c.passed]
    if state in ("Safe", "Armed"):
        assert not failed, flight.report.text()
    else:
        assert all(n.startswith("the record covers") for n in failed), flight.report.text()


@pytest.mark.parametrize("name", ["coast", "coast-watchdog"])  # (the Uno's 1 KB store is full 12 s into the flight)
def test_the_record_goes_on_with_the_same_flight(flights, name):
    from fswkit.autocode.recorder import decode, plan

    app, flight = flights[name]
    p = plan(app)
    image = flight.run.eeprom[p.base:p.base + p.size]
    found, _ = decode(p, image)
    assert len(found) == 1, [f.number for f in found]
    [f] = found
    assert f.start is not None and len(f.resumed) == 1
    ev = flight.run.reset_events[0]
    # the second start is the boot after the reset, on the same time line (G went on)
    t_launch = next(t for t, _, n in flight.run.transitions if n == "Boost")
    assert abs(f.resumed[0].t0 / 1000 - f.start.t0 / 1000 - (ev.t - t_launch)) < 0.2
    # and the record's samples after it carry the resumed reset cause and go on to landing
    causes = {row["resetCause"] for _, row in f.samples}
    assert CAUSE[ev.cause] | RESUMED in causes
    assert max(t for t, _ in f.samples) > f.resumed[0].t0


def test_the_drogue_pulse_is_not_restarted(flights):
    _app, flight = flights["drogue-pulse"]
    run = flight.run
    ev = run.reset_events[0]
    [rise] = _rises(run, "drogue")
    assert rise < ev.t < rise + 0.1  # the reset came while its pin was high ...
    falls = [e.t for e in run.pin_events if e.role == "drogue" and not e.level]
    assert falls and falls[0] <= ev.t + 0.001  # ... the reset dropped it, and nothing raised it again
    assert run.session.health["pyro"][0]["fired"] and not run.session.health["pyro"][0]["firing"]


def test_a_power_on_reset_on_the_pad_starts_afresh(flights):
    _app, flight = flights["pad-power"]
    run = flight.run
    [ev] = run.reset_events
    # (>=: the boot's first state can be stamped with the reset's own instant,
    # the report's times rounding down to the millisecond since the UART
    # sends a frame from where it was built; tests/plant/test_reset_in_flight.py
    # reads it so too)
    after = [n for t, _, n in run.transitions if t >= ev.t]
    assert after[0] == "Safe"  # not resumed: on the pad from the first state again
    assert run.session.hello["reset_cause"] == CAUSE["power"]
    # the key still on and the igniters intact, it arms again and flies the whole flight
    assert _states(run) == SEQUENCE[:2] + SEQUENCE
    assert len(_rises(run, "drogue")) == 1 and len(_rises(run, "main")) == 1


def test_an_open_igniter_is_reported_and_the_vehicle_refuses_to_arm(flights):
    _app, flight = flights["open-igniter"]
    run = flight.run
    assert _states(run) == ["Safe"]  # the key on, never armed
    assert not run.pin_events or not any(e.level for e in run.pin_events if e.role in ("drogue", "main"))
    drogue, main = run.session.health["pyro"]
    assert (drogue["name"], drogue["armed"], drogue["continuity"], drogue["fired"]) == ("drogue", True, False, False)
    assert (main["armed"], main["continuity"]) == (True, True)
    assert "OPEN" in drogue["words"]
    assert flight.report.passed, flight.report.text()
