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
wake-up (before: it ran from the wake-up on), the period stays 1 ms to
within the spin's tick, and no cycle is counted late (the wake-up's path
fits in the compare's lead)."""

from __future__ import annotations

import os
import shutil

import pytest

from conftest import ROOT, run_fsw
from support.simfw import OUT, toggle_uno  # noqa: F401

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
        at, size = b.symbol("fsw_gen::(anonymous namespace)::ex")
        ex = b.peek(at, size)
    # The wake-up, the clock's count of the sub-period and the test of the
    # wrap fit in the second compare's lead: no cycle counted late (the
    # Executor's `late`, after its configuration's address and `cycles`).
    assert size == 16 and int.from_bytes(ex[2:6], "little") > 100, ex.hex()
    assert int.from_bytes(ex[6:8], "little") == 0, ex.hex()
    periods = [e2.cycle - e1.cycle for e1, e2 in zip(edges, edges[1:])]
    assert periods and all(abs(p - MS) <= 8 for p in periods), sorted(set(periods))  # one timer tick
    seen = "".join("s" if s == "sleeping" else "r" for s in states)
    woke = seen.find("r")  # the early wake-up: the first awake sample after the sleep between cycles
    assert woke > 0 and seen[:woke] == "s" * woke, seen
    # before: "r" from the wake-up to the edge, the last stretch spun
    assert seen[woke:].count("s") >= 3, seen


@pytest.mark.parametrize("rate", [400, 25])
def test_no_cycle_is_late_where_the_lead_counts_more(tmp_path, rate):
    """The second compare's lead is 2 ticks longer where a sub-period has a
    fraction of a millisecond to count (400 Hz: 2,500 us) and 1 longer where
    a cycle has several sub-periods (25 Hz: two of 20 ms): still no cycle
    counted late, the period exact."""
    proj = tmp_path / "toggle"
    shutil.copytree(ROOT / "tests" / "sim" / "toggle", proj)
    app = proj / "toggle.app"
    app.write_text(app.read_text().replace("rate  1000", f"rate  {rate}").replace("rate=1000", f"rate={rate}"))
    out = OUT / f"toggle-{rate}hz-uno"  # kept between runs (support.simfw): the same configs, nothing to relink
    r = run_fsw("build", str(proj), "--board", "uno", "--out", str(out))
    assert r.code == 0, r.err
    elf = str(out / "toggle.elf")
    period = MS * 1000 // rate
    with SimBoard(elf, "uno", sim_limit=10) as b:
        b.watch(13)
        b.run_for(40 / rate)
        edges = b.edges()[4:]
        at, size = b.symbol("fsw_gen::(anonymous namespace)::ex")
        ex = b.peek(at, size)
    periods = [e2.cycle - e1.cycle for e1, e2 in zip(edges, edges[1:])]
    assert len(periods) > 20 and all(abs(p - period) <= 8 for p in periods), sorted(set(periods))
    assert int.from_bytes(ex[6:8], "little") == 0, ex.hex()
