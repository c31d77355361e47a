"""Every port the ground opens for a project runs at that project's link
rate: `fsw monitor` and `fsw cmd` open it at the application's `baud` (the
default the firmware itself uses when the .app sets none), not at a fixed
115200; an explicit `--baud` other than the application's is honoured, with
one warning naming the application's rate. The rate checked is the one the
port's terminal settings hold (a pseudo-terminal keeps what was set)."""

from __future__ import annotations

import struct
import termios

import pytest
from conftest import run_fsw
from support.linkstream import PtyStream, PtyTarget, hello, layout_of, tank_copy

from fswkit.link import wire

SPEED = {termios.B9600: 9600, termios.B19200: 19200, termios.B38400: 38400, termios.B57600: 57600,
         termios.B115200: 115200}


def _speed(fd: int) -> int:
    return SPEED[termios.tcgetattr(fd)[5]]


def _with_baud(project, baud: int | None):
    app = project / "tank.app"
    text = app.read_text()
    if baud is not None:
        text = text.replace("rate  100\n", f"rate  100\nbaud  {baud}\n", 1)
        assert f"baud  {baud}" in text
    app.write_text(text)
    return project


@pytest.fixture(scope="module")
def quiet(tmp_path_factory):
    """The tank without its uplink (the monitor only waits for a hello): at
    57600 baud, and as it was (no `baud`)."""
    base = tmp_path_factory.mktemp("baud")
    slow = _with_baud(tank_copy(base / "slow", uplink=False), 57600)
    plain = _with_baud(tank_copy(base / "plain", uplink=False), None)
    return slow, plain


def _monitor(project, *extra):
    layout = layout_of(project)
    with PtyStream(layout, hello_first=True) as target:
        r = run_fsw("monitor", str(project), "--port", target.port, "--headless", "--frames", "5", *extra)
        return r, _speed(target.slave)


def test_monitor_uses_the_application_baud(quiet):
    slow, _ = quiet
    r, speed = _monitor(slow)
    assert r.code == 0, r.err
    assert speed == 57600
    assert "baud" not in r.err  # the rate the application runs at: nothing to warn about


def test_monitor_without_baud_in_the_app_uses_the_firmware_default(quiet):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import load

    _, plain = quiet
    r, speed = _monitor(plain)
    assert r.code == 0, r.err
    assert speed == load(str(plain), Diagnostics()).baud  # what the generated console_begin() gets


def test_monitor_explicit_other_baud_is_honoured_with_one_warning(quiet):
    slow, _ = quiet
    r, speed = _monitor(slow, "--baud", "115200")
    assert r.code == 0, r.err
    assert speed == 115200
    assert r.err.count("the application runs its link at 57600 baud") == 1, r.err


class Responder(PtyTarget):
    """A target with an uplink on a pseudo-terminal: answers a `hello`
    command with a hello frame, and acknowledges every command (OK)."""

    def __init__(self, layout):
        super().__init__()
        self.layout = layout
        self.start()

    def _run(self) -> None:
        import os
        import select

        buf = b""
        n = 1
        while not self._stop.is_set():
            r, _, _ = select.select([self.master], [], [], 0.05)
            if not r:
                continue
            try:
                buf += os.read(self.master, 4096)
            except OSError:
                return
            *frames, buf = buf.split(b"\0")
            for enc in frames:
                body = wire.cobs_decode(enc) if enc else None
                if body is None or len(body) < 5 or wire.crc16(body) != 0:
                    continue
                op, cseq = body[0], body[1] | body[2] << 8
                out = hello(self.layout, n, 10 * n) if op == wire.OP_HELLO else b""
                n += 1
                out += wire.downlink(wire.ACK, n, 10 * n, struct.pack("<HBBH", cseq, op, 0, cseq))
                n += 1
                os.write(self.master, out)


@pytest.mark.parametrize("extra, rate, warned", [((), 19200, False), (("--baud", "9600"), 9600, True),
                                                 (("--baud", "19200"), 19200, False)])
def test_cmd_uses_the_application_baud(tmp_path, extra, rate, warned):
    project = _with_baud(tank_copy(tmp_path), 19200)
    target = Responder(layout_of(project))
    try:
        r = run_fsw("cmd", "ping", "--port", target.port, "-p", str(project), *extra)
        speed = _speed(target.slave)
    finally:
        target.close()
    assert r.code == 0, r.err
    assert speed == rate
    assert r.err.count("the application runs its link at 19200 baud") == (1 if warned else 0), r.err
