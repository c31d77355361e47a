"""`fsw ports` and the default port: pyserial's list_ports (replaced here by
the ports a machine with boards attached reports), board guesses from USB
vendor and product IDs, the only candidate as the default of `fsw flash`
and `fsw monitor`."""

from __future__ import annotations

import pytest
from serial.tools import list_ports as lp
from serial.tools.list_ports_common import ListPortInfo

from conftest import EXAMPLES
from fswkit.target import ports


def info(device, vid=None, pid=None, description="n/a"):
    p = ListPortInfo(device, skip_link_detection=True)
    p.vid, p.pid, p.description = vid, pid, description
    return p


UNO = info("/dev/ttyACM0", 0x2341, 0x0043, "Arduino Uno")
CLONE = info("/dev/ttyUSB0", 0x1A86, 0x7523, "USB2.0-Serial")
UART = info("/dev/ttyS0")
ODD = info("/dev/ttyACM1", 0x1234, 0x5678, "Some Gadget")


@pytest.fixture
def attached(monkeypatch):
    def attach(*found):
        monkeypatch.setattr(lp, "comports", lambda *a, **k: list(found))
    return attach


def test_ports_lists_usb_ports_with_board_guesses(fsw, attached):
    attached(UART, CLONE, UNO, ODD)
    r = fsw("ports")
    assert r.code == 0, r.err
    assert r.out.splitlines() == [
        "PORT          WHAT IT SEEMS TO BE                     USB ID     BOARD",
        "/dev/ttyACM0  Arduino Uno                             2341:0043  uno",
        "/dev/ttyACM1  Some Gadget                             1234:5678  -",
        "/dev/ttyUSB0  CH340 USB-serial (Nano and Uno clones)  1a86:7523  nano or uno or mega2560",
    ]


def test_ports_all_adds_built_in_uarts(fsw, attached):
    attached(UART, UNO)
    r = fsw("ports", "--all")
    assert r.code == 0
    assert [line.split()[0] for line in r.out.splitlines()[1:]] == ["/dev/ttyACM0", "/dev/ttyS0"]


def test_no_ports_says_so(fsw, attached):
    attached(UART)
    r = fsw("ports")
    assert r.code == 1
    assert "fsw ports: no serial port found (connect a board by USB; --all lists built-in ports too)" in r.err


def test_the_only_candidate_is_the_default(attached):
    attached(UART, UNO)
    device, listing = ports.default_port(None, "flash")
    assert device == "/dev/ttyACM0" and listing.boards == ("uno",)
    assert ports.default_port("/dev/ttyS0", "flash")[0] == "/dev/ttyS0"  # a named port is taken as named


def test_no_candidate_or_several_is_an_error(attached):
    attached(UART)
    with pytest.raises(ports.PortError, match="no serial port found"):
        ports.default_port(None, "monitor")
    attached(UNO, CLONE)
    with pytest.raises(ports.PortError, match=r"2 serial ports found \(/dev/ttyACM0 \(Arduino Uno, USB 2341:0043\), "
                                              r"/dev/ttyUSB0 .*\): choose one with --port"):
        ports.default_port(None, "monitor")


def test_monitor_without_port_needs_exactly_one(fsw, attached):
    attached(UNO, CLONE)
    r = fsw("monitor", str(EXAMPLES / "tank"))
    assert r.code == 1
    assert "fsw monitor: 2 serial ports found" in r.err and "choose one with --port" in r.err
    attached()
    r = fsw("monitor", str(EXAMPLES / "tank"))
    assert r.code == 1 and "fsw monitor: no serial port found" in r.err
