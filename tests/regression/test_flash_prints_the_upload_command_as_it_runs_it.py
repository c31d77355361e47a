"""`fsw flash` prints the upload command it runs (`fsw flash: avrdude -p m328p
... -U flash:w:HEX:i`) so that it can be run again by hand, but printed it
words joined by spaces: a project under `~/My Projects/` gave a line that,
pasted, hands avrdude two arguments where it got one. The line is now
quoted for the shell: split as a shell splits it, it is the command run
(`--via pio` alike)."""

from __future__ import annotations

import os
import pty
import shlex
import shutil
import stat

import pytest

from conftest import run_fsw
from fswkit.target import ports


@pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")
def test_the_printed_avrdude_line_is_the_command_run(tmp_path, monkeypatch):
    monkeypatch.setattr(ports, "list_ports", lambda include_all=False: [])
    project = tmp_path / "My Projects" / "rig"
    project.parent.mkdir()
    assert run_fsw("new", str(project)).code == 0
    bindir = tmp_path / "bin"
    bindir.mkdir()
    record = tmp_path / "avrdude.args"
    tool = bindir / "avrdude"
    tool.write_text(f'#!/bin/sh\nprintf "%s\\n" "$@" > "{record}"\necho "avrdude: 10 bytes of flash verified"\n')
    tool.chmod(tool.stat().st_mode | stat.S_IEXEC)
    monkeypatch.setenv("PATH", f"{bindir}{os.pathsep}{os.environ['PATH']}")
    master, slave = pty.openpty()
    try:
        r = run_fsw("flash", str(project), "--port", os.ttyname(slave))
    finally:
        os.close(slave)
        os.close(master)
    assert r.code == 0, r.err
    line = next(l for l in r.err.splitlines() if l.startswith("fsw flash: avrdude "))
    printed = shlex.split(line[len("fsw flash: "):])
    assert printed == ["avrdude"] + record.read_text().split("\n")[:-1], (line, record.read_text())
    assert any(" " in a for a in printed)  # the hex's path, space and all
