"""`--port` naming a regular file or a folder (a slip: the project's folder,
a log) went to pyserial, whose words were `cannot open stand.app: Could not
configure port: (25, 'Inappropriate ioctl for device')`; a port that does
not exist was `cannot open /dev/ttyNOPE: [Errno 2] could not open port
/dev/ttyNOPE: [Errno 2] No such file or directory: '/dev/ttyNOPE'`. Each
now says what the path is, once, with status 1, as every command that
opens a port (`fsw machine`, `fsw param`, `fsw monitor`...) does."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES

STAND = EXAMPLES / "stand"


@pytest.mark.parametrize("port, words", [
    (str(STAND / "stand.app"), "it is a regular file, not a serial port"),
    (str(STAND), "it is a folder, not a serial port"),
    ("/dev/ttyNOPE", "no such port"),
])
@pytest.mark.parametrize("argv", [("machine", str(STAND), "list"), ("monitor", str(STAND), "--headless")])
def test_a_port_that_is_no_device_is_said_so(fsw, port, words, argv):
    r = fsw(*argv, "--port", port)
    assert r.code == 1, r.err
    assert f"cannot open {port}: {words}" in r.err, r.err
    assert "Errno" not in r.err and "ioctl" not in r.err and "Traceback" not in r.err
