"""A link log or an archive session whose layout JSON nests deeper than the
JSON reader recurses was `fsw: input nested too deeply to process`, exit 3
(the kit's internal error), without naming the file, and a server error of
the web page's archive browser. It is a log that is not valid, named as
any other (exit 1; 422 on the web page)."""

from __future__ import annotations

import sqlite3
import struct

import pytest

from conftest import run_fsw

from fswkit.outputs import RECORDING_MAGIC

DEEP = "[" * 100_000 + "]" * 100_000


def test_a_log_header_nested_too_deeply(tmp_path):
    for name, head in (("list.log", DEEP), ("layout.log", '{"format": 1, "layout": ' + DEEP + "}")):
        log = tmp_path / name
        log.write_bytes(RECORDING_MAGIC + struct.pack("<I", len(head)) + head.encode())
        for argv in (("log2csv", str(log)), ("replay", str(log), "--headless"),
                     ("plot", str(log), "-e", "x", "-o", str(tmp_path / "p.png"))):
            r = run_fsw(*argv)
            assert r.code == 1 and f"{log}: not a valid log:" in r.err and "nested too deeply" in r.err, r.err


def test_an_archive_layout_nested_too_deeply(tmp_path):
    from fswkit.ground.archive import Archive

    path = tmp_path / "a.sqlite"
    Archive(str(path)).close()
    con = sqlite3.connect(path)
    con.execute("INSERT INTO sessions (project, port, baud, started, layout, fswkit) VALUES "
                "('x', 'p', 9600, 1.0, ?, '0')", (DEEP,))
    con.commit()
    con.close()
    for argv in (("log2csv", str(path)), ("archive", "export", str(path), "-o", str(tmp_path / "x.csv"))):
        r = run_fsw(*argv)
        assert r.code == 1 and f"{path}: session 1: not a valid layout" in r.err and "nested too deeply" in r.err, \
            r.err
    # the web page's archive browser: a refusal with its reason, not a server error
    from fswkit.web.archive import BrowseError, Session

    with pytest.raises(BrowseError, match="not a valid layout: JSON nested too deeply") as e:
        Session(str(path), "1")
    assert e.value.status == 422
