"""simavr 1.6 leaves the phase-correct PWM modes out of the ATmega328P's and
ATmega2560's timer tables (the 8-bit timers' mode 1, the 16-bit timers'
modes 1-3). A timer in a mode the table lacks gets a TOP of 0: it overflowed,
and matched both its compare units, every prescaler period. The Arduino
core's init() leaves Timer1 and Timer2 (and the Mega's Timer3-5) in mode 1
at clk/64, so every firmware built on it had them overflow every 64 CPU
cycles: three interrupt flags raised each time, about two fifths of the
simulator's time on a flight that never uses them. The harness fills in the
modes as simavr's own ATmega164-1284 and ATmega32U4 tables have them (one
TOP + 1 period: 256 x 64 cycles at clk/64, where the part's dual slope takes
510 x 64). Checked by counting a timer's overflow flag in a polling loop."""

from __future__ import annotations

import os
import shutil

import pytest

from support.simfw import c_elf

pytestmark = pytest.mark.skipif(shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                reason="gcc-avr and libsimavr-dev are needed (make setup)")

# Timer T in mode 1 (PWM, phase correct, 8-bit: WGMn0 in TCCRnA) at clk/64,
# as the Arduino core's init() leaves Timer1 and Timer2; the loop counts its
# overflow flag (TOVn, cleared by writing 1) for ever.
POLL_C = r"""
#include <avr/io.h>
volatile uint16_t overflows;
int main(void) {
    TCCR@A = _BV(WGM@0);
    TCCR@B = _BV(CS@1) | _BV(CS@0) | 0;
    TIFR@ = _BV(TOV@);
    for (;;) {
        if (TIFR@ & _BV(TOV@)) {
            TIFR@ = _BV(TOV@);
            overflows++;
        }
    }
}
"""
# clk/64 is CS22 on Timer2 (its prescaler has more steps), CS11 | CS10 on the 16-bit timers
PRESCALE_64 = {"2": "TCCR2B = _BV(CS22);"}

SECONDS = 0.1
PART = SECONDS * 16e6 / (510 * 64)  # 49 overflows on the part (dual slope)
MODEL = SECONDS * 16e6 / (256 * 64)  # 97.7 in simavr's one-slope model of the mode


def _program(timer: str) -> str:
    src = POLL_C.replace("@", timer)
    if timer in PRESCALE_64:
        src = src.replace(f"TCCR{timer}B = _BV(CS{timer}1) | _BV(CS{timer}0) | 0;", PRESCALE_64[timer])
    return src


@pytest.mark.parametrize("board, mcu, timer", [("uno", "atmega328p", "1"), ("uno", "atmega328p", "2"),
                                               ("mega2560", "atmega2560", "2"), ("mega2560", "atmega2560", "3")])
def test_a_timer_in_phase_correct_pwm_overflows_at_its_period(board, mcu, timer):
    from fswkit.sim.board import SimBoard

    elf = c_elf(f"pwm{timer}", _program(timer), mcu=mcu)
    with SimBoard(elf, board, uart="control", sim_limit=1) as b:
        b.step(b.cycles_for(SECONDS))
        addr, size = b.symbol("overflows")
        n = int.from_bytes(b.peek(addr, size), "little")
    # 25,000 before (one every 64 cycles); simavr's model of the mode, within a few of the part's period
    assert PART - 1 <= n <= MODEL + 1, (n, PART, MODEL)
