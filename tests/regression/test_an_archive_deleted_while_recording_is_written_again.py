"""The archive file deleted while the station recorded (an operator's
`rm`, a cleanup script) lost the whole session silently: SQLite went on
writing into the deleted file, which vanished with everything in it when
the station ended, and nobody was told. Now the archive sees at its next
commit that its file is gone, writes everything it held (this session and
the ones before) to its path again, goes on recording there, and says so
in a note; the station passes the note on to its clients and the page."""

from __future__ import annotations

import os
import time

import pytest
from support.linkstream import TANK, layout_of

from fswkit.ground.archive import Archive, ArchiveReader, sessions
from fswkit.ground.station import Station


@pytest.mark.parametrize("also", [(), ("-wal", "-shm")], ids=["the file", "the file and its WAL"])
def test_an_archive_deleted_while_recording_keeps_everything(tmp_path, also):
    layout = layout_of(TANK)
    path = str(tmp_path / "ground.sqlite")
    a = Archive(path)
    a.begin(layout=layout, project="tank", port="/dev/ttyACM0", baud=115200, started=time.time())
    a.received(1_000_000_000, b"first\0", (), now=0.0)
    a.received(1_100_000_000, b"second\0", (), now=1.0)
    for suffix in ("",) + also:
        os.unlink(path + suffix)
    a.received(1_200_000_000, b"third\0", (), now=2.0)  # commits: the file is found gone
    assert os.path.exists(path)
    assert a.notices == [f"the archive {path} was deleted while recording: written again there with all it "
                         "held; recording goes on in it"]
    a.received(1_300_000_000, b"fourth\0", (), now=3.0)
    a.close()
    rows = sessions(path)
    assert len(rows) == 1 and rows[0]["ended"] is not None
    got = [data for _, _, data in ArchiveReader(path).records()]
    assert got == [b"first\0", b"second\0", b"third\0", b"fourth\0"]


def test_the_station_says_its_archive_was_written_again(tmp_path, monkeypatch):
    monkeypatch.setenv("FSW_RUNTIME_DIR", str(tmp_path / "run"))
    layout = layout_of(TANK)
    path = str(tmp_path / "ground.sqlite")
    notes = []
    st = Station(layout, "tank", "loop://", 115200, archive=Archive(path), serve=False)
    st.notes(lambda text, up: notes.append(text))
    st.archive.begin(layout=layout, project="tank", port="loop://", baud=115200, started=time.time())
    st._received(b"one\0")
    st._archive("tick", time.monotonic() + 1)
    os.unlink(path)
    st._received(b"two\0")
    st._archive("tick", time.monotonic() + 2)
    assert any(n.startswith(f"the archive {path} was deleted while recording: written again") for n in notes), notes
    st._archive("close")
    assert [d for _, _, d in ArchiveReader(path).records()] == [b"one\0", b"two\0"]
