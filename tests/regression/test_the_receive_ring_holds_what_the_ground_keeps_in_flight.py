"""The kit's UART driver gave every application a 64-byte receive ring
(FSW_CONSOLE_RX_SIZE), sized for the parameter client, which keeps up to 90
bytes of commands in flight (fswkit.param.client RX_WINDOW; the reload
commands go through it too). An application without parameters or reload
has no such client: its ground sends one command and waits for the ack
(the link client, the ground station's lock), so at most 27 bytes wait for
the uplink task's next run, and 32 of the core rocket's RAM went unused.
Now the generated code sizes the ring for what its ground keeps in flight:
32 bytes for one command, 4 without an uplink task (nothing reads it), the
runtime's 64 where the ground pipelines; a program that does not size it
gets the runtime's, and a command of the longest kind still arrives whole
in one burst."""

from __future__ import annotations

import re
import shutil
import struct
import subprocess

import pytest

from conftest import EXAMPLES, ROOT, run_fsw
from fswkit.autocode.emit import app as emit_app
from fswkit.link import wire
from fswkit.link.layout import from_app
from fswkit.link.session import Session
from fswkit.param.client import RX_CAP
from support.core_rocket import build_core, core_project
from support.simfw import project_elf

sim = pytest.importorskip("fswkit.sim.board")
pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or shutil.which("simavr") is None,
                                reason="gcc-avr / simavr not installed")

ROCKET = EXAMPLES / "rocket"


def _ring(elf) -> int | None:
    nm = subprocess.run(["avr-nm", "-S", str(elf)], capture_output=True, text=True, check=True).stdout
    m = re.search(r"^[0-9a-f]+ ([0-9a-f]+) [bBdD] fsw_console_rx$", nm, re.M)
    return int(m.group(1), 16) if m else None


@pytest.fixture(scope="module")
def core(tmp_path_factory):
    project, out = build_core(tmp_path_factory)
    return project, out / "rocket.elf"


def test_one_command_in_flight_fits_the_ring():
    # the longest burst of one command: the handshake's lone delimiter (fswkit.link.client), the
    # command's leading delimiter, its encoded frame (at most the link's receive buffer) and its
    # closing delimiter
    args = b"\x01" * 3
    leading = len(wire.uplink(wire.OP_SET, 1, args)) - len(wire.frame(bytes((wire.OP_SET, 1, 0)) + args))
    burst = 1 + leading + RX_CAP + 1
    fw_cap = re.search(r"#  define FSW_LINK_RX_CAP (\d+)", (ROOT / "firmware/src/fsw_config.h").read_text())
    assert fw_cap and int(fw_cap.group(1)) == RX_CAP
    ring = getattr(emit_app, "CONSOLE_RX_ONE_COMMAND", None)  # the generator's size for one command
    assert burst == 27 and ring == 32 and burst <= ring - 1  # one free slot tells full from empty


def test_the_ring_is_sized_for_the_ground(core):
    assert _ring(core[1]) == 32  # no parameters, no reload: one command in flight
    elf = project_elf(str(ROCKET), "uno")  # kept between runs (support.simfw)
    assert _ring(elf) == 64  # parameters: the client pipelines


def test_a_telemetry_only_application_keeps_the_smallest_ring(tmp_path):
    project = core_project(tmp_path)
    app = project / "rocket.app"
    text = re.sub(r"(?m)^uplink\s+uplink\b.*\n", "", app.read_text())
    app.write_text(re.sub(r"\n\[uplink\]\n\w+\n", "\n", text))
    r = run_fsw("gen", str(project), "--out", str(tmp_path / "gen"))
    assert r.code == 0, r.err
    gen = (tmp_path / "gen" / "app.gen.cpp").read_text()
    assert "uint8_t fsw_console_rx[4];" in gen and "fsw_console_rx_mask = 3;" in gen, gen[:1500]


def test_the_longest_burst_arrives_whole(core):
    """27 bytes at once, a command last: the ring holds them until the
    uplink task's next run, which applies the command."""
    project, elf = core
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import load

    lay = from_app(load(str(project), Diagnostics()))
    s = Session(lay)
    with sim.SimBoard(str(elf), "uno", sim_limit=30, wall_limit=120) as b:
        b.run_for(1.0)
        s.feed(b.uart_read())
        assert s.hello is not None
        seq = s.hello["last_seq"] + 1
        frame = wire.uplink(wire.OP_SET, seq, struct.pack("<HB", lay.element("abortCmd").index, 1))
        b.uart_write(b"\0" * (27 - len(frame)) + frame)
        b.run_for(0.3)
        s.feed(b.uart_read())
        assert [(a["cmd_seq"], a["status_name"]) for a in s.acks] == [(seq, "OK")]
        assert s.values["abortCmd"] is True
