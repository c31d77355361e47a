"""`fsw sim --eeprom-file FILE` keeps the board's EEPROM in FILE: read at
the start, saved when the board stops. A FIFO given as FILE hung the
command (the harness opened it to read and waited for a writer); a folder
or a device was said to "hold 4096 bytes" (or 0) "of another chip"; a
path in a folder that does not exist, or a save that failed at the end (a
full disk), was dropped in silence with exit 0, so the user believed the
EEPROM kept. Now FILE is checked before the build (a regular file or
nothing yet, in a folder that exists, never a recording), and a save that
fails is said with exit 1; the file there before is left whole."""

from __future__ import annotations

import os
import shutil

import pytest
from conftest import EXAMPLES, run_fsw

from fswkit.sim.board import SimBoard

TANK = EXAMPLES / "tank"


@pytest.mark.parametrize("kind", ["fifo", "folder", "device", "no-folder", "link-log"])
def test_what_cannot_keep_an_eeprom_is_refused_before_any_work(tmp_path, kind):
    path = tmp_path / "ee.bin"
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "folder":
        path.mkdir()
    elif kind == "device":
        path = "/dev/null"
    elif kind == "no-folder":
        path = tmp_path / "gone" / "ee.bin"
    else:
        path.write_bytes(b"FSWLOG1\n" + b"\0" * 1016)  # a recording of the EEPROM's size
    r = run_fsw("sim", str(TANK), "--duration", "0.1", "--fast", "--eeprom-file", str(path))
    assert r.code == 2, r.out + r.err
    assert f"fsw sim: --eeprom-file {path}: " in r.err and "Traceback" not in r.err, r.err
    assert "built" not in r.err  # before any work
    if kind == "link-log":
        assert path.read_bytes() == b"FSWLOG1\n" + b"\0" * 1016


@pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")
def test_a_save_that_fails_is_said(tmp_path):
    out = tmp_path / "build"
    assert run_fsw("build", str(TANK), "--out", str(out)).code == 0
    keep = tmp_path / "keep"
    keep.mkdir()
    ee = keep / "ee.bin"
    b = SimBoard(str(out / "tank.elf"), "uno", uart="control", eeprom_file=str(ee))
    b.step(b.cycles_for(0.01))
    shutil.rmtree(keep)  # its folder gone: the save at the end cannot be made
    assert b.close() != 0
    assert len(b.save_errors) == 1 and b.save_errors[0].startswith(f"cannot save the EEPROM in {ee}: "), b.save_errors
