"""The sleeping executor (AVR) woke FSW_WAKE_EARLY_US (16 us) before each
cycle and spun out the rest with interrupts off, so that no handler could
delay the cycle's start: 11 us of awake time a cycle on the rocket, spent
reading the timer's count.

Now, where the application has no sensor parts and its period is a
constant, the early wake-up holds the kit's other interrupt sources (the
UART's, the ADC's) and puts the CPU back to sleep until the timer's second
compare, moved to 12 ticks (6 us) before the count wraps: nothing else can
wake it then, so it wakes at the same instruction every cycle and spins
only the rest, and the cycle starts on the timer's count as before.

Sampled one microsecond a cycle over the last 90 us before the toggle
project's task sets its pin (1 kHz), the CPU sleeps again after the early
wake-up (before: it ran from the wake-up on), and the period stays 1 ms
to within the spin's tick."""

from __future__ import annotations

import os
import shutil

import pytest

from support.simfw import toggle_uno  # noqa: F401

from fswkit.sim.board import SimBoard

pytestmark = pytest.mark.skipif(
    shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
    reason="gcc-avr and libsimavr-dev are needed (make setup)")

MS = 16000  # CPU cycles a millisecond (and a cycle of the toggle project) at 16 MHz
US = 16


def test_the_cpu_sleeps_between_the_early_wake_up_and_the_cycle(toggle_uno):  # noqa: F811
    with SimBoard(toggle_uno, "uno", sim_limit=5) as b:
        b.watch(13)
        b.run_for(0.05)
        edge = b.edges()[-1].cycle
        states = []
        for k, before in enumerate(range(90, 0, -1)):  # a sample a cycle, 90 us .. 1 us before its pin edge
            states.append(b.until(edge + (k + 1) * MS - before * US).state)
        b.until(edge + 100 * MS)
        edges = b.edges()
    periods = [e2.cycle - e1.cycle for e1, e2 in zip(edges, edges[1:])]
    assert periods and all(abs(p - MS) <= 8 for p in periods), sorted(set(periods))  # one timer tick
    seen = "".join("s" if s == "sleeping" else "r" for s in states)
    woke = seen.find("r")  # the early wake-up: the first awake sample after the sleep between cycles
    assert woke > 0 and seen[:woke] == "s" * woke, seen
    # before: "r" from the wake-up to the edge, the last stretch spun
    assert seen[woke:].count("s") >= 3, seen
