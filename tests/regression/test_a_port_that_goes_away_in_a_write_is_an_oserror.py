"""A serial port that went away while a frame was written (a cable pulled,
the board's USB reset) made pyserial's flush() raise termios.error from
tcdrain(), which is no OSError: the ground station's hello thread, which
waits on OSError, died with a traceback (`Exception in thread
fsw-ground-hello ... termios.error: (5, 'Input/output error')`), and
`fsw cmd`'s send let it through the same way. Now every write to a port
drains it through fswkit.link.port.drain, which says it as an OSError, and
port_errors() names termios.error too."""

from __future__ import annotations

import termios
import threading

import pytest


class _PulledPort:
    """A port whose device went away between a write and its drain."""

    def __init__(self):
        self.written = b""

    def write(self, data: bytes) -> int:
        self.written += data
        return len(data)

    def flush(self) -> None:
        raise termios.error(5, "Input/output error")


def test_draining_a_pulled_port_is_an_oserror():
    from fswkit.link.port import drain, port_errors

    with pytest.raises(OSError, match="Input/output error"):
        drain(_PulledPort())
    assert termios.error in port_errors()


def test_a_ground_client_says_a_pulled_port_as_an_oserror():
    from fswkit.link.client import Ground

    g = Ground.__new__(Ground)
    g.port, g.log = _PulledPort(), None
    with pytest.raises(OSError):
        g.send(b"\0")
    assert g.port.written == b"\0"


def test_the_station_says_a_pulled_port_as_an_oserror():
    from fswkit.ground.station import Station

    st = Station.__new__(Station)
    st.port, st._write_lock = _PulledPort(), threading.Lock()
    st._archive = lambda *a, **k: None
    with pytest.raises(OSError):
        st.write(b"\0")
