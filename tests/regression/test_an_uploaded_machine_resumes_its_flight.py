"""A reset in flight with an uploaded machine running (docs/safety.md, "A
reset in flight"; docs/reload.md): the banks kept the state vector, the
machine's state and the generated machine's locals, but at boot the
store then started the newest activated image afresh, from its first
state (`vm_reset`), with its windows and locals at their initial values.
So after a brown-out the uploaded machine was back on the pad: here its
`Safe.entry` set the charge's element false, the key and the trigger
still read armed, and it went through Armed into Fire again and fired
the charge a second time, 0.1 s after the brown-out. In the rocket the
same would have left the main undeployed (both igniters must read intact
to arm again; the drogue's reads open once fired).

Now the banks also keep which machine runs (the generated one or an
uploaded slot) and an uploaded machine's RAM (its windows and locals);
after a brown-out or a watchdog reset the store runs that same machine
on in the state it was in, with its RAM as it was. One charge, one
pulse, and the machine still in Fire (its count of entries still 1).

A small project on the simulated Uno: [reload] of the machine that fires
the [pyro] channel; the same machine uploaded and activated, then armed,
fired, and a brown-out in its pulse's second."""

from __future__ import annotations

import os
import shutil

import pytest

from support.gate import GATE_DIO, gate_app, gate_firmware

pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                reason="gcc-avr and libsimavr-dev are needed (make setup)")

SV = """[Flight]
U64 time
U32 state
U8  cause
bool armSwitch
bool go
bool charge
U32 count
"""

# Safe sets the charge false (as the rocket's does); Fire counts its entries.
SM = """[state_vector]
U64 time         @alias G
U32 state        @alias S
bool armSwitch   @read_only
bool go          @read_only
bool charge
U32 count

[local]
U32 n = 0

[Safe]
.entry
    charge = false
.step
    armSwitch: -> Armed
[Armed]
.step
    go: -> Fire
[Fire]
.entry
    n = n + 1
    count = n
    charge = true
.step
    T >= 1000: -> Done
.exit
    charge = false
[Done]
"""

DIO = GATE_DIO

APP = gate_app(extra="reset_cause cause\n", telemetry_rate=50, sections="""[reload]
machine  gate
size     256
ram      32
activate Safe

[pyro]
charge   arm=armSwitch  pulse=0.05  machine=gate  armed=Armed  fire=Fire
""")

CHARGE, KEY, GO = 5, 2, 3
FIRE, DONE = 3, 4  # the machine's state numbers


@pytest.fixture(scope="module")
def project(tmp_path_factory):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.cli.machine import image_for

    d = tmp_path_factory.mktemp("reload_resume")
    app, elf = gate_firmware(d, {"gate.sv": SV, "gate.sm": SM, "gate.dio": DIO, "gate.app": APP})
    diags = Diagnostics()
    image = image_for(app, str(d / "gate.sm"), diags)
    assert image is not None, diags.render()
    return app, elf, image


class Rig:
    def __init__(self, app, elf):
        from fswkit.autocode.schema import link_plan
        from fswkit.link.layout import from_app
        from fswkit.link.session import Session
        from fswkit.param.client import SimTransport
        from fswkit.reload.client import MachineClient
        from fswkit.sim.board import SimBoard

        self.b = SimBoard(elf, "uno", uart="control", sim_limit=120)
        self.session = Session(from_app(app))
        self.t = SimTransport(self.b, self.session)
        self.rows: list[tuple[float, dict]] = []
        self.rises: list[float] = []
        self.level = False
        self.run(0.3)
        assert self.session.hello is not None
        self.c = MachineClient(self.t, link_plan(app).tx_cap, baud=app.baud, timeout=0.3)

    def run(self, seconds: float) -> None:
        """Runs the board in 5 ms steps, watching the charge's pin (a pulse
        is 50 ms) and collecting telemetry."""
        end = self.b.time + seconds
        while self.b.time < end:
            if any(ev.kind == "sample" for ev in self.t.events(0.005)):
                self.rows.append((self.b.time, dict(self.session.values)))
            level = self.b.digital(CHARGE) and self.b.is_output(CHARGE)  # driven high by the firmware
            if level and not self.level:
                self.rises.append(self.b.time)
            self.level = level

    def close(self) -> None:
        self.b.close()


@pytest.mark.parametrize("cause", ["brownout", "watchdog"])
def test_a_reset_in_the_uploaded_machines_pulse_does_not_fire_it_again(project, cause):
    app, elf, built = project
    image, mask = built[0], built[1]
    rig = Rig(app, elf)
    try:
        slot, _ = rig.c.upload(image, mask)
        assert rig.c.activate(slot).active == slot
        rig.b.set_digital(KEY, True)
        rig.run(0.1)
        rig.b.set_digital(GO, True)
        rig.run(0.3)
        assert len(rig.rises) == 1, rig.rises  # fired once, the pulse over, still in Fire (1 s)
        fired = rig.rises[0]
        rig.b.reset(cause)
        rig.b.set_digital(KEY, True)  # the key and the trigger still read armed (a reset lets go of the pins)
        rig.b.set_digital(GO, True)
        rig.run(0.6)
        assert rig.session.hello["reset_cause"] == {"brownout": 0x04, "watchdog": 0x08}[cause] | 0x80  # resumed
        assert rig.rises == [fired], f"fired again after the {cause}"
        after = [row for t, row in rig.rows if t > fired + 0.3 + 0.05]
        assert after and {row["state"] for row in after} == {FIRE}, after[-3:]
        assert {row["count"] for row in after} == {1}
        assert rig.c.info().active == slot
        # its T went on from the kept entry: Done 1 s after Fire was entered, not 1 s after the reset
        rig.run(fired + 1.2 - rig.b.time)
        done = next(t for t, row in rig.rows if row["state"] == DONE)
        assert fired + 0.95 < done < fired + 1.1, (fired, done)
    finally:
        rig.close()
