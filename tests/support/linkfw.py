"""Helpers for the link tests: the tank example built for the host, run on
a pseudo-terminal (a serial port for the ground tools) or on the simulated
clock with its link bytes captured."""

from __future__ import annotations

import os
import pty
import shutil
import subprocess
import tty
from pathlib import Path

from conftest import EXAMPLES

TANK = EXAMPLES / "tank"


def build_native(project: Path) -> Path:
    """The project built for the host into build/sim-tests/ (kept between
    runs, built once for every test file: support.simfw.kept_native); its
    executable."""
    from support.simfw import kept_native

    return kept_native(project) / project.name


def tank_layout(project: Path = TANK):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import load
    from fswkit.link.layout import from_app

    return from_app(load(str(project), Diagnostics()))


def control_commands(lay) -> list[tuple[int, bytes]]:
    """The link's control commands every application answers, as (op,
    args): PING, HELLO, SNAPSHOT, a SET of the rocket's `abortCmd` to 0, a
    MODE of task 0 to safed."""
    import struct

    from fswkit.autocode import protocol as P

    abort = lay.element("abortCmd").index
    return [(P.OP_PING, b""), (P.OP_HELLO, b""), (P.OP_SNAPSHOT, b""),
            (P.OP_SET, struct.pack("<HB", abort, 0)), (P.OP_MODE, bytes((0, 2)))]


def hello_seq(board, session) -> int:
    """A simulated board's first 1.5 s (its hello, and a health frame)
    read into `session`; the hello's last command number, after which the
    next command goes."""
    board.run_for(1.5)
    session.feed(board.uart_read())
    assert session.hello is not None and session.hello["schema_ok"], session.hello
    return session.hello["last_seq"]


def send_one_at_a_time(board, session, commands, seq: int) -> None:
    """Each (op, args) of `commands` sent to a simulated board as command
    seq + 1, seq + 2, ..., 0.1 s apart (one ack waits at a time), what came
    back fed to `session`."""
    from fswkit.link import wire

    for k, (op, args) in enumerate(commands, start=1):
        board.uart_write(wire.uplink(op, seq + k, args))
        board.run_for(0.1)
        session.feed(board.uart_read())


def volts_psi(raw: int) -> float:
    """tank.aio's calibration in binary64 (the native build's R)."""
    return raw * 5.0 / 1023.0 * 250.0 + -125.0


class PtyTarget:
    """The host build of the firmware with its console on a pty: the pty's
    slave path is the port the ground tools open."""

    def __init__(self, exe: Path, *args: str):
        master, slave = pty.openpty()
        tty.setraw(slave)
        self.port = os.ttyname(slave)
        self._slave = slave
        self.proc = subprocess.Popen([str(exe), *args], stdin=master, stdout=master, stderr=subprocess.DEVNULL)
        os.close(master)

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(timeout=5)

    def close(self) -> None:
        self.stop()
        os.close(self._slave)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def needs_cxx():
    import pytest

    return pytest.mark.skipif(shutil.which("g++") is None, reason="no host C++ compiler")


def simulated_link(exe: Path, cycles: int, *args: str) -> bytes:
    """The link bytes of `cycles` executor cycles on the simulated clock."""
    r = subprocess.run([str(exe), str(cycles), "--link", *args], capture_output=True, check=True)
    assert b"console overruns: 0" in r.stderr, r.stderr
    return r.stdout
