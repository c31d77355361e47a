"""The station's hello thread wrote to the port while the reader, which had
seen the port go away, closed it: pyserial, its descriptor gone from under
the write, raised TypeError, which ended the thread with a traceback (seen
as pytest's unhandled-thread-exception warning in the pseudo-terminal
test). Now a write to a port closed under it is the port gone, as a write
after it is: OSError `the port is not open (it went away)`, which the
hello and every command take as such. A TypeError from a port still open
is a defect and stays one. And a test whose thread ends in an exception
fails (pyproject.toml: the warning is an error)."""

from __future__ import annotations

import pytest
from support.linkstream import TANK, layout_of

from fswkit.ground.station import Station


class _Port:
    """A pyserial port as the reader leaves it mid-write: closed, its
    descriptor None (or, `open`, one that fails the same way still open)."""

    def __init__(self, open_: bool):
        self.is_open = open_

    def write(self, data: bytes) -> int:
        raise TypeError("argument must be an int, or have a fileno() method.")


def test_a_port_closed_under_a_write_is_the_port_gone():
    st = Station(layout_of(TANK), "tank", "/dev/null", 115200, serve=False)
    st.port = _Port(open_=False)
    with pytest.raises(OSError, match=r"^the port is not open \(it went away\)$"):
        st.write(b"\0")
    st.port = _Port(open_=True)
    with pytest.raises(TypeError):
        st.write(b"\0")
