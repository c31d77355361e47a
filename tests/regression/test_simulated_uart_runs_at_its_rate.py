"""The simulated Uno's UART ran at half its rate: `console_begin` wrote
`UBRR0` before setting double speed (`U2X0`), and simavr fixes the bit rate
when `UBRR0` is written, so the link carried 5,316 B/s where 10,695 are
possible and dropped frames a stream set needed. Silicon takes either
order; the runtime sets the UART up in the order both honour."""

from __future__ import annotations

import os
import shutil
import sys

import pytest

from conftest import ROOT

from support.simfw import sketch_elf  # noqa: E402

pytestmark = pytest.mark.skipif(shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                reason="gcc-avr and libsimavr-dev are needed (make setup)")

# Hands 64 'U's again whenever the UART took every byte handed (its data
# register then still holds the last: the line is never idle).
FLOOD_SKETCH = r"""
#include <Arduino.h>
#include "fswkit.h"
static uint8_t u[64];
void setup() {
    memset(u, 'U', sizeof u);
    fsw::pal::console_begin(BAUD);
}
void loop() {
    if (fsw::pal::console_sending() == 0) fsw::pal::console_send(u, sizeof u);
}
"""


# 8N1: start, 8 data, stop. simavr 1.6 alone times a byte as 11 bit times
# (it counts a parity bit with parity off); the harness takes that bit out
# again (docs/sim.md, "fsw sim and the pty"), so 8N1 at 117,647 baud is
# 11,765 B/s, as on silicon.
BITS_PER_BYTE = 10


@pytest.mark.parametrize("baud, made", [(115200, 117647), (57600, 57143), (9600, 9615)])
def test_the_console_sends_at_the_rate_it_was_given(baud, made):
    from fswkit.sim.board import SimBoard

    elf = sketch_elf(f"flood{baud}", FLOOD_SKETCH.replace("BAUD", f"{baud}UL"))
    seconds = 0.2
    with SimBoard(elf, "uno", uart="control") as board:
        board.step(board.cycles_for(0.01))  # boot and the first bytes
        board.uart_read()
        board.step(board.cycles_for(seconds))
        sent = len(board.uart_read())
    expected = made / BITS_PER_BYTE * seconds  # the rate the divisor makes (half of it before)
    assert abs(sent - expected) <= 0.01 * expected + 2, (sent, expected)

