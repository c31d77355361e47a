"""A closed-loop flight sends its plant steps to the board several to a
write, worked out ahead (fswkit.plant.cosim.SPECULATE): the flight must be
the one sent a step at a time, step for step -- the truth rows, the pin
events, the telemetry, the resets, the parts' failures, the recorder's
EEPROM. Flown both ways here through what makes the board stop early or the
plant go back: pyro edges, a brown-out in flight, a reset when telemetry
shows a state, sensor dropouts held by a digital part, a part that stops
answering, the tank's valve."""

from __future__ import annotations

import os
import shutil

import pytest

from conftest import EXAMPLES
from fswkit.plant import cosim, study
from fswkit.plant.dispersion import draw
from fswkit.plant.dispersion import load as load_dispersion
from fswkit.plant.run import prepare
from support.simfw import kept_sim

pytestmark = pytest.mark.skipif(shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                reason="gcc-avr and libsimavr-dev are needed (make setup)")

FIELDS = ("rows", "pin_events", "samples", "transitions", "steps", "sim_s", "resets", "reset_events", "eeprom",
          "flash", "part_failures", "part_health", "ram")


def both_ways(make, elf, board, layout, monkeypatch):
    """(the run a step to a write, the run as flown): `make` gives a fresh scenario."""
    with monkeypatch.context() as m:
        m.setattr(cosim, "SPECULATE", 1)
        one = cosim.fly(make(), elf, board, layout)
    return one, cosim.fly(make(), elf, board, layout)


def same(one, many) -> None:
    for f in FIELDS:
        assert getattr(many, f) == getattr(one, f), f
    assert one.round_trips == one.steps and many.round_trips < many.steps / 8


def study_setup(project):
    elf, board = kept_sim(project)
    app, layout, _sc = prepare(str(project), "rocket", seed=1)
    disp = load_dispersion(str(EXAMPLES / "rocket" / "dispersion.toml"))
    return study.Setup(app, layout, str(project / "plant.toml"), elf, board, disp, 7)


def test_a_brownout_in_flight_and_the_drogue(monkeypatch):
    setup = study_setup(EXAMPLES / "rocket")
    index = next(i for i in range(400) if (draw(setup.disp, 7, i).brownout_s or 99) < 12)
    d = draw(setup.disp, 7, index)

    def make():
        sc = study.scenario_for(setup, d)
        sc.max_s = sc.ignition_s + d.brownout_s + 1.0  # past the reset: the drogue fires before it
        return sc

    one, many = both_ways(make, setup.elf, setup.board, setup.layout, monkeypatch)
    same(one, many)
    assert [e.role for e in one.pin_events][:1] == ["drogue"] and len(one.resets) == 1
    assert one.pin_events[0].t < one.resets[0]


def test_a_reset_when_telemetry_shows_a_state(monkeypatch):
    elf, board = kept_sim(EXAMPLES / "rocket")
    _app, layout, _sc = prepare(str(EXAMPLES / "rocket"), "rocket", seed=2)

    def make():
        sc = prepare(str(EXAMPLES / "rocket"), "rocket", seed=2)[2]
        sc.reset_state, sc.reset_cause, sc.reset_after_s = "Coast", "watchdog", 0.05
        sc.max_s = 9.0
        return sc

    one, many = both_ways(make, elf, board, layout, monkeypatch)
    same(one, many)
    assert [(e.cause, e.state, e.trigger) for e in one.reset_events] == [("watchdog", "Coast", "state")]


def test_a_digital_barometers_dropout_and_its_failure(monkeypatch):
    setup = study_setup(EXAMPLES / "hpr_digital")
    index = next(i for i in range(400) if any(a < 2 for a, _b in draw(setup.disp, 7, i).baro.dropouts))
    d = draw(setup.disp, 7, index)

    def make():
        sc = study.scenario_for(setup, d)
        sc.part_fail_plan = [(sc.ignition_s + 2.5, sc.baro_part, "nack")]
        sc.max_s = sc.ignition_s + 3.0
        return sc

    one, many = both_ways(make, setup.elf, setup.board, setup.layout, monkeypatch)
    same(one, many)
    assert len(one.part_failures) == 1


def test_the_tank_regulates_and_aborts(monkeypatch):
    elf, board = kept_sim(EXAMPLES / "tank")
    _app, layout, _sc = prepare(str(EXAMPLES / "tank"), "tank", seed=1)
    one, many = both_ways(lambda: prepare(str(EXAMPLES / "tank"), "tank", seed=1)[2], elf, board, layout,
                          monkeypatch)
    same(one, many)
    assert len(one.pin_events) >= 4 and one.transitions[-1][2] == "Abort"
