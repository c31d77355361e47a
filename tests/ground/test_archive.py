"""The ground station's archive (fswkit.ground.archive): a session written
from a recorded link byte stream reads back as it was written, decodes as
the same bytes in a link log do, lists, exports, and a file that is not an
archive is refused and left as it was."""

from __future__ import annotations

import csv
import io
import math
import random
import shutil
import sqlite3
import threading

import pytest

from conftest import run_fsw
from fswkit.ground import logs
from fswkit.ground.archive import APPLICATION_ID, SCHEMA_VERSION, Archive, ArchiveError, ArchiveReader, \
    is_archive, sessions
from fswkit.link.log import RX, TX, LogWriter
from fswkit.link.session import Session
from support.linkstream import TANK, layout_of, stream

T0 = 1_700_000_000_000_000_000  # host time of the first chunk, ns


@pytest.fixture(scope="module")
def layout():
    return layout_of(TANK)


def chunks(layout, count: int = 600, seed: int = 1):
    """The link as a serial port reads it: the frames of a clean downlink in
    chunks of random sizes (frames cut anywhere), 5 ms apart, with a command
    sent to the target now and then."""
    data = b"".join(stream(layout, 0, count, hello_first=True))
    rnd = random.Random(seed)
    out, at, t = [], 0, T0
    while at < len(data):
        n = rnd.randint(1, 200)
        out.append((RX, t, data[at:at + n]))
        at += n
        t += 5_000_000
        if rnd.random() < 0.05:
            out.append((TX, t, bytes([0x00, rnd.randint(1, 255), 0x02, 0x00])))
    return out


def write_session(archive: Archive, layout, recorded, *, port="/dev/ttyACM0", started=1_700_000_000.0) -> int:
    """One session as the station writes it: every chunk, every decoded
    frame, a command and a note, ticks in between."""
    sid = archive.begin(layout=layout, project="tank", port=port, baud=115200, started=started)
    decoder = Session(layout)
    for i, (d, t, data) in enumerate(recorded):
        if d == RX:
            archive.rx(t, data)
            for ev in decoder.feed(data, t / 1e9):
                archive.event(ev)
        else:
            archive.tx(t, data)
        archive.tick(i * 0.005)
    archive.command(who="web 127.0.0.1", text="set valveOpen true", op=1, args=b"\x05\x01", sent=started + 1,
                    cmd_seq=4, status=0, words="applied", acked=started + 1.02)
    archive.command(who="fsw cmd", text="ping", op=3, args=b"", sent=started + 2, cmd_seq=5, status=None,
                    words="no acknowledgement", acked=None)
    archive.note(started + 3, "port went away")
    return sid


def write_log(path, layout, recorded) -> None:
    w = LogWriter(str(path), layout, port="/dev/ttyACM0", project="tank")
    for d, t, data in recorded:
        w.record(d, t, data)
    w.close()


def clean(r):
    assert "Traceback" not in r.err and "internal error" not in r.err, r.err
    return r


@pytest.fixture(scope="module")
def two_sessions(tmp_path_factory, layout):
    """An archive of two sessions (the second appended after a reopen) and
    a link log of the first session's bytes."""
    tmp = tmp_path_factory.mktemp("archive")
    path = tmp / "station.sqlite"
    first, second = chunks(layout, 600, seed=1), chunks(layout, 120, seed=2)
    with Archive(str(path)) as a:
        write_session(a, layout, first)
    with Archive(str(path)) as a:
        write_session(a, layout, second, port="/dev/ttyUSB0", started=1_700_000_600.0)
    log = tmp / "first.fswlog"
    write_log(log, layout, first)
    return path, log, first, second


# ---- writing and reading back ------------------------------------------------------------

def test_records_read_back_as_written(two_sessions, layout):
    path, _, first, second = two_sessions
    assert is_archive(path)
    r = ArchiveReader(str(path), 1)
    assert r.layout.schema == layout.schema and r.layout.raw == layout.raw
    assert r.header == {"session": 1, "project": "tank", "port": "/dev/ttyACM0", "baud": 115200,
                        "started": 1_700_000_000.0, "ended": r.header["ended"]}
    assert r.header["ended"] is not None and not r.truncated
    assert list(r.records()) == [(d, t / 1e9, data) for d, t, data in first]
    newest = ArchiveReader(str(path))
    assert newest.header["session"] == 2 and newest.header["port"] == "/dev/ttyUSB0"
    assert [data for _, _, data in newest.records()] == [data for _, _, data in second]


def test_the_file_is_what_the_schema_says(two_sessions):
    path, _, first, _ = two_sessions
    con = sqlite3.connect(path)
    assert con.execute("PRAGMA application_id").fetchone()[0] == APPLICATION_ID
    assert con.execute("PRAGMA user_version").fetchone()[0] == SCHEMA_VERSION
    assert con.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
    kinds = dict(con.execute("SELECT kind, count(*) FROM frames WHERE session = 1 GROUP BY kind"))
    assert kinds == {"hello": 3, "health": 21, "sample": 576}  # stream(): a hello every 250, health every 25
    # one row per sample, its values by element name, strict JSON that SQLite reads
    n, first_psi = con.execute("SELECT count(*), min(json_extract(vals, '$.tankPressure')) FROM sample_rows "
                               "WHERE session = 1 AND region = 'Sensors'").fetchone()
    assert n == 576 and first_psi is not None
    ack = con.execute("SELECT json_extract(info, '$.schema_ok') FROM frames WHERE kind = 'hello' LIMIT 1")
    assert ack.fetchone()[0] == 1
    cmds = con.execute("SELECT who, text, op, args, cmd_seq, status, words, acked FROM commands "
                       "WHERE session = 1 ORDER BY id").fetchall()
    assert cmds == [("web 127.0.0.1", "set valveOpen true", 1, b"\x05\x01", 4, 0, "applied", 1_700_000_001.02),
                    ("fsw cmd", "ping", 3, b"", 5, None, "no acknowledgement", None)]
    assert con.execute("SELECT text FROM notes WHERE session = 1").fetchall() == [("port went away",)]
    plan = " ".join(r[3] for r in con.execute("EXPLAIN QUERY PLAN SELECT * FROM frames WHERE session = 1 "
                                              "AND host_time BETWEEN 0 AND 1"))
    assert "frames_by_time" in plan
    con.close()


def test_info_bytes_are_hex_and_non_finite_floats_named(tmp_path, layout):
    from fswkit.link.session import Event

    path = tmp_path / "a.sqlite"
    with Archive(str(path)) as a:
        a.begin(layout=layout, project="tank", port="p", baud=9600, started=1.0)
        a.event(Event("ack", 7, 70, 2.0, info={"cmd_seq": 1, "data": b"\x01\xab"}))
        a.event(Event("sample", 8, 80, 2.5, stream=0, samples=[(80, (1, 2, math.nan))]))
        a.event(Event("sample", 9, 2**64 - 1, 2.6, stream=0, samples=[(2**64 - 1, (1, 2, -math.inf))]))
    con = sqlite3.connect(path)
    assert con.execute("SELECT json_extract(info, '$.data') FROM frames WHERE kind = 'ack'").fetchone() == ("01ab",)
    vals = [v for (v,) in con.execute("SELECT json_extract(vals, '$.tankPressure') FROM samples ORDER BY frame")]
    assert vals == ["NaN", "-Infinity"]
    assert con.execute("SELECT time FROM frames WHERE seq = 9").fetchone()[0] == float(2**64 - 1)
    con.close()


def test_tick_commits_every_half_second_and_close_ends_the_session(tmp_path, layout):
    path = tmp_path / "a.sqlite"
    a = Archive(str(path))
    a.begin(layout=layout, project="tank", port="p", baud=9600, started=1.0)
    a.tick(100.0)  # the first tick starts the clock
    peek = sqlite3.connect(path)

    def seen():
        return peek.execute("SELECT count(*) FROM chunks").fetchone()[0]

    a.rx(1, b"abc")
    a.tick(100.4)
    assert seen() == 0  # still in the open batch
    a.tick(100.5)
    assert seen() == 1
    a.rx(2, b"def")
    assert ArchiveReader(str(path)).truncated  # not ended yet: as after a kill
    a.close()
    assert seen() == 2
    r = ArchiveReader(str(path))
    assert not r.truncated and r.header["ended"] is not None
    a.rx(3, b"late")  # a reading thread racing the close: ignored
    a.close()
    assert seen() == 2
    peek.close()


def test_threads_write_through_one_lock(tmp_path, layout):
    path = tmp_path / "a.sqlite"
    a = Archive(str(path))
    a.begin(layout=layout, project="tank", port="p", baud=9600, started=1.0)

    def writer(k):
        for i in range(300):
            (a.rx if k == 0 else a.tx)(i, bytes([k, i & 0xFF]))
            a.tick()

    threads = [threading.Thread(target=writer, args=(k,)) for k in (0, 1)]
    for t in threads:
        t.start()
    a.note(2.0, "while they write")
    for t in threads:
        t.join()
    a.close()
    recs = list(ArchiveReader(str(path)).records())
    assert sorted(d for d, _, _ in recs) == [0] * 300 + [1] * 300
    assert [data for d, _, data in recs if d == RX] == [bytes([0, i & 0xFF]) for i in range(300)]


# ---- the tools on an archive ----------------------------------------------------------------

def test_log2csv_of_the_archive_is_log2csv_of_the_log(two_sessions):
    path, log, _, _ = two_sessions
    from_log = clean(run_fsw("log2csv", str(log)))
    from_archive = clean(run_fsw("log2csv", str(path), "--session", "1"))
    assert from_log.code == 0 and from_archive.code == 0, from_archive.err
    assert from_archive.out == from_log.out and from_log.out.count("\n") > 500
    newest = clean(run_fsw("log2csv", str(path)))
    assert newest.code == 0 and newest.out != from_log.out  # the newest: session 2


def test_replay_and_plot_take_a_session(two_sessions, tmp_path):
    path, _, _, second = two_sessions
    r = clean(run_fsw("replay", str(path), "--session", "2", "--headless", "--speed", "0"))
    assert r.code == 0 and " hello " in r.out and len(r.out.splitlines()) == 120
    # the session reaches plot's reader (the drawing is the same as a log's)
    r = clean(run_fsw("plot", str(path), "--session", "3", "-e", "tankPressure", "-o", str(tmp_path / "p.png")))
    assert r.code == 1 and "no session 3 in the archive" in r.err


def test_sessions_are_listed(two_sessions):
    path, _, first, second = two_sessions
    rows = sessions(str(path))
    assert [(s["id"], s["port"], s["baud"], s["commands"]) for s in rows] == \
        [(1, "/dev/ttyACM0", 115200, 2), (2, "/dev/ttyUSB0", 115200, 2)]
    assert rows[0]["frames"] == 600 and rows[1]["frames"] == 120
    assert rows[0]["bytes"] == sum(len(d) for _, _, d in first)
    assert all(s["ended"] is not None for s in rows)
    r = clean(run_fsw("archive", "list", str(path)))
    lines = r.out.splitlines()
    assert r.code == 0 and lines[0].split() == ["session", "started", "length", "project", "port", "baud",
                                                "frames", "commands", "bytes"]
    assert lines[1].split()[0] == "1" and "/dev/ttyACM0" in lines[1] and " 600 " in lines[1]
    assert lines[2].split()[0] == "2" and "/dev/ttyUSB0" in lines[2]


def test_a_missing_session_names_the_ones_there_are(two_sessions):
    path, log, _, _ = two_sessions
    with pytest.raises(ArchiveError, match=r"no session 9 in the archive: its sessions are 1-2"):
        ArchiveReader(str(path), 9)
    r = clean(run_fsw("log2csv", str(path), "--session", "9"))
    assert r.code == 1 and "no session 9 in the archive: its sessions are 1-2" in r.err
    r = clean(run_fsw("log2csv", str(log), "--session", "1"))
    assert r.code == 1 and "this is a link log" in r.err and "--session" in r.err


# ---- refusals ---------------------------------------------------------------------------------

def test_a_file_that_is_not_an_archive_is_refused_and_left_as_it_was(tmp_path, layout, two_sessions):
    _, log, _, _ = two_sessions
    text = tmp_path / "notes.txt"
    text.write_text("flight notes\n")
    empty = tmp_path / "empty.sqlite"
    empty.write_bytes(b"")
    other = tmp_path / "other.sqlite"  # an SQLite database, not ours
    con = sqlite3.connect(other)
    con.execute("CREATE TABLE t (x)")
    con.commit()
    con.close()
    for f in (text, empty, other, log):
        before = f.read_bytes()
        with pytest.raises(ArchiveError, match="is not an fswkit archive: it is left as it is"):
            Archive(str(f))
        assert f.read_bytes() == before
        assert not (tmp_path / (f.name + "-wal")).exists() and not (tmp_path / (f.name + "-shm")).exists()
        assert not is_archive(f)
        r = clean(run_fsw("archive", "list", str(f)))
        assert r.code == 1 and "not an fswkit archive" in r.err
    with pytest.raises(ArchiveError, match="it is a folder"):
        Archive(str(tmp_path))
    with pytest.raises(ArchiveError, match="cannot write the archive"):
        Archive(str(tmp_path / "no" / "such" / "a.sqlite"))
    r = clean(run_fsw("archive", "list", str(tmp_path / "missing.sqlite")))
    assert r.code == 1 and "no such file" in r.err
    assert [p.name for p in tmp_path.iterdir() if p.name.endswith(".part")] == []


def test_log2csv_never_writes_over_an_archive(two_sessions, tmp_path):
    path, log, _, _ = two_sessions
    other = tmp_path / "other.sqlite"
    Archive(str(other)).close()
    before = other.read_bytes()
    r = clean(run_fsw("log2csv", str(log), "-o", str(other)))
    assert r.code == 1 and "a ground station archive (a recording) is there" in r.err
    assert other.read_bytes() == before


def test_an_archive_of_a_newer_schema_is_refused(tmp_path, layout):
    path = tmp_path / "a.sqlite"
    Archive(str(path)).close()
    con = sqlite3.connect(path)
    con.execute(f"PRAGMA user_version = {SCHEMA_VERSION + 1}")
    con.close()
    with pytest.raises(ArchiveError, match="written by a newer fswkit"):
        Archive(str(path))
    with pytest.raises(ArchiveError, match="written by a newer fswkit"):
        ArchiveReader(str(path))


def test_an_archive_without_sessions(tmp_path):
    path = tmp_path / "a.sqlite"
    Archive(str(path)).close()
    assert sessions(str(path)) == []
    r = clean(run_fsw("archive", "list", str(path)))
    assert r.code == 0 and "no sessions yet" in r.err
    r = clean(run_fsw("log2csv", str(path)))
    assert r.code == 1 and "has no sessions yet" in r.err


# ---- fsw archive export ------------------------------------------------------------------------

def _same_cells(a: list[list], b: list[list[str]]) -> None:
    """Rows of Parquet values against the CSV's text: numbers equal to the
    printed digits, None as empty, bools as 1/0."""
    assert len(a) == len(b)
    for ra, rb in zip(a, b):
        assert len(ra) == len(rb)
        for x, y in zip(ra, rb):
            if x is None or isinstance(x, (bool, str)):
                assert ("" if x is None else str(int(x)) if isinstance(x, bool) else x) == y, (ra, rb)
            elif math.isnan(x):
                assert y == "nan", (ra, rb)
            else:
                assert math.isclose(x, float(y), rel_tol=1e-9, abs_tol=1e-6), (ra, rb)


def test_export_csv_and_parquet(two_sessions, tmp_path):
    import pyarrow.parquet as pq

    path, _, _, _ = two_sessions
    want = clean(run_fsw("log2csv", str(path), "--session", "1")).out
    out = tmp_path / "s1.csv"
    r = clean(run_fsw("archive", "export", str(path), "--session", "1", "-o", str(out)))
    rows = list(csv.reader(io.StringIO(want)))
    assert r.code == 0 and f"{len(rows) - 1} rows of session 1" in r.err, r.err
    assert out.read_text() == want and len(rows) > 500  # the CSV is log2csv's

    pqt = tmp_path / "s1.parquet"
    r = clean(run_fsw("archive", "export", str(path), "--session", "1", "-o", str(pqt)))
    assert r.code == 0, r.err
    t = pq.read_table(pqt)
    assert t.column_names == rows[0] and t.num_rows == len(rows) - 1
    types = {f.name: str(f.type) for f in t.schema}
    assert types[logs.HOST_TIME] == "double" and types[logs.BOOT] == "int64" and types[logs.FRAME] == "string"
    assert types["tankPressure"] == "double" and types["valveOpen"] == "bool"
    cols = t.to_pydict()
    _same_cells([[cols[c][i] for c in t.column_names] for i in range(t.num_rows)], rows[1:])


def test_export_a_time_range(two_sessions, tmp_path):
    path, _, _, _ = two_sessions
    out = tmp_path / "part.csv"
    r = clean(run_fsw("archive", "export", str(path), "--session", "1", "--from", "0.2525", "--to", "0.5025",
                      "-o", str(out)))
    assert r.code == 0, r.err
    rows = list(csv.DictReader(io.StringIO(out.read_text())))
    times = [float(row[logs.HOST_TIME]) for row in rows]
    # chunks 5 ms apart from 1_700_000_000 s, the time the session began (the bounds between two)
    assert len(rows) > 100 and all(1_700_000_000.2525 <= t <= 1_700_000_000.5025 for t in times)
    assert times == sorted(times)
    everything = list(csv.DictReader(io.StringIO(clean(run_fsw("log2csv", str(path), "--session", "1")).out)))
    assert rows == [row for row in everything if 1_700_000_000.2525 <= float(row[logs.HOST_TIME]) <= 1_700_000_000.5025]
    r = clean(run_fsw("archive", "export", str(path), "--from", "3", "--to", "2", "-o", str(tmp_path / "x.csv")))
    assert r.code == 1 and "--from 3 is after --to 2" in r.err


def test_export_refuses_before_any_work(two_sessions, tmp_path):
    path, log, _, _ = two_sessions
    old = tmp_path / "old.csv"
    old.write_text("keep me\n")
    odd = tmp_path / "archive.parquet"  # an archive of any name is never its own output
    shutil.copyfile(path, odd)
    cases = [
        ((str(path), "-o", str(old)), "exists: it is replaced only when asked (--force)"),
        ((str(path), "-o", str(tmp_path / "out.txt")), "`.txt` is not a format it writes"),
        ((str(path), "-o", str(path)), "`.sqlite` is not a format it writes"),
        ((str(odd), "-o", str(odd), "--force"), "would overwrite an input"),
        ((str(log), "-o", str(tmp_path / "x.csv")), "not an fswkit archive"),
        ((str(path), "--session", "7", "-o", str(tmp_path / "x.csv")), "no session 7"),
    ]
    for argv, msg in cases:
        r = clean(run_fsw("archive", "export", *argv))
        assert r.code == 1 and msg in r.err, (argv, r.err)
    assert old.read_text() == "keep me\n" and is_archive(path) and is_archive(odd)
    assert not (tmp_path / "x.csv").exists()
    r = clean(run_fsw("archive", "export", str(path), "-o", str(old), "--force"))
    assert r.code == 0 and old.read_text().startswith(logs.TIME), r.err


def _tables(path) -> dict:
    con = sqlite3.connect(path)
    out = {t: con.execute(f"SELECT * FROM {t} ORDER BY rowid").fetchall() for t in ("chunks", "frames")}
    out["samples"] = con.execute("SELECT * FROM samples ORDER BY frame, i").fetchall()
    con.close()
    return out


def test_received_writes_what_rx_and_event_write(tmp_path, layout):
    """The station's one call per read (the bytes, their frames, a tick)
    keeps the rows the separate calls keep, each frame's samples under its
    own number."""
    recorded = [r for r in chunks(layout, 300) if r[0] == RX]
    paths = [tmp_path / "calls.sqlite", tmp_path / "received.sqlite"]
    for k, path in enumerate(paths):
        a = Archive(str(path))
        a.begin(layout=layout, project="tank", port="p", baud=115200, started=1.0)
        decoder = Session(layout)
        for i, (_, t, data) in enumerate(recorded):
            evs = decoder.feed(data, t / 1e9)
            if k == 0:
                a.rx(t, data)
                for ev in evs:
                    a.event(ev)
                a.tick(i * 0.01)
            else:
                a.received(t, data, evs, now=i * 0.01)
        a.close()
    first, second = _tables(paths[0]), _tables(paths[1])
    assert first == second
    assert len(first["frames"]) == 300 and len(first["samples"]) > 250


def test_two_writers_number_their_frames_apart(tmp_path, layout):
    """Frames wait in memory and take their numbers when written: a batch
    numbers its frames after the archive's last, under the write lock, so
    another writer's frames between two batches never take a number twice
    and every sample stays with its frame."""
    path = tmp_path / "a.sqlite"
    writers = [Archive(str(path)), Archive(str(path))]
    decoders = []
    for k, a in enumerate(writers):
        a.begin(layout=layout, project="tank", port=f"p{k}", baud=115200, started=1.0)
        decoders.append(Session(layout))
    data = b"".join(stream(layout, 0, 200, hello_first=True))
    for i in range(0, len(data), 97):
        for k, a in enumerate(writers):
            piece = data[i:i + 97]
            a.received(T0 + i, piece, decoders[k].feed(piece, 1.0 + i / 1e6), now=i / 500)
    for a in writers:
        a.close()
    con = sqlite3.connect(path)
    per_session = con.execute("SELECT session, count(*) FROM frames GROUP BY session ORDER BY session").fetchall()
    assert per_session == [(1, 200), (2, 200)]
    # each sample row belongs to a sample frame of the session whose decoder made it, in its order
    rows = con.execute("SELECT f.session, f.seq, count(*) FROM samples s JOIN frames f ON f.id = s.frame "
                       "WHERE f.kind = 'sample' GROUP BY s.frame ORDER BY s.frame").fetchall()
    assert len(rows) == con.execute("SELECT count(*) FROM frames WHERE kind = 'sample'").fetchone()[0]
    assert con.execute("SELECT count(*) FROM samples s LEFT JOIN frames f ON f.id = s.frame "
                       "WHERE f.id IS NULL OR f.kind != 'sample'").fetchone()[0] == 0
    for sid in (1, 2):
        assert [seq for s, seq, _ in rows if s == sid] == sorted(seq for s, seq, _ in rows if s == sid)
    con.close()


def test_abandon_drops_the_batch_waiting_in_memory(tmp_path, layout):
    path = tmp_path / "a.sqlite"
    a = Archive(str(path))
    a.begin(layout=layout, project="tank", port="p", baud=9600, started=1.0)
    decoder = Session(layout)
    data = b"".join(stream(layout, 0, 20, hello_first=True))
    a.received(1, data, decoder.feed(data, 1.0), now=100.0)  # the first tick commits
    a.received(2, data[:10], [], now=100.1)  # waits for the next
    a.abandon()
    con = sqlite3.connect(path)
    assert con.execute("SELECT count(*), sum(length(data)) FROM chunks").fetchone() == (1, len(data))
    assert con.execute("SELECT count(*) FROM frames").fetchone() == (20,)
    con.close()
