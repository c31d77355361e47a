"""`SimBoard.batches`: several lock-steps in one write, the later ones run
only while no step before them saw a watched pin's edge or a change of the
guarded RAM bytes; a step not run is None and the board stays where the
last run step left it."""

from __future__ import annotations

import os
import shutil

import pytest

from conftest import EXAMPLES
from fswkit.plant.run import prepare
from fswkit.sim.board import SimBoard, SimError
from support.simfw import kept_sim, probe_uno  # noqa: F401

pytestmark = pytest.mark.skipif(shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                reason="gcc-avr and libsimavr-dev are needed (make setup)")

MS = 16_000  # cycles in a millisecond at 16 MHz


def test_the_steps_after_an_edge_are_not_run(probe_uno):
    with SimBoard(probe_uno, "uno", sim_limit=5) as b:
        b.watch(8)  # the sketch mirrors input pin 7 on pin 8
        b.batch(20 * MS)
        steps = [(20 * MS + (i + 1) * MS, None, {7: True} if i == 3 else None, None) for i in range(10)]
        out = b.batches(steps)
        assert all(r is not None for r in out[:4]) and out[4:] == [None] * 6
        assert [e.pin for e in out[3].edges] == [8] and not any(r.edges for r in out[:3])
        assert b.cycle == out[3].run.cycle and 24 * MS <= b.cycle < 24 * MS + 8  # an instruction's end
        # a plain batch runs again from there, and starts a new run of batches
        assert 25 * MS <= b.batch(25 * MS).run.cycle < 25 * MS + 8
        again = b.batches([(26 * MS, None, None, None), (27 * MS, None, None, None)])
        assert [r.run.cycle // MS for r in again] == [26, 27]


def test_the_steps_after_the_guarded_bytes_change_are_not_run():
    project = EXAMPLES / "rocket"
    elf, board = kept_sim(project)
    _app, layout, _sc = prepare(str(project), "rocket", seed=1)
    state = next(e for e in layout.elements if e.name == "state")
    names = {v: k for k, v in layout.states["state"].items()}
    with SimBoard(elf, board, sim_limit=5, analog={"A0": 3.9, "A1": 2.6, "A2": 2.5, "A3": 2.5}) as b:
        sv, _size = b.symbol("fsw_gen::sv")
        b.guard(sv + state.offset, state.size)
        first = b.batch(500 * MS)
        assert layout.states["state"][int.from_bytes(first.guard, "little")] == "Safe"
        # the arming key turned on at the first step: the mission machine arms within a cycle or two
        out = b.batches([(500 * MS + (i + 1) * MS, None, {2: True} if i == 0 else None, None) for i in range(40)])
        ran = [r for r in out if r is not None]
        assert 1 <= len(ran) < 40 and out[len(ran):] == [None] * (40 - len(ran))
        assert [layout.states["state"][int.from_bytes(r.guard, "little")] for r in ran] == \
            ["Safe"] * (len(ran) - 1) + ["Armed"]
        assert b.cycle == ran[-1].run.cycle and b.cycle // MS == 500 + len(ran)
        assert names["Armed"] != names["Safe"]


def test_a_guard_outside_ram_is_refused(probe_uno):
    with SimBoard(probe_uno, "uno", sim_limit=5) as b:
        with pytest.raises(SimError, match="usage: guard ADDR LEN"):
            b.guard(0x10, 2)
        with pytest.raises(SimError, match="usage: guard ADDR LEN"):
            b.guard(0x100, 9)
        b.guard(0, 0)  # none
        assert b.batch(MS).guard == b""
