"""An archive the station cannot write — a lock another program holds
longer than SQLite waits, a full disk — ended the station's reader thread
with a traceback (`ArchiveError: ... database is locked`): the station
went on running deaf, its port no longer read, every client's command
unanswered. The link comes first: archiving stops, said once in a note,
the archive keeps what was committed, and the port is read and served as
before. An archive locked when the station starts is refused as an archive
is (`fsw ground` said `internal error: ArchiveError`)."""

from __future__ import annotations

import sqlite3
import threading
import time

import pytest
from conftest import run_fsw
from support.linkstream import TANK, PtyStream, layout_of

from fswkit.ground.archive import Archive, ArchiveReader, sessions
from fswkit.ground.station import Station

pytestmark = pytest.mark.costly(13, waits=True)  # SQLite waits 5 s for a lock, in each test


@pytest.fixture
def thread_errors(monkeypatch):
    """The exceptions that end any thread, instead of a traceback on the console."""
    seen: list[BaseException] = []
    monkeypatch.setattr(threading, "excepthook", lambda a: seen.append(a.exc_value))
    return seen


def test_a_locked_archive_stops_archiving_not_the_link(tmp_path, monkeypatch, thread_errors):
    monkeypatch.setenv("FSW_RUNTIME_DIR", str(tmp_path / "run"))
    layout = layout_of(TANK)
    path = tmp_path / "ground.sqlite"
    notes: list[str] = []
    frames = []
    with PtyStream(layout, hello_first=True) as target:
        st = Station(layout, str(TANK), target.port, 115200, archive=Archive(str(path)), serve=False)
        st.notes(lambda text, up: notes.append(text))
        st.listen(lambda evs: frames.extend(evs))
        st.start()
        try:
            time.sleep(1.0)
            # another program writes: the station waits 5 s, then gives up. This
            # side waits as long as it takes to get the lock between two of the
            # station's batches (on a loaded machine SQLite's 5 s were too few)
            lock = sqlite3.connect(path, isolation_level=None, timeout=60)
            lock.execute("BEGIN IMMEDIATE")
            deadline = time.monotonic() + 15
            while not any("archiving stopped" in n for n in notes) and time.monotonic() < deadline:
                time.sleep(0.1)
            lock.execute("ROLLBACK")
            lock.close()
            before = len(frames)
            time.sleep(1.0)
            assert len(frames) > before  # the port is still read
            assert st.archive is None
        finally:
            st.stop()
    assert thread_errors == []
    said = [n for n in notes if "archiving stopped" in n]
    assert said == [f"archiving stopped: cannot write the archive {path}: database is locked; the link goes on "
                    "without it (the archive keeps what was committed before)"]
    rows = sessions(str(path))  # whole, with what was committed before
    assert len(rows) == 1 and rows[0]["frames"] > 0
    assert sum(1 for _ in ArchiveReader(str(path)).records()) > 0


def test_an_archive_locked_at_start_is_refused(tmp_path, monkeypatch):
    monkeypatch.setenv("FSW_RUNTIME_DIR", str(tmp_path / "run"))
    layout = layout_of(TANK)
    path = tmp_path / "ground.sqlite"
    Archive(str(path)).close()
    lock = sqlite3.connect(path, isolation_level=None)
    lock.execute("BEGIN IMMEDIATE")
    try:
        with PtyStream(layout, hello_first=True) as target:
            r = run_fsw("ground", str(TANK), "--port", target.port, "--no-web", "--archive", str(path))
    finally:
        lock.execute("ROLLBACK")
        lock.close()
    assert r.code == 1 and f"cannot write the archive {path}: database is locked" in r.err, r.err
    assert "internal error" not in r.err
