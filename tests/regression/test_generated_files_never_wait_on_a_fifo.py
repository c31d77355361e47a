"""`fsw build`, `fsw gen --out` and `fsw gen --sketch` read the file already
at each generated file's place, to leave an unchanged one untouched, or to
see whether a sketch's file is the export's own: a FIFO there (or a link to
a device) hung the command forever, and a link to /dev/zero read until
memory ran out. Such a file is now refused without being opened for long:
`cannot write PATH: not a regular file (a FIFO)`, exit 1, the FIFO left as
it was; a sketch's file that is not a regular file is not the export's to
replace. The build folder's own `fsw-libs/.key` (which cache entry its
links are of) hung `fsw build` the same way; a FIFO there is the kit's
folder's to replace, and the build goes on."""

from __future__ import annotations

import os
import shutil
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import EXAMPLES

FSW = str(Path(sys.executable).parent / "fsw")


def fsw(*argv, cwd) -> subprocess.CompletedProcess:
    # A child process, so that a command that blocks fails the test instead of hanging it.
    return subprocess.run([FSW, *argv], cwd=cwd, capture_output=True, text=True, timeout=60)


@pytest.fixture
def tank(tmp_path):
    for name in ("tank.sv", "tank.sm", "tank.app", "tank.aio", "tank.dio"):
        shutil.copy(EXAMPLES / "tank" / name, tmp_path / name)
    return tmp_path


@pytest.mark.parametrize("argv,place", [
    (("gen", ".", "--out", "out"), "out/app.gen.cpp"),
    (("build", ".", "--board", "native", "--out", "out"), "out/gen/app.gen.cpp"),
])
def test_a_fifo_where_a_generated_file_goes_is_refused_at_once(tank, argv, place):
    (tank / place).parent.mkdir(parents=True)
    (tank / "out" / ".lock").touch()  # a folder the kit built in before (a build goes into no other)
    os.mkfifo(tank / place)
    r = fsw(*argv, cwd=tank)
    assert r.returncode == 1, r.stderr
    assert f"cannot write {place}: not a regular file (a FIFO)" in r.stderr, r.stderr
    assert "Traceback" not in r.stderr
    assert stat.S_ISFIFO(os.lstat(tank / place).st_mode)


def test_a_device_where_a_generated_file_goes_is_not_read(tank):
    (tank / "out").mkdir()
    (tank / "out" / "app.gen.cpp").symlink_to("/dev/zero")
    r = fsw("gen", ".", "--out", "out", cwd=tank)
    assert r.returncode == 1, r.stderr
    assert "cannot write out/app.gen.cpp: not a regular file (a device)" in r.stderr, r.stderr


def test_a_fifo_in_a_sketch_folder_is_not_the_exports_to_replace(tank):
    (tank / "sk").mkdir()
    for name in ("sk.ino", "app.gen.cpp"):
        place = tank / "sk" / name
        os.mkfifo(place)
        r = fsw("gen", ".", "--sketch", "sk", cwd=tank)
        assert r.returncode == 1, r.stderr
        assert f"sk/{name}: a file not written by fsw gen is there" in r.stderr, r.stderr
        assert stat.S_ISFIFO(os.lstat(place).st_mode)
        place.unlink()


def test_a_fifo_in_the_build_folders_links_does_not_hang_the_build(tank):
    (tank / "out" / "fsw-libs").mkdir(parents=True)
    (tank / "out" / ".lock").touch()  # a folder the kit built in before
    os.mkfifo(tank / "out" / "fsw-libs" / ".key")
    r = fsw("build", ".", "--board", "native", "--out", "out", cwd=tank)
    assert r.returncode == 0, r.stderr
    assert (tank / "out" / "tank").is_file()
