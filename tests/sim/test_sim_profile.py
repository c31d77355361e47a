"""The simulated board's profiler (`prof`, SimBoard.profile): cycles spent
in chosen functions of the firmware (the executor's task steps) and in
frames, one executor cycle each; what tools/bench_busy.py measures with."""

from __future__ import annotations

import os
import shutil

import pytest

from support.simfw import tank_uno  # noqa: F401  (a fixture)

from fswkit.sim.board import SimBoard, SimError

pytestmark = pytest.mark.skipif(
    shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
    reason="gcc-avr and libsimavr-dev are needed (make setup)")


def test_profile_counts_each_task_call_and_each_cycle(tank_uno):
    with SimBoard(tank_uno, "uno", analog={"A0": 3.9}, sim_limit=5) as b:
        up = b.function("fsw::link_uplink_task")  # the tank's first task
        down = b.function("fsw::link_telemetry_task")  # and its last
        b.run_for(0.005)
        b.profile([up, down])
        b.run_for(0.1)  # ten cycles at 100 Hz
        p = b.profile_read()
    fu, fd = p.functions
    assert (fu.entry, fd.entry) == (up, down)
    assert fu.calls == fd.calls == p.frames == 10
    for f in (fu, fd):
        assert 0 < f.worst <= f.total
    # a frame runs from the first task's start to the last one's end
    assert p.frame_total >= fu.total + fd.total
    assert fu.worst + 0 <= p.frame_worst <= 160_000  # under a 10 ms period
    assert p.frame_worst_at > 0.005 * 16_000_000


def test_profile_restarts_from_zero_and_refuses_bad_addresses(tank_uno):
    with SimBoard(tank_uno, "uno", sim_limit=5) as b:
        up = b.function("fsw::link_uplink_task")
        b.profile([up])
        b.run_for(0.05)
        assert b.profile_read().functions[0].calls > 0
        b.profile([up])
        assert b.profile_read().functions[0].calls == 0
        with pytest.raises(SimError, match="usage: prof"):
            b.profile([1 << 20])
        with pytest.raises(SimError, match="no function `no_such_function`"):
            b.function("no_such_function")


def test_the_executor_sleeps_between_cycles(tank_uno):
    """Between cycles the core sleeps (idle, until the executor's timer wakes
    it): of 0.1 s at 100 Hz, the tank's tasks keep it busy a few percent, so
    well over three quarters of the cycles are asleep, and the cycles spent
    in the tasks are not counted as sleep."""
    with SimBoard(tank_uno, "uno", analog={"A0": 3.9}, sim_limit=5) as b:
        up = b.function("fsw::link_uplink_task")
        down = b.function("fsw::link_telemetry_task")
        b.run_for(0.005)
        b.profile([up, down])
        c0 = b.cycle
        b.run_for(0.1)
        total = b.cycle - c0
        p = b.profile_read()
    assert p.sleep > 0.75 * total
    assert p.sleep + p.frame_total <= total
