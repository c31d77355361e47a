"""A recording that ends before its end is said, by every command that
reads one, in words that fit what happened: a link log whose last record
is cut short (the recorder stopped mid-write), a link log damaged in the
middle (a record no recorder writes — another direction, an empty one, as
a tail of NULs a crash can leave —: its bytes from there are not decoded,
and how many is said; it was reported as cut short, though most of the
log was left unread, or read as millions of empty records), and an archive's session that was never ended (it
was reported as a record cut short). `fsw replay` and `fsw plot` said
nothing of either."""

from __future__ import annotations

import pytest
from conftest import run_fsw
from support.linkstream import TANK, layout_of, stream, write_log


def _starts(data: bytes) -> list[int]:
    """Where each record of a link log begins: after the magic and the
    header (u32 length, JSON), records of direction u8, host time u64,
    length u32 and the bytes."""
    at = 12 + int.from_bytes(data[8:12], "little")
    out = []
    while at < len(data):
        out.append(at)
        at += 13 + int.from_bytes(data[at + 9:at + 13], "little")
    return out


def _commands(path, tmp_path):
    return [("log2csv", str(path)), ("replay", str(path), "--headless", "--speed", "0"),
            ("plot", str(path), "-e", "tankPressure", "-o", str(tmp_path / "p.png"), "--force")]


def test_a_log_cut_short(tmp_path):
    log = write_log(tmp_path / "x.log", 200)
    data = log.read_bytes()[:-5]  # the last record's bytes cut short
    log.write_bytes(data)
    at = _starts(data)[-1]
    for argv in _commands(log, tmp_path):
        r = run_fsw(*argv)
        assert r.code == 0, r.err
        assert f"{log}: the record at byte {at:,} is cut short ({len(data) - at:,} bytes not decoded): the " \
               "recording stopped mid-write, or the file is damaged" in r.err, (argv, r.err)


def test_a_log_damaged_in_the_middle(tmp_path):
    log = write_log(tmp_path / "x.log", 200)
    data = bytearray(log.read_bytes())
    at = _starts(data)[50]
    left = len(data) - at
    data[at] = 7  # no direction a recorder writes
    log.write_bytes(bytes(data))
    for argv in _commands(log, tmp_path):
        r = run_fsw(*argv)
        assert r.code == 0, r.err
        assert f"{log}: the record at byte {at:,} is not one a recorder writes: the file is damaged; " \
               f"its last {left:,} bytes are not decoded" in r.err, (argv, r.err)
        assert "cut short" not in r.err


def test_a_log_with_a_tail_of_nuls(tmp_path):
    # a file system's crash recovery can leave a file's tail as NULs: read as millions of empty
    # records (seconds per hundred MB), then reported as a record cut short in its last bytes
    log = write_log(tmp_path / "x.log", 200)
    end = log.stat().st_size
    with open(log, "r+b") as f:
        f.truncate(end + 10_000_000)
    r = run_fsw("log2csv", str(log))
    assert r.code == 0, r.err
    assert f"{log}: the record at byte {end:,} is not one a recorder writes: the file is damaged; its last " \
           f"{10_000_000:,} bytes are not decoded" in r.err, r.err


def test_an_archive_session_never_ended(tmp_path):
    from fswkit.ground.archive import Archive
    from fswkit.link.session import Session

    layout = layout_of(TANK)
    path = tmp_path / "a.sqlite"
    a = Archive(str(path))
    a.begin(layout=layout, project="tank", port="/dev/ttyACM0", baud=115200, started=1_700_000_000.0)
    decoder = Session(layout)
    for i, frame in enumerate(stream(layout, 0, 100, hello_first=True)):
        t = 1_700_000_000_000_000_000 + i * 10_000_000
        a.rx(t, frame)
        for ev in decoder.feed(frame, t / 1e9):
            a.event(ev)
    a.tick()  # committed, the session still open: as a station still running, or killed
    try:
        for argv in _commands(path, tmp_path) + [("archive", "export", str(path), "-o", str(tmp_path / "x.csv"))]:
            r = run_fsw(*argv)
            assert r.code == 0, r.err
            assert f"{path}: session 1 was never ended (the station was killed, or still runs)" in r.err, \
                (argv, r.err)
            assert "cut short" not in r.err
    finally:
        a.close()


@pytest.mark.parametrize("what", ["missing", "junk"])
def test_session_of_a_file_that_is_no_recording(tmp_path, what):
    # `--session` with a path that is neither an archive nor a link log: said for what it is,
    # not taken for a link log
    path = tmp_path / "x.sqlite"
    if what == "junk":
        path.write_bytes(b"\x00garbage")
    r = run_fsw("log2csv", str(path), "--session", "2")
    assert r.code == 1 and "this is a link log" not in r.err, r.err
    assert ("cannot read" if what == "missing" else "not an fswkit link log") in r.err, r.err
