"""A FIFO (a named pipe) given as a port was called `a device that is not a
terminal` by every command on a port (it is no device), and a Unix socket
got pyserial's words twice over: `cannot open S: [Errno 6] could not open
port S: [Errno 6] No such device or address: 'S'`. Each is now said to be
what it is, not a serial port, in the same words from every command,
before anything is built (`fsw flash`) or opened, exit 1, no traceback."""

from __future__ import annotations

import os
import socket

import pytest

from conftest import EXAMPLES, run_fsw

COMMANDS = {
    "monitor": ("monitor", "--port", "{port}", str(EXAMPLES / "tank"), "--duration", "1"),
    "cmd": ("cmd", "ping", "--port", "{port}", "-p", str(EXAMPLES / "tank")),
    "param": ("param", str(EXAMPLES / "rocket"), "list", "--port", "{port}"),
    "flash": ("flash", str(EXAMPLES / "tank"), "--port", "{port}", "--out", "{tmp}/build"),
}


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_a_fifo_is_said_to_be_one(tmp_path, name):
    port = tmp_path / "pipe"
    os.mkfifo(port)
    argv = [a.format(port=port, tmp=tmp_path) for a in COMMANDS[name]]
    r = run_fsw(*argv)
    assert r.code == 1, r.err
    assert f"cannot open {port}: it is a FIFO (a named pipe), not a serial port" in r.err, r.err
    assert "device" not in r.err and "Traceback" not in r.err
    assert not (tmp_path / "build").exists()  # refused before the build


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_a_socket_is_said_to_be_one(tmp_path, name):
    port = tmp_path / "sock"
    s = socket.socket(socket.AF_UNIX)
    try:
        s.bind(str(port))
        argv = [a.format(port=port, tmp=tmp_path) for a in COMMANDS[name]]
        r = run_fsw(*argv)
    finally:
        s.close()
    assert r.code == 1, r.err
    assert f"cannot open {port}: it is a socket, not a serial port" in r.err, r.err
    assert "Errno" not in r.err and "Traceback" not in r.err
    assert not (tmp_path / "build").exists()
