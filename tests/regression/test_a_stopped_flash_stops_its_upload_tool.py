"""`fsw flash` stopped by SIGTERM or SIGHUP (a `kill`, a closed SSH session)
exited with 143 as docs/cli.md says, but left avrdude running on its own:
still holding the port, still trying the bootloader (up to a minute) or
writing the board's flash after the command had ended, so that the next
`fsw flash` found the port busy. (Ctrl-C on a terminal reached avrdude
too, as one process group.) `fsw flash --via pio` ended PlatformIO's own
process but not what it had started (its build, its avrdude). The upload
tool and everything it started now end with the command, whatever stops
it."""

from __future__ import annotations

import json
import os
import pty
import shutil
import signal
import stat
import subprocess
import sys
import time

import pytest

from conftest import EXAMPLES


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:  # a zombie is gone for the port's sake
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split(") ", 1)[1][0] != "Z"
    except OSError:
        return False


@pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_avrdude_ends_with_the_command(tmp_path, sig):
    master, slave = pty.openpty()
    port = os.ttyname(slave)
    bindir = tmp_path / "bin"
    bindir.mkdir()
    pidfile = tmp_path / "avrdude.pid"
    tool = bindir / "avrdude"
    tool.write_text(f"#!/bin/sh\necho $$ > {pidfile}\nexec sleep 60\n")
    tool.chmod(tool.stat().st_mode | stat.S_IEXEC)
    env = dict(os.environ, PATH=f"{bindir}{os.pathsep}{os.environ['PATH']}")
    fsw = os.path.join(os.path.dirname(sys.executable), "fsw")
    p = subprocess.Popen([fsw, "flash", str(EXAMPLES / "tank"), "--port", port, "--out", str(tmp_path / "build")],
                         env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                         start_new_session=True)
    avrdude = None
    try:
        deadline = time.monotonic() + 120
        while avrdude is None and time.monotonic() < deadline and p.poll() is None:
            if pidfile.exists() and pidfile.read_text().strip():
                avrdude = int(pidfile.read_text())
            time.sleep(0.1)
        assert avrdude is not None, p.stderr.read() if p.poll() is not None else "avrdude never started"
        p.send_signal(sig)  # the command alone, as `kill PID` sends it
        assert p.wait(timeout=30) == 128 + sig
        deadline = time.monotonic() + 10
        while _alive(avrdude) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not _alive(avrdude), "avrdude outlived fsw flash"
        assert "Traceback" not in p.stderr.read()
    finally:
        if p.poll() is None:
            p.kill()
        if avrdude is not None and _alive(avrdude):
            os.kill(avrdude, signal.SIGKILL)
        os.close(slave)
        os.close(master)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_platformio_and_what_it_started_end_with_the_command(tmp_path, sig):
    """`--via pio`: PlatformIO runs its build and avrdude as its children."""
    master, slave = pty.openpty()
    port = os.ttyname(slave)
    fsw = os.path.join(os.path.dirname(sys.executable), "fsw")
    assert subprocess.run([fsw, "new", str(tmp_path / "rocket")], capture_output=True).returncode == 0
    config = [["platformio", [["default_envs", ["uno"]]]], ["env", [["custom_fsw_project", "."]]],
              ["env:uno", [["platform", "atmelavr"], ["board", "uno"], ["custom_fsw_board", "uno"]]]]
    (tmp_path / "config.json").write_text(json.dumps(config))
    pidfile = tmp_path / "child.pid"
    bindir = tmp_path / "bin"
    bindir.mkdir()
    tool = bindir / "pio"
    tool.write_text(f'#!/bin/sh\nif [ "$1" = project ]; then cat {tmp_path / "config.json"}; exit 0; fi\n'
                    f"sh -c 'echo $$ > {pidfile}; exec sleep 60' &\nwait\n")
    tool.chmod(tool.stat().st_mode | stat.S_IEXEC)
    env = dict(os.environ, PATH=f"{bindir}{os.pathsep}{os.environ['PATH']}")
    p = subprocess.Popen([fsw, "flash", str(tmp_path / "rocket"), "--port", port, "--via", "pio"], env=env,
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, start_new_session=True)
    child = None
    try:
        deadline = time.monotonic() + 60
        while child is None and time.monotonic() < deadline and p.poll() is None:
            if pidfile.exists() and pidfile.read_text().strip():
                child = int(pidfile.read_text())
            time.sleep(0.1)
        assert child is not None, p.stderr.read() if p.poll() is not None else "the upload never started"
        p.send_signal(sig)  # the command alone
        assert p.wait(timeout=30) == (130 if sig == signal.SIGINT else 128 + sig)
        deadline = time.monotonic() + 10
        while _alive(child) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not _alive(child), "what PlatformIO started outlived fsw flash"
        assert "Traceback" not in p.stderr.read()
    finally:
        if p.poll() is None:
            p.kill()
        if child is not None and _alive(child):
            os.kill(child, signal.SIGKILL)
        os.close(slave)
        os.close(master)
