"""A FIFO named as a config hung `fsw check` forever; `/dev/zero` raised
MemoryError. Every config, state script, board and plant parameters file is
now read in one place, which refuses what is not a regular file without
reading it, and a file over the stated size (MAX_INPUT)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import EXAMPLES

from fswkit.autocode.diagnostics import MAX_INPUT

FSW = str(Path(sys.executable).parent / "fsw")


def fsw(*argv, cwd) -> subprocess.CompletedProcess:
    # A child process, so that a reader that blocks fails the test, not hangs it.
    return subprocess.run([FSW, *argv], cwd=cwd, capture_output=True, text=True, timeout=30)


@pytest.fixture
def tank(tmp_path):
    for name in ("tank.sv", "tank.sm", "tank.ss", "tank.app", "tank.aio", "tank.dio", "plant.toml"):
        (tmp_path / name).write_bytes((EXAMPLES / "tank" / name).read_bytes())
    return tmp_path


@pytest.mark.parametrize("name,lang", [("tank.sv", "state vector config"), ("tank.sm", "state machine config"),
                                       ("tank.ss", "state script"), ("tank.app", "application config"),
                                       ("tank.aio", "application config")])
def test_a_fifo_config_is_refused_at_once(tank, name, lang):
    (tank / name).unlink()
    os.mkfifo(tank / name)
    target = "tank.app" if name.endswith(".aio") else name
    r = fsw("check", target, cwd=tank)
    assert r.returncode == 1, r.stderr
    assert f"{lang} error @ {name}:1:1:" in r.stderr
    assert "cannot read file: not a regular file (a FIFO)" in r.stderr


def test_a_device_config_is_refused(tank):
    (tank / "tank.sm").unlink()
    (tank / "tank.sm").symlink_to("/dev/zero")
    r = fsw("check", "tank.sm", cwd=tank)
    assert r.returncode == 1 and "internal error" not in r.stderr
    assert "tank.sm:1:1:" in r.stderr and "not a regular file (a device)" in r.stderr


@pytest.mark.skipif(not hasattr(__import__("socket"), "AF_UNIX"), reason="no Unix sockets")
def test_a_socket_config_is_named_as_one(tank):
    # Opening a Unix socket fails (ENXIO) before the file's kind is known:
    # the message still says what it is, not "No such device or address".
    import socket
    (tank / "tank.sv").unlink()
    with socket.socket(socket.AF_UNIX) as sock:
        sock.bind(str(tank / "tank.sv"))
        r = fsw("check", "tank.sv", cwd=tank)
    assert r.returncode == 1, r.stderr
    assert "tank.sv:1:1:" in r.stderr and "not a regular file (a socket)" in r.stderr, r.stderr


def test_a_fifo_state_script_is_refused_by_fsw_test(tank):
    (tank / "tank.ss").unlink()
    os.mkfifo(tank / "tank.ss")
    r = fsw("test", "tank.ss", cwd=tank)
    assert r.returncode == 2 and "not a regular file (a FIFO)" in r.stderr


def test_size_limit_boundary(tank):
    """MAX_INPUT bytes are read (and checked); one byte more is refused."""
    sv = (tank / "tank.sv").read_bytes()
    (tank / "tank.sv").write_bytes(sv + b"#" * (MAX_INPUT - len(sv)))
    r = fsw("check", "tank.sv", cwd=tank)
    assert r.returncode == 0, r.stderr
    (tank / "tank.sv").write_bytes(sv + b"#" * (MAX_INPUT + 1 - len(sv)))
    r = fsw("check", "tank.sv", cwd=tank)
    assert r.returncode == 1
    assert f"tank.sv:1:1:\n  | \n  | ^ cannot read file: file too large: {MAX_INPUT + 1:,} bytes" in r.stderr


def test_plant_parameters_from_a_fifo_are_refused(tank):
    os.unlink(tank / "plant.toml")
    os.mkfifo(tank / "plant.toml")
    code = ("from fswkit.plant.params import ParamsError, load\n"
            "from fswkit.plant.scenario import SCHEMAS\n"
            "try:\n"
            "    load('plant.toml', SCHEMAS['tank'])\n"
            "except ParamsError as e:\n"
            "    print(e.errors)\n")
    r = subprocess.run([sys.executable, "-c", code], cwd=tank, capture_output=True, text=True, timeout=30)
    assert r.returncode == 0, r.stderr
    assert "plant.toml: not a regular file (a FIFO)" in r.stdout


@pytest.mark.parametrize("argv,expect", [
    (("log2csv", "x.log", "-o", "x.csv"), "cannot read x.log: not a regular file (a FIFO)"),
    (("replay", "x.log"), "cannot read x.log: not a regular file (a FIFO)"),
    (("sim", "x.elf", "--board", "uno"), "x.elf: not a regular file (a FIFO)"),
])
def test_a_fifo_log_or_firmware_is_refused_at_once(tmp_path, argv, expect):
    os.mkfifo(tmp_path / argv[1])
    r = fsw(*argv, cwd=tmp_path)
    assert r.returncode != 0 and expect in r.stderr, r.stderr
    assert not (tmp_path / "x.csv").exists()
