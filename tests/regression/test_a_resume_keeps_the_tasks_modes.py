"""The ground's task modes were lost at a resume (docs/safety.md, "A reset
in flight"): a crew that safed the machine on the pad (`fsw cmd mode fly
safed`) saw it come back enabled after a brown-out, in its `start=` mode,
armed by the key still on: the charge fired. The banks kept the state
vector, where a task's `mode=` element lives, but the executor's start
wrote every task's `start=` mode over it, and a task without a mode
element kept its mode in the executor's records, not in the banks.

Now a resumed flight goes on with every task's mode as the last cycle
left it, with a mode element or without. The gate project (support.gate)
on the simulated Uno: `fly` (no mode element) safed from the ground, the
key and the trigger on and read, then `sense` (its mode in the
`senseMode` element) safed, a brown-out: nothing fires, both still safed
in the health frames that follow."""

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
U8  senseMode
"""

SM = GATE_SM

DIO = GATE_DIO

APP = gate_app(telemetry_rate=10, sections="""[pyro]
charge   arm=armSwitch  pulse=0.5  machine=gate  armed=Armed  fire=Fire
""").replace("sense    inputs        rate=100", "sense    inputs        rate=100  mode=senseMode")

CHARGE, KEY, GO = 5, 2, 3
SENSE, FLY = 1, 2  # the tasks' indexes in [tasks]
SAFED = 1


@pytest.fixture(scope="module")
def project(tmp_path_factory):
    return gate_firmware(tmp_path_factory.mktemp("modes"), {"gate.sv": SV, "gate.sm": SM, "gate.dio": DIO,
                                                           "gate.app": APP})


@pytest.mark.parametrize("cause", ["brownout", "watchdog"])
def test_the_grounds_modes_go_on_after_a_resume(project, cause):
    g = GateBoard(*project)
    b, t, session = g.b, g.t, g.session
    try:
        def safe(task):
            ack = g.mode(task, SAFED)
            assert ack is not None and ack["status"] == 0, ack

        safe(FLY)
        b.set_digital(KEY, True)  # armed and triggered: read, and not seen by the safed machine
        b.set_digital(GO, True)
        t.events(0.2)
        safe(SENSE)
        t.events(0.1)
        b.reset(cause)
        session.health = None
        b.set_digital(KEY, True)
        b.set_digital(GO, True)
        fired = False
        end = b.time + 1.5
        while b.time < end:
            t.events(0.01)
            fired |= b.digital(CHARGE) and b.is_output(CHARGE)
        assert session.hello["reset_cause"] & 0x80, session.hello  # the flight resumed
        assert session.health is not None  # a health frame since the reset
        modes = {x["name"]: x["mode_name"] for x in session.health["tasks"]}
        assert modes["fly"] == "safed" and modes["sense"] == "safed", modes
        assert not fired, "the safed machine fired after the reset"
    finally:
        g.close()
