"""The AVR benchmarks (tools/bench_vm.py, tools/bench_firmware.py) subtract
from every step's time the cost of timing it: two Timer1 reads back to back
in tools/bench/cycle_report.h. They were read with interrupts on, so an
interrupt that came between them (the core's Timer0, every 16,384 cycles)
counted as that cost: 101 cycles rather than 4 in some builds of the VM's
probe, and its step's average 97 cycles too low. Here an interrupt is
pending between any two instructions while the report reads its cost (a
Timer2 overflow every 256 cycles, whose handler takes longer than that):
the cost must still be the two reads' own."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
ARDUINO = Path("/usr/share/arduino/hardware/arduino/avr")

SKETCH = r"""
#include <Arduino.h>
#include "@ROOT@/tools/bench/cycle_report.h"

namespace {
volatile uint8_t spin;
volatile uint8_t overflows;
}  // namespace

// Longer than Timer2's 256-cycle period: one instruction of the sketch runs
// between two of these, until the two hundredth turns the interrupt off.
ISR(TIMER2_OVF_vect) {
    for (uint8_t i = 0; i < 80; ++i) spin = i;
    if (++overflows == 200) TIMSK2 = 0;
}

void setup() {
    Serial.begin(115200);
    TCCR1A = 0;
    TCCR1B = 1;
    TCCR2A = 0;
    TCCR2B = 1;
    TIMSK2 = 1 << TOIE2;
    while (overflows == 0) {
    }
    // the same two reads with interrupts on, as the report read them before
    const uint16_t t0 = TCNT1;
    const uint16_t t1 = TCNT1;
    const uint16_t naive = static_cast<uint16_t>(t1 - t0);
    report_cycles(0, 0, naive > 255 ? 255 : static_cast<uint8_t>(naive));
}

void loop() {}
"""

pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or not ARDUINO.is_dir(),
                                reason="gcc-avr and arduino-core-avr are needed (make setup)")


def test_the_timing_cost_is_the_two_reads_own_under_interrupts():
    from fswkit.sim.board import harness
    from support.simfw import sketch_elf

    elf = sketch_elf("cycle-report-under-interrupts", SKETCH.replace("@ROOT@", str(ROOT)))
    r = subprocess.run([harness(), "-u", "stdout", "-m", "atmega328p", "-t", "5", "-w", "60", elf],
                       capture_output=True, text=True)
    m = re.search(r"cycles (\d+) worst (\d+) overhead (\d+) state (\d+)", r.stdout + r.stderr)
    assert m, r.stdout + r.stderr
    overhead, naive = int(m.group(3)), int(m.group(4))
    # the same reads with interrupts on take the handler's cycles: the case is the one the report must survive
    assert naive > 200, f"no interrupt came between two reads with interrupts on ({naive} cycles): the test tests nothing"
    assert overhead <= 8, f"the two timer reads cost {overhead} cycles: an interrupt came between them"
