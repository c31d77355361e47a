"""`fsw ground` stopping while its reader is inside a read: stop() waits 2 s
for the reader thread, then closes the port; pyserial's read on a port
closed under it raises TypeError (its file descriptor is None), which used
to end the reader thread with a traceback on the console. The reader now
ends quietly when the station is stopping, and still raises such an error
when it is not (a defect to see, not to hide)."""

from __future__ import annotations

import pytest

from fswkit.ground.station import Station
from support.linkfw import tank_layout
from conftest import EXAMPLES


class ClosedUnderTheReader:
    """A port that stop() closes while the reader is in `read`."""

    def __init__(self, station, stopping: bool):
        self.station, self.stopping = station, stopping
        self.in_waiting = 0
        self.is_open = True

    def read(self, n):
        if self.stopping:
            self.station._stop.set()  # stop() ran meanwhile ...
        self.is_open = False  # ... and closed the port
        raise TypeError("'NoneType' object cannot be interpreted as an integer")

    def close(self):
        self.is_open = False


def station() -> Station:
    return Station(tank_layout(), str(EXAMPLES / "tank"), "/dev/null", 115200, serve=False)


def test_a_read_on_a_port_stop_closed_ends_the_reader_quietly():
    st = station()
    st.port = ClosedUnderTheReader(st, stopping=True)
    st._read_loop()  # returns: no exception out of the reader thread
    assert st._stop.is_set()


def test_the_same_error_while_running_is_not_swallowed():
    st = station()
    st.port = ClosedUnderTheReader(st, stopping=False)
    with pytest.raises(TypeError):
        st._read_loop()
