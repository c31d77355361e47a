"""The ground could hold a charge's pin high. The outputs task that drives
the pyro pins is the only code that ends a pulse (docs/safety.md, "the
gate"), and the uplink's MODE command changes any task's mode, with a
mode element or without: `fsw cmd mode act disabled` in the middle of a
pulse was acknowledged (OK) and the pin stayed high with the firing
current on, the pulse's end and the machine's own `charge = false` never
reaching it. (The uplink task's own mode was already LOCKED.)

Now the target refuses a MODE that would disable or safe the task that
drives the pyro channels (LOCKED, as for the uplink task's), and `fsw
check` refuses a `mode=` on it: the pulse ends on time whatever the
ground sends. A small project on the simulated Uno: armed, fired with a
0.5 s pulse, MODE act disabled 0.1 s in."""

from __future__ import annotations

import os
import shutil

import pytest

from support.gate import GATE_DIO, GATE_SM, GateBoard, gate_app, gate_firmware

pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                reason="gcc-avr and libsimavr-dev are needed (make setup)")

SV = """[Flight]
U64 time
U32 state
bool armSwitch
bool go
bool charge
"""

SM = GATE_SM

DIO = GATE_DIO

APP = gate_app(sections="""[pyro]
charge   arm=armSwitch  pulse=0.5  machine=gate  armed=Armed  fire=Fire
""")

CHARGE, KEY, GO = 5, 2, 3
ACT = 3  # the outputs task's index in [tasks]
OK, LOCKED = 0, 7


@pytest.fixture(scope="module")
def project(tmp_path_factory):
    return gate_firmware(tmp_path_factory.mktemp("mode_in_a_pulse"),
                         {"gate.sv": SV, "gate.sm": SM, "gate.dio": DIO, "gate.app": APP})


@pytest.mark.parametrize("mode", [0, 1])  # disabled, safed
def test_a_mode_command_in_a_pulse_is_locked_and_the_pulse_ends(project, mode):
    g = GateBoard(*project)
    b, t = g.b, g.t
    try:
        b.set_digital(KEY, True)
        t.events(0.1)
        b.set_digital(GO, True)
        while not b.digital(CHARGE) and b.time < 2:
            t.events(0.005)
        rise = b.time
        assert b.digital(CHARGE)
        t.events(0.1)
        ack = g.mode(ACT, mode)
        assert ack["status"] == LOCKED, ack
        t.events(rise + 0.55 - b.time)
        assert not b.digital(CHARGE), "the pin is still high past the pulse"
    finally:
        g.close()
