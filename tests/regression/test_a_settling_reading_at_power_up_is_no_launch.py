"""The example flight computers (examples/rocket, examples/hpr) armed in the
first step after a power-up with the key already on, as docs/safety.md
suggests wiring it (the arming switch also switching the computer on), and
tested for a launch at once with `roll_min(accel, 5)`: a window that is not
full yet uses the samples so far (docs/languages.md), so one reading of an
accelerometer still settling as its supply came up (6 g for the first
4 ms) was a launch: Boost, Coast by the burn's timer, and the drogue fired
on the pad at APOGEE_BACKUP. The launch test now waits until the window
holds five samples taken since the machine armed (`T >= 40`, ms), and
the machine stays in Armed. The firmware on the simulated Uno, its pins
driven by hand from power-up."""

from __future__ import annotations

import os
import shutil

import pytest

from conftest import EXAMPLES
from support.simfw import kept_folder

pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                reason="gcc-avr and libsimavr-dev are needed (make setup)")

# example: (accel's volts for g (its .aio), the pad's inputs besides it, Armed's and Boost's state numbers)
EXAMPLE = {
    "rocket": (lambda g: (g + 20) / 8, {"A0": (101325 - 76875) / 6250, "A2": 2.5, "A3": 2.5}),
    "hpr": (lambda g: (g + 26.316) / 15.949, {"A0": (86000 - 10555.56) / 22222.22}),
}
ARMED, BOOST = 2, 3


@pytest.mark.parametrize("name", sorted(EXAMPLE))
def test_a_settling_reading_at_power_up_with_the_key_on_is_no_launch(name):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.link.layout import from_app
    from fswkit.link.session import Session
    from fswkit.param.client import SimTransport
    from fswkit.sim.board import SimBoard
    from fswkit.target.build import firmware, load

    d = Diagnostics()
    app = load(str(EXAMPLES / name / f"{name}.app"), d)
    assert app is not None, d.render()
    built = firmware(app, str(kept_folder(EXAMPLES / name, "uno")))  # kept between runs (support.simfw)
    assert built.fits, built.report
    volts, pad = EXAMPLE[name]
    b = SimBoard(built.artifact, "uno", uart="control", sim_limit=60,
                 analog={**pad, "A1": volts(6.0)})  # from power-up: 6 g while the part settles
    try:
        s = Session(from_app(app))
        t = SimTransport(b, s)
        b.set_digital(2, True)  # the key: armed before the power came
        t.events(0.004)
        b.set_analog("A1", volts(1.0))  # settled: 1 g on the pad
        seen = set()
        for _ in range(30):
            t.events(0.05)
            seen.add(s.values.get("state"))
        assert seen == {ARMED}, seen
    finally:
        b.close()
