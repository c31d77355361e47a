"""`fsw flash --port` naming a regular file or a folder (the project's
folder, a log: a slip) said pyserial's words, `cannot open stand.app: Could
not configure port: (25, 'Inappropriate ioctl for device')`, where every
other command on a port says what the path is
(test_a_port_that_is_no_device.py): `fsw flash` was left out of that fix.
It says it now, before anything is built."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES

STAND = EXAMPLES / "stand"


@pytest.mark.parametrize("port, words", [
    (str(STAND / "stand.app"), "it is a regular file, not a serial port"),
    (str(STAND), "it is a folder, not a serial port"),
])
def test_a_port_that_is_no_device_is_said_so(fsw, tmp_path, port, words):
    r = fsw("flash", str(STAND), "--port", port, "--out", str(tmp_path / "out"))
    assert r.code == 1, r.err
    assert r.err == f"fsw flash: cannot open {port}: {words}\n", r.err
    assert not (tmp_path / "out").exists()  # refused before the build
