"""`fsw new NAME --board BOARD`: the project it writes passes `fsw check`,
`fsw test` and `fsw build` untouched; PlatformIO reads its platformio.ini;
bad names, taken folders and unknown boards are refused clearly."""

from __future__ import annotations

import shutil

import pytest

from conftest import ROOT, needs_pio, project_config

needs_avr = pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")


def test_scaffold_files(fsw, tmp_path):
    r = fsw("new", str(tmp_path / "rocket"), "--board", "uno")
    assert r.code == 0, r.err
    names = sorted(p.name for p in (tmp_path / "rocket").iterdir())
    assert names == [".gitignore", "README.md", "platformio.ini", "rocket.aio", "rocket.app", "rocket.dio",
                     "rocket.sm", "rocket.ss", "rocket.sv"]
    aio = (tmp_path / "rocket" / "rocket.aio").read_text()
    assert "analog inputs: A0=14 A1=15 A2=16 A3=17 A4=18 A5=19" in aio
    assert "PWM pins (analog outputs): 3 5-6 11\n#   not 9 or 10: their timer (Timer1) paces the executor" in aio
    dio = (tmp_path / "rocket" / "rocket.dio").read_text()
    assert "digital pins: 2-19 (A0-A5 are 14-19)" in dio
    assert "reserved: 0: serial RX (USART0)" in dio
    ss = (tmp_path / "rocket" / "rocket.ss").read_text()
    assert ss.startswith("# State-script skeleton for rocket.sm, made by `fsw skeleton`.")
    assert "Closed -> Open when pressure > P_Open" in ss and "Open -> Closed when pressure < P_Close" in ss
    assert "board uno" in (tmp_path / "rocket" / "rocket.app").read_text()


@needs_avr
def test_scaffold_passes_check_test_and_build_untouched(fsw, tmp_path):
    assert fsw("new", "rocket", "--board", "uno", cwd=tmp_path).code == 0
    project = tmp_path / "rocket"
    r = fsw("check", ".", "--strict", cwd=project)
    assert r.code == 0, r.err
    assert "fsw check: 4 files, 0 errors, 0 warnings" in r.err
    r = fsw("test", "rocket.ss", cwd=project)
    assert r.code == 0, r.out + r.err
    assert "5 asserts passed" in r.out
    assert fsw("test", "rocket.ss", "--board", "uno", cwd=project).code == 0
    r = fsw("build", ".", cwd=project)
    assert r.code == 0, r.err
    assert "fsw build: rocket.app for uno (atmega328p)" in r.out
    assert (project / "build" / "uno" / "rocket.hex").is_file()


@pytest.mark.parametrize("board", ["nano", "mega2560", "native"])
def test_scaffold_for_every_board_checks(fsw, tmp_path, board):
    assert fsw("new", str(tmp_path / "p"), "--board", board).code == 0
    r = fsw("check", str(tmp_path / "p"), "--strict")
    assert r.code == 0, r.err
    assert f"board {board}" in (tmp_path / "p" / "p.app").read_text()


@needs_pio
def test_scaffold_platformio_ini_parses(fsw, tmp_path):
    assert fsw("new", str(tmp_path / "rocket"), "--board", "mega2560").code == 0
    cfg = project_config(tmp_path / "rocket", tmp_path)
    env = cfg["env:mega2560"]
    assert env["platform"] == "atmelavr" and env["board"] == "megaatmega2560"
    assert env["custom_fsw_board"] == "mega2560"
    assert env["extra_scripts"] == [f"pre:{ROOT}/integrations/platformio/pio_hook.py"]
    assert env["lib_deps"] == [f"fswkit=symlink://{ROOT}/firmware"]
    assert cfg["env:native"]["platform"] == "native"
    assert cfg["platformio"]["default_envs"] == ["mega2560"]


@pytest.mark.parametrize("name, message", [
    ("9lives", "`9lives` cannot name a project"),
    ("my-rocket", "`my-rocket` cannot name a project"),
    ("not", "`not` is a keyword of the config languages"),
])
def test_bad_names_are_refused(fsw, tmp_path, name, message):
    r = fsw("new", str(tmp_path / name))
    assert r.code == 2
    assert message in r.err
    assert not (tmp_path / name).exists()


def test_taken_folder_and_unknown_board_are_refused(fsw, tmp_path):
    (tmp_path / "rocket").mkdir()
    (tmp_path / "rocket" / "notes.txt").write_text("ours\n")
    r = fsw("new", str(tmp_path / "rocket"))
    assert r.code == 1 and "already exists: choose a new folder" in r.err
    assert (tmp_path / "rocket" / "notes.txt").read_text() == "ours\n"
    r = fsw("new", str(tmp_path / "x"), "--board", "pdp11")
    assert r.code == 2 and "unknown board `pdp11`" in r.err
