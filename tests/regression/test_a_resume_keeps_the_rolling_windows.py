"""A reset in flight emptied the machines' rolling windows (docs/safety.md,
"A reset in flight"): the banks kept the state, the timers and the
locals, and the windows started again from no sample, where a window
that is not full yet uses the samples so far (docs/languages.md). So
examples/rocket, armed on the pad, whose launch needs five samples of
the accelerometer above LAUNCH_G (`roll_min(accel, 5)`), took one
reading of 6 g right after a brown-out or a watchdog reset (an
accelerometer settling as its own supply comes back) for a launch: Boost,
Coast by the burn's timer, and at APOGEE_BACKUP the drogue fired on the
pad, the key armed, 13 s after the reset. Before the reset the same
reading was one sample among five.

Now the banks keep every machine's windows with its locals: after the
reset the window holds the four pad samples before it, and the settling
reading is one of five. The rocket's firmware on the simulated Uno, its
pins driven by hand: armed on the pad, a reset, 6 g for the first 4 ms
after it, then 1 g: the machine stays in Armed."""

from __future__ import annotations

import os
import shutil

import pytest

from conftest import EXAMPLES
from support.simfw import kept_folder

pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                reason="gcc-avr and libsimavr-dev are needed (make setup)")

ARMED, BOOST = 2, 3  # mission.sm's state numbers


def volts_g(g: float) -> float:
    return (g + 20) / 8  # rocket.aio: accel = volts * 8 - 20


@pytest.fixture(scope="module")
def rocket():
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import firmware, load

    d = Diagnostics()
    app = load(str(EXAMPLES / "rocket" / "rocket.app"), d)
    assert app is not None, d.render()
    built = firmware(app, str(kept_folder(EXAMPLES / "rocket", "uno")))  # kept between runs (support.simfw)
    assert built.fits, built.report
    return app, built.artifact


@pytest.mark.parametrize("cause", ["brownout", "watchdog"])
def test_a_settling_reading_after_a_reset_on_the_pad_is_no_launch(rocket, cause):
    from fswkit.link.layout import from_app
    from fswkit.link.session import Session
    from fswkit.param.client import SimTransport
    from fswkit.sim.board import SimBoard

    app, elf = rocket
    b = SimBoard(elf, "uno", uart="control", sim_limit=60)
    try:
        s = Session(from_app(app))
        t = SimTransport(b, s)

        def pad(accel_g: float) -> None:
            b.set_analog("A0", (101325 - 76875) / 6250)  # the pad's pressure
            b.set_analog("A1", volts_g(accel_g))
            b.set_analog("A2", 2.5)  # both igniters intact
            b.set_analog("A3", 2.5)
            b.set_digital(2, True)  # the key: armed

        pad(1.0)
        t.events(1.5)
        assert s.values.get("state") == ARMED
        b.reset(cause)
        pad(6.0)  # the first reading after the reset
        t.events(0.004)
        pad(1.0)
        seen = set()
        for _ in range(20):
            t.events(0.05)
            seen.add(s.values.get("state"))
        assert s.hello["reset_cause"] & 0x80, s.hello  # the flight resumed
        assert seen == {ARMED}, seen
    finally:
        b.close()
