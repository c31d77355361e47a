"""The link built each frame in its own transmit buffer (80 bytes on the
core rocket), then copied it into the UART driver's 64-byte transmit ring,
from which the interrupt sent it: every byte on the wire was held twice,
and the copy cost the CPU its time (the driver's console_write, the link's
pump, the main loop woken to feed the ring). Now the interrupt sends the
frames from the link's buffer where they were built (pal::console_send): the
buffer holds two runs of frames, the one going out and one at its front, and
a frame goes where the UART has already sent. The core rocket keeps no
transmit ring (64 B of RAM and 122 B of flash less), and its demo flight
streams as it did: every frame the ground expects, none lost or dropped."""

from __future__ import annotations

import re
import shutil
import subprocess

import pytest

from support.core_rocket import build_core

sim = pytest.importorskip("fswkit.sim.board")
pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or shutil.which("simavr") is None,
                                reason="gcc-avr / simavr not installed")


@pytest.fixture(scope="module")
def core(tmp_path_factory):
    project, out = build_core(tmp_path_factory)
    return project, out / "rocket.elf"


def test_no_transmit_ring(core):
    nm = subprocess.run(["avr-nm", "-S", "-C", str(core[1])], capture_output=True, text=True, check=True).stdout
    rows = {m.group(2): int(m.group(1), 16) for m in re.finditer(r"^[0-9a-f]+ ([0-9a-f]+) [bBdD] (.+)$", nm, re.M)}
    assert not [n for n in rows if re.search(r"\bg_tx\b|g_txE", n)], nm  # the driver's ring is gone
    link_tx = [size for n, size in rows.items() if "link_tx" in n]
    assert link_tx == [80], rows  # one longest frame (the health frame), where the frames are sent from


def test_the_demo_flight_streams_every_frame(core):
    from fswkit.plant.run import execute, prepare
    from fswkit.sim.command import build as build_for_sim

    project, _ = core
    elf, board = build_for_sim(str(project), "uno", str(project.parent / "sim"))
    _app, layout, sc = prepare(str(project), "rocket", seed=1)
    flight = execute(sc, elf, board, layout, None, quiet=True)
    assert flight.report.passed
    ses = flight.run.session
    assert ses.stats.lost == 0 and ses.health["dropped"] == 0
    assert ses.deframer.stats.crc_errors == 0 and ses.deframer.stats.framing_errors == 0
    # Flight at 50 Hz (2 a frame), Outputs at 10 Hz, a health frame a second, through 46 s of flight
    assert ses.stats.frames >= 1_600 and len(flight.run.samples) >= 2_700, (ses.stats.frames, len(flight.run.samples))
