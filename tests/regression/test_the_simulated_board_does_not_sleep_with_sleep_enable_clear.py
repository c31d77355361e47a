"""On the ATmega328P a SLEEP instruction puts the CPU to sleep only while the
SE bit of SMCR is set ("to enter any of the sleep modes, the SE bit must be
written to logic one and a SLEEP instruction must be executed"); with SE
clear it does nothing. simavr sleeps on every SLEEP, so the simulated board
slept where the part runs on: a firmware whose interrupt handler clears SE
so that a SLEEP just after it cannot sleep through the wake-up it brought
(the sleeping executor's loop, psl_arduino.cpp cycle_wait) lost that
wake-up on the board and started cycles late (188 late cycles instead of
17 on the rocket at 1 kHz, tools/bench_busy.py).

Now the board (host-tools/fswkit/sim/harness.c) runs a SLEEP with SE clear
as a NOP and sleeps on one with SE set, as the part does. The probe below
prints `a`, runs a SLEEP with SE clear (no interrupt is enabled: a sleep
there would never end), prints `b`, then sleeps with SE set, which ends
only at an interrupt (none comes: `c` never prints)."""

from __future__ import annotations

import os
import shutil
import subprocess

import pytest

from fswkit.sim.board import SimBoard

pytestmark = pytest.mark.skipif(
    shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
    reason="gcc-avr (to build the probe firmware) and libsimavr-dev are needed (make setup)")

PROBE = r"""
#include <avr/io.h>
#include <avr/interrupt.h>

static void tx(char c) {
    while (!(UCSR0A & (1 << UDRE0))) {}
    UDR0 = (uint8_t)c;
}

int main(void) {
    UBRR0 = 0;  /* 2 Mbaud: U2X, UBRR 0 */
    UCSR0A = 1 << U2X0;
    UCSR0B = 1 << TXEN0;
    UCSR0C = 3 << UCSZ00;
    tx('a');
    SMCR = 0;  /* SE clear: the SLEEP below does nothing */
    sei();
    __asm__ __volatile__("sleep" ::: "memory");
    tx('b');
    SMCR = 1 << SE;  /* SE set: asleep until an interrupt, and none is enabled */
    __asm__ __volatile__("sleep" ::: "memory");
    tx('c');
    for (;;) {}
}
"""


@pytest.fixture(scope="module")
def probe(tmp_path_factory) -> str:
    d = tmp_path_factory.mktemp("sleep")
    src, elf = d / "probe.c", d / "probe.elf"
    src.write_text(PROBE)
    r = subprocess.run(["avr-gcc", "-mmcu=atmega328p", "-DF_CPU=16000000UL", "-Os", "-Wall", "-Wextra", "-Werror",
                        "-o", str(elf), str(src)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return str(elf)


def test_a_sleep_with_se_clear_runs_on_and_one_with_se_set_sleeps(probe):
    with SimBoard(probe, "uno", sim_limit=10, wall_limit=30) as b:
        b.run_for(0.01)
        assert b.uart_read() == b"ab"
        b.run_for(0.01)
        assert b.uart_read() == b""
