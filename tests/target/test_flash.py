"""`fsw flash`: avrdude's command line from the board's upload settings
(asserted through a fake avrdude on PATH, writing to a pseudo-terminal as
the port), and a clear message, never a traceback, for a missing port, a
busy port, a wrong board, a board without a bootloader answering, a board
with nothing to upload; `--via pio` runs PlatformIO's upload for the
environment that builds the project."""

from __future__ import annotations

import json
import os
import pty
import shutil
import stat

import pytest
import serial

from conftest import EXAMPLES
from fswkit.target import ports

TANK = EXAMPLES / "tank"
needs_avr = pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")


@pytest.fixture
def port():
    """A pseudo-terminal: a real tty that pyserial and avrdude can open."""
    master, slave = pty.openpty()
    yield os.ttyname(slave)
    os.close(slave)
    os.close(master)


@pytest.fixture(scope="module")
def build_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("flash-build")


def fake_tool(bindir, name, body):
    bindir.mkdir(exist_ok=True)
    tool = bindir / name
    tool.write_text("#!/bin/sh\n" + body)
    tool.chmod(tool.stat().st_mode | stat.S_IEXEC)


@pytest.fixture
def avrdude(tmp_path, monkeypatch):
    """A fake avrdude on PATH: records its arguments, prints what it is told."""
    bindir = tmp_path / "bin"
    record = tmp_path / "avrdude.args"

    def install(output="avrdude: 7758 bytes of flash written\navrdude: 7758 bytes of flash verified\n", status=0):
        (tmp_path / "avrdude.out").write_text(output)
        fake_tool(bindir, "avrdude", f'printf "%s\\n" "$@" > {record}\ncat {tmp_path / "avrdude.out"}\n'
                                     f"exit {status}\n")
        monkeypatch.setenv("PATH", f"{bindir}{os.pathsep}{os.environ['PATH']}")
        return record

    return install


def no_ports(monkeypatch, found=()):
    monkeypatch.setattr(ports, "list_ports", lambda include_all=False: list(found))


@needs_avr
def test_avrdude_gets_the_boards_upload_settings(fsw, avrdude, port, build_dir, monkeypatch):
    no_ports(monkeypatch)
    record = avrdude()
    r = fsw("flash", str(TANK), "--port", port, "--out", str(build_dir))
    assert r.code == 0, r.err
    hexfile = build_dir / "tank.hex"
    assert hexfile.is_file()
    assert record.read_text().split("\n")[:-1] == [
        "-p", "m328p", "-c", "arduino", "-P", port, "-b", "115200", "-D", "-U", f"flash:w:{hexfile}:i"]
    assert "fsw build: tank.app for uno (atmega328p)" in r.out
    assert f"fsw flash: tank.hex is on the uno at {port} (7,758 B, verified)" in r.out


@needs_avr
def test_another_board_takes_its_own_settings(fsw, avrdude, port, tmp_path, monkeypatch):
    no_ports(monkeypatch)
    record = avrdude()
    r = fsw("flash", str(TANK), "--board", "mega2560", "--port", port, "--out", str(tmp_path / "mega"))
    assert r.code == 0, r.err
    args = record.read_text().split("\n")
    assert args[:8] == ["-p", "m2560", "-c", "wiring", "-P", port, "-b", "115200"]


@needs_avr
def test_the_only_connected_port_is_the_default(fsw, avrdude, port, build_dir, monkeypatch):
    no_ports(monkeypatch, [ports.Port(port, "Arduino Uno", 0x2341, 0x0043, "X1")])
    record = avrdude()
    r = fsw("flash", str(TANK), "--out", str(build_dir))
    assert r.code == 0, r.err
    assert f"fsw flash: using {port} (Arduino Uno, USB 2341:0043), the only serial port found" in r.err
    assert record.read_text().split("\n")[5] == port


def test_missing_port_is_a_clear_error(fsw, avrdude, monkeypatch, tmp_path):
    no_ports(monkeypatch)
    record = avrdude()
    r = fsw("flash", str(TANK), "--port", str(tmp_path / "ttyACM9"))
    assert r.code == 1
    assert f"fsw flash: no serial port {tmp_path / 'ttyACM9'}: no board is connected" in r.err
    assert "Traceback" not in r.err and not record.exists()


def test_no_port_and_several_ports_are_clear_errors(fsw, monkeypatch):
    no_ports(monkeypatch)
    r = fsw("flash", str(TANK))
    assert r.code == 1 and "no serial port found: connect the board by USB" in r.err
    no_ports(monkeypatch, [ports.Port("/dev/ttyACM0", "", 0x2341, 0x0043, None),
                           ports.Port("/dev/ttyUSB0", "", 0x1A86, 0x7523, None)])
    r = fsw("flash", str(TANK))
    assert r.code == 1
    assert ("2 serial ports found (/dev/ttyACM0 (Arduino Uno, USB 2341:0043), /dev/ttyUSB0 (CH340 USB-serial "
            "(Nano and Uno clones), USB 1a86:7523)): choose one with --port") in r.err


def test_busy_port_is_a_clear_error(fsw, avrdude, port, monkeypatch):
    no_ports(monkeypatch)
    record = avrdude()
    holder = serial.Serial(port, exclusive=True)  # a serial monitor that has it open
    try:
        r = fsw("flash", str(TANK), "--port", port)
    finally:
        holder.close()
    assert r.code == 1
    assert f"fsw flash: {port} is busy: another program has it open" in r.err
    assert not record.exists()


def test_usb_ids_of_another_board_are_refused(fsw, avrdude, port, monkeypatch):
    no_ports(monkeypatch, [ports.Port(port, "", 0x2341, 0x0042, None)])
    record = avrdude()
    r = fsw("flash", str(TANK), "--port", port)
    assert r.code == 1
    assert (f"the board on {port} looks like an Arduino Mega 2560 (USB 2341:0042), not a uno: flash it with "
            "--board mega2560, or add --force if it is a uno after all") in r.err
    assert not record.exists()


WRONG_MCU = """\
avrdude: AVR device initialized and ready to accept instructions
avrdude: device signature = 0x1e9801 (probably m2560)
avrdude: Expected signature for ATmega328P is 1E 95 0F
avrdude: Double check chip or use -F to override this check.
"""

NO_BOOTLOADER = """\
avrdude: stk500_recv(): programmer is not responding
avrdude: stk500_getsync() attempt 10 of 10: not in sync: resp=0x00
"""


@needs_avr
@pytest.mark.parametrize("output, message", [
    (WRONG_MCU, "the board on {port} is not a uno: its MCU answers with signature 0x1e9801 (ATmega2560), "
                "a uno has an atmega328p: choose its board with --board"),
    (NO_BOOTLOADER, "no answer from a bootloader on {port} (arduino protocol at 115200 baud): is it a uno"),
    ("avrdude: something nobody expected\n", "avrdude failed (exit status 1):\n  avrdude: something nobody expected"),
])
def test_avrdude_failures_are_explained(fsw, avrdude, port, build_dir, monkeypatch, output, message):
    no_ports(monkeypatch)
    avrdude(output, status=1)
    r = fsw("flash", str(TANK), "--port", port, "--out", str(build_dir))
    assert r.code == 1
    assert message.format(port=port) in r.err
    assert "Traceback" not in r.err


def test_native_board_has_nothing_to_flash(fsw):
    r = fsw("flash", str(TANK), "--board", "native", "--port", "/dev/null")
    assert r.code == 2 and "board `native` runs on this computer, there is nothing to upload" in r.err


def test_unknown_board_and_bad_project(fsw, tmp_path):
    r = fsw("flash", str(TANK), "--board", "pdp11", "--port", "/dev/null")
    assert r.code == 2 and "unknown board `pdp11`" in r.err
    r = fsw("flash", str(tmp_path), "--port", "/dev/null")
    assert r.code == 2 and "expected one application config (.app)" in r.err


def test_via_pio_uploads_the_environment_that_builds_the_project(fsw, port, tmp_path, monkeypatch):
    """`--via pio` finds platformio.ini, asks PlatformIO for its environments
    (`pio project config`, answered here as PlatformIO 6.2 answers it) and
    runs the upload of the one whose project and board are these."""
    no_ports(monkeypatch)
    assert fsw("new", str(tmp_path / "rocket"), "--board", "uno").code == 0
    project = tmp_path / "rocket"
    config = [["platformio", [["default_envs", ["uno"]]]],
              ["env", [["custom_fsw_project", "."]]],
              ["env:native", [["platform", "native"], ["custom_fsw_board", "native"]]],
              ["env:uno", [["platform", "atmelavr"], ["board", "uno"], ["custom_fsw_board", "uno"]]]]
    (tmp_path / "config.json").write_text(json.dumps(config))
    record = tmp_path / "pio.args"
    fake_tool(tmp_path / "bin", "pio", f'if [ "$1" = project ]; then cat {tmp_path / "config.json"}; exit 0; fi\n'
                                       f'printf "%s\\n" "$@" > {record}\n')
    monkeypatch.setenv("PATH", f"{tmp_path / 'bin'}{os.pathsep}{os.environ['PATH']}")
    r = fsw("flash", str(project), "--port", port, "--via", "pio")
    assert r.code == 0, r.err
    assert record.read_text().split("\n")[:-1] == ["run", "-d", str(project), "-e", "uno", "-t", "upload",
                                                  "--upload-port", port]
    # No environment for this board: said, with the environments there are.
    r = fsw("flash", str(project), "--port", port, "--via", "pio", "--board", "nano")
    assert r.code == 2
    assert "builds rocket.app for the nano (custom_fsw_project and custom_fsw_board; environments: native, uno)" \
        in r.err
