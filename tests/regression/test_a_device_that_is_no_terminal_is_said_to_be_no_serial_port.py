"""A device that is not a terminal given as a port (`--port /dev/null`, a
disk, `/dev/zero`: a slip of the keyboard) got pyserial's own words from
every command on a port: `cannot open /dev/null: Could not configure port:
(25, 'Inappropriate ioctl for device')`. A regular file or a folder was
already said to be no serial port (docs/cli.md, fsw monitor); such a
device now is too, in the same words from every command, exit 1 and no
traceback."""

from __future__ import annotations

import os

import pytest

from conftest import EXAMPLES, run_fsw

DEVICE = "/dev/null"  # a character device that is no terminal

COMMANDS = {
    "monitor": ("monitor", "--port", DEVICE, str(EXAMPLES / "tank"), "--duration", "1"),
    "cmd": ("cmd", "ping", "--port", DEVICE, "-p", str(EXAMPLES / "tank")),
    "ground": ("ground", str(EXAMPLES / "tank"), "--port", DEVICE, "--no-web", "--no-archive"),
    "param": ("param", str(EXAMPLES / "rocket"), "list", "--port", DEVICE),
    "dump": ("dump", str(EXAMPLES / "rocket"), "--port", DEVICE, "-o", "{tmp}/flights"),
    "machine": ("machine", str(EXAMPLES / "stand"), "list", "--port", DEVICE),
    "flash": ("flash", str(EXAMPLES / "tank"), "--port", DEVICE),
}


@pytest.mark.skipif(not os.path.exists(DEVICE), reason="needs /dev/null")
@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_command_on_a_port_says_a_device_that_is_no_terminal_is_no_serial_port(tmp_path, name):
    argv = [a.replace("{tmp}", str(tmp_path)) for a in COMMANDS[name]]
    r = run_fsw(*argv)
    assert r.code == 1, r.err
    assert f"cannot open {DEVICE}: it is a device that is not a terminal, not a serial port" in r.err
    assert "Inappropriate ioctl" not in r.err and "(25," not in r.err and "Traceback" not in r.err
