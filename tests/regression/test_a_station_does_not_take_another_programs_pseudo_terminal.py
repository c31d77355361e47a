"""A station whose port went away opened it again as soon as a device was
back at its name, every 0.25 s. A pseudo-terminal does not come back: when
its other end closes, the system gives the next one it makes the same
number (/dev/pts/N), which is another program's, a terminal window's say.
The station took it: it wrote a hello into it and read what came as link
bytes (seen as a test's station taking the pseudo-terminal of a test
running beside it: `/dev/pts/0 is busy`). Now a port named by its own
/dev/pts path is never opened again once it went away, and the station
says why; one named by a link (a simulator's, socat's `link=`) is opened
again when the link is made again (tests/ground/test_station.py)."""

from __future__ import annotations

import os
import pty
import select
import time

from support.linkstream import TANK, layout_of

from fswkit.ground.station import REOPEN_S, Station
from fswkit.link.port import port_identity, port_returned


def _same_number(path: str, within: float = 5.0) -> tuple[int, int]:
    """A new pseudo-terminal at `path` (the system gives the lowest number
    free; another test may hold it a moment): its (master, slave)."""
    others = []
    deadline = time.monotonic() + within
    try:
        while time.monotonic() < deadline:
            master, slave = pty.openpty()
            if os.ttyname(slave) == path:
                return master, slave
            others.append((master, slave))
            if len(others) > 64:  # every number up to a free one taken: let them go and try again
                for fds in others:
                    os.close(fds[0])
                    os.close(fds[1])
                others.clear()
                time.sleep(0.05)
        raise AssertionError(f"no new pseudo-terminal came at {path} within {within} s")
    finally:
        for m, s in others:
            os.close(m)
            os.close(s)


def test_a_closed_pseudo_terminals_number_is_not_opened_again(tmp_path, monkeypatch):
    monkeypatch.setenv("FSW_RUNTIME_DIR", str(tmp_path / "run"))
    master, slave = pty.openpty()
    path = os.ttyname(slave)
    assert port_identity(path) == ("pty", os.stat(path).st_rdev)
    notes = []
    st = Station(layout_of(TANK), "tank", path, 115200, serve=False)
    st.notes(lambda text, up: notes.append(text))
    st.start()
    try:
        os.close(master)  # the other end closes: the port goes away
        os.close(slave)
        deadline = time.monotonic() + 5
        while st.up and time.monotonic() < deadline:
            time.sleep(0.02)
        assert not st.up, notes
        m2, s2 = _same_number(path)
        try:
            time.sleep(6 * REOPEN_S)  # six of the station's tries at its port
            assert not st.up and st.reconnects == 0, notes
            r, _, _ = select.select([m2], [], [], 0)
            assert not r, os.read(m2, 100)  # nothing was written into the other program's terminal
        finally:
            os.close(m2)
            os.close(s2)
    finally:
        st.stop()
    gone = [n for n in notes if n.startswith("the port went away")]
    assert len(gone) == 1, notes
    assert gone[0].endswith("it was a pseudo-terminal, and one does not come back: the next one takes the same "
                            "number (another program's); start the station again on the new port"), gone


def test_a_link_to_a_pseudo_terminal_comes_back_when_it_is_made_again(tmp_path):
    master, slave = pty.openpty()
    link = tmp_path / "board"
    os.symlink(os.ttyname(slave), link)
    try:
        ident = port_identity(str(link))
        assert ident[0] == "link"
        assert port_returned(str(link), ident) == "its link still names the pseudo-terminal that closed"
        link.unlink()
        assert port_returned(str(link), ident) == "its link is not there"
        os.symlink(os.ttyname(slave), str(link) + ".new")
        os.replace(str(link) + ".new", link)  # made again, as a simulator does on a restart
        assert port_returned(str(link), ident) is None
    finally:
        os.close(master)
        os.close(slave)


def test_a_device_that_is_no_pseudo_terminal_may_come_back_as_anything(tmp_path):
    assert port_identity("/dev/null") is None  # a USB adapter's node, plugged in again, is the port back
    assert port_returned("/dev/null", None) is None
    assert port_identity(str(tmp_path / "nothing")) is None
    assert port_identity("socket://127.0.0.1:1") is None
