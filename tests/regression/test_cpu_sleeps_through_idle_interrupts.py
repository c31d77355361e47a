"""The sleeping executor returned to the main loop after every interrupt,
and the loop polled the link and the EEPROM writers for nothing some twenty
times a 100 Hz cycle (the UART's transmit, the ADC's scan): the rocket on
the pad was awake 1,202 µs a cycle. The generated poll() now tells the
executor whether any of them has work, and the CPU sleeps on until the
cycle otherwise (1,026 µs a cycle; simavr's cycle counts, deterministic).
The link, the parameters and the recorder, which need the loop, are
tested where they are (tests/ground, tests/param, tests/recorder)."""

from __future__ import annotations

import os
import shutil

import pytest

from conftest import EXAMPLES, ROOT
from fswkit.sim.board import SimBoard
from support.simfw import kept_sim

pytestmark = pytest.mark.skipif(shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                reason="gcc-avr and libsimavr-dev are needed (make setup)")


def test_the_rocket_on_the_pad_sleeps_through_interrupts_it_has_no_work_for(monkeypatch):
    monkeypatch.syspath_prepend(str(ROOT / "tools"))
    import bench_busy  # its reader of the task table

    elf, board = kept_sim(EXAMPLES / "rocket")
    first_task = bench_busy.task_steps(elf, 7)[0]
    with SimBoard(elf, board, sim_limit=5, analog={"A0": 3.9, "A1": 2.6, "A2": 2.5, "A3": 2.5}) as b:
        b.profile([first_task])
        b.batch(2 * 16_000_000)
        p = b.profile_read()
        awake_us = (b.cycle - p.sleep) / p.frames / 16
    assert p.frames == 200
    assert awake_us < 1_100, f"awake {awake_us:.0f} µs a cycle (1,026 when it slept through them, 1,202 before)"
