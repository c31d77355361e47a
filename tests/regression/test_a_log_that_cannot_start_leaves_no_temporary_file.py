"""`fsw monitor --log FILE` (and every link log: `fsw dump`, a flight of
`fsw sim --plant`) on a disk already full failed to write the log's header
and said so, but left its empty temporary file (`.FILE.XXXX.part`) beside
FILE for good. Now a log that cannot even start removes it; a log that
fills the disk later keeps what it recorded under its name (the monitor
commits it), as before."""

from __future__ import annotations

import errno

import pytest
from support.linkstream import TANK, layout_of

from fswkit.link import log as link_log


def test_a_full_disk_at_the_header_leaves_nothing(tmp_path, monkeypatch):
    layout = layout_of(TANK)

    def full(fd, data):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(link_log.os, "write", full)
    path = tmp_path / "m.log"
    with pytest.raises(link_log.LogError, match=f"cannot write the log {path}: No space left on device"):
        link_log.LogWriter(str(path), layout)
    assert list(tmp_path.iterdir()) == []
