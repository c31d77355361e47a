"""A long uplink step (a machine upload's commit checks the image in the
EEPROM: 21 ms on an ATmega2560) made the next cycle start in the same
millisecond as the late one: G (`[time] source clock, unit ms`) had not
moved, both machine steps refused it (kErrTime) and the executor safed nav
and mission, the rocket's flight logic, with the board otherwise running.
The pending activation then never came. A machine task now leaves a step
whose G is its last step's for its next run (fsw::machine_same_tick).

The case as tools/bench_reload.py found it: examples/rocket on a simulated
ATmega2560 at 9,600 baud, its mission machine uploaded and activated
through a link that loses 20 % of the frames each way (seed 1)."""

from __future__ import annotations

import os
import shutil

import pytest

from support.tools import rocket_with_reload

pytestmark = [pytest.mark.skipif(shutil.which("avr-g++") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                 reason="gcc-avr and libsimavr-dev are needed (make setup)"),
              pytest.mark.costly(3)]


def test_an_upload_over_a_lossy_9600_baud_link_activates_and_no_machine_is_safed(tmp_path):
    from fswkit.reload.sim import timed_upload

    app, built, image, mask = rocket_with_reload(str(tmp_path), 9600)
    # before the fix: MachineError "still waiting after 30 s", nav and mission safed with a fault each
    r = timed_upload(built.artifact, "mega2560", app, image, mask, loss=0.2, seed=1)
    assert r.slot in (1, 2) and r.activate_s < 5.0, r
