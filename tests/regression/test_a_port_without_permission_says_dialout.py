"""A serial port the system would not open for the user (on Linux the
devices belong to the `dialout` group: a newcomer's first trouble) got the
`dialout` advice from `fsw flash` only; `fsw monitor`, `fsw ground`, `fsw
cmd`, `fsw param` and `fsw dump` said `cannot open PORT: [Errno 13] could
not open port PORT: [Errno 13] Permission denied: 'PORT'`. Every command
that opens a port now says what to do."""

from __future__ import annotations

import errno

import pytest
import serial

from fswkit.link import port as ports

WORDS = ("no permission to open /dev/ttyACM7: add yourself to the `dialout` group (sudo usermod -aG dialout "
         "$USER, then log in again)")


def _refuse(*_a, **_k):
    raise serial.SerialException(errno.EACCES, "could not open port /dev/ttyACM7: [Errno 13] Permission denied: "
                                               "'/dev/ttyACM7'")


@pytest.mark.parametrize("command", [None, "fsw monitor"])
def test_opening_a_port_without_permission_says_dialout(monkeypatch, tmp_path, command):
    monkeypatch.setenv("FSW_RUNTIME_DIR", str(tmp_path / "run"))
    monkeypatch.setattr(ports, "not_a_port", lambda name: None)  # as a real device would pass
    monkeypatch.setattr(serial, "serial_for_url", _refuse)
    monkeypatch.setattr(ports, "_held_serial", lambda: _refuse)
    with pytest.raises(ports.PortError) as e:
        ports.open_port("/dev/ttyACM7", 115200, command=command)
    assert str(e.value) == WORDS


def test_flash_says_it_in_the_same_words():
    from fswkit.target.flash import _port_problem

    assert _port_problem("/dev/ttyACM7", errno.EACCES, "Permission denied") == WORDS
    assert ports.denied("/dev/ttyACM7", None, "open failed: Permission denied") == WORDS
    assert ports.denied("/dev/ttyACM7", errno.ENOENT, "No such file or directory") is None
