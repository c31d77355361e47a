"""A machine upload's COMMIT checked the image in one uplink step: its CRC
and the board's verifier reading the EEPROM byte by byte, 11.1 ms of CPU
for the rocket's 646-byte mission machine on a 16 MHz ATmega2560, longer
than the 10 ms cycle; the activation checked it again inside the machine
task's step. A test stand at 100 Hz mid-sequence took a late cycle from a
ground command. The checks now run in slices, one at each of the machine
task's steps (docs/reload.md, "Checked in slices").

examples/rocket (100 Hz) with [reload] of its mission machine on a
simulated ATmega2560 (tools/bench_reload.py's variant), and examples/stand
(100 Hz) on a simulated Uno: an upload, its commit and its activation, the
executor's health frames read before and after."""

from __future__ import annotations

import os
import shutil

import pytest

from conftest import EXAMPLES
from support.simfw import kept_folder
from support.tools import rocket_with_reload

pytestmark = [pytest.mark.skipif(shutil.which("avr-g++") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                 reason="gcc-avr and libsimavr-dev are needed (make setup)"),
              pytest.mark.costly(10, waits=True)]

CYCLE_US = 10_000  # both applications run at 100 Hz
# The longest step the uplink task may take through it (a command's work
# only), and the machine's task (its step and a slice of a check, or the
# switch: the image copied from the EEPROM, 1.2 ms for 646 B, and its first
# step), against the 10 ms cycle.
UPLINK_US = 2_000
MACHINE_US = 2_500
SLICE_CYCLES = 16_000  # a slice of a check: under 1 ms at 16 MHz


def _check(r, machine_task: str):
    assert r.late == 0, f"{r.late} late cycles through the upload and the activation"
    assert r.overruns and not any(r.overruns.values()), r.overruns
    assert r.worst_us["uplink"] < UPLINK_US, r.worst_us
    assert r.worst_us[machine_task] < MACHINE_US, r.worst_us
    assert 0 < r.longest_slice < SLICE_CYCLES and r.slices > 2, r


def test_the_rocket_mission_machine_uploaded_and_activated_at_100_hz_on_a_mega2560(tmp_path):
    from fswkit.reload.sim import timed_upload

    app, built, image, mask = rocket_with_reload(str(tmp_path), 115200)
    assert len(image) + len(mask) == 769  # (758 B before its launch test waited 40 ms armed; 731 B in bytecode format 2)
    # before: 2 late cycles, an overrun each for the uplink task (the commit's
    # step: 11.4 ms) and the mission's (the activation's: 14.2 ms)
    r = timed_upload(built.artifact, "mega2560", app, image, mask)
    assert r.slot in (1, 2), r
    _check(r, "mission")


def test_the_link_s_service_between_cycles_makes_none_late_at_9600_baud_through_a_lossy_link(tmp_path):
    """loop() serves the link and the EEPROM writers between cycles; a pass
    begun just before a cycle's start held the CPU past it: a late cycle
    (`late_other`) in the upload at 9,600 baud with a fifth of the frames
    lost, with seeds 1 and 4 (1 here). No background work starts in the last
    FSW_BACKGROUND_GUARD_US (256) before a cycle now."""
    from fswkit.reload.sim import timed_upload

    app, built, image, mask = rocket_with_reload(str(tmp_path), 9600)
    r = timed_upload(built.artifact, "mega2560", app, image, mask, loss=0.2, seed=1)
    assert r.slot in (1, 2), r
    _check(r, "mission")


def test_the_stand_vent_controller_uploaded_and_activated_at_100_hz_on_an_uno():
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.cli.machine import image_for
    from fswkit.reload.sim import timed_upload
    from fswkit.target.build import firmware, load

    d = Diagnostics()
    app = load(str(EXAMPLES / "stand"), d)
    assert app is not None, d.render()
    built = firmware(app, str(kept_folder(EXAMPLES / "stand", "uno")))  # kept between runs
    assert built.fits, built.report
    got = image_for(app, str(EXAMPLES / "stand" / "tank_700.sm"), d)
    assert got is not None, d.render()
    volts = {"A0": (740 + 125.0) / 250.0}  # the vent controller holds: an allowed state
    # before: no late cycle, but steps of 2.2 ms (uplink) and 2.9 ms (control)
    r = timed_upload(built.artifact, "uno", app, got[0], got[1], analog=volts)
    assert r.slot == 1, r
    _check(r, "control")
