"""The ground station's archive: one SQLite file that keeps every session of
a station — the raw bytes both ways (what `fsw log2csv`, `fsw replay` and
`fsw plot` decode again, as from a link log), the frames decoded as they
came (for queries), the commands sent and their acknowledgements, and the
station's notes. sqlite3 is in Python's standard library; SQLite is the
embedded default, one file, readable while the station writes it.

The file is an SQLite database whose PRAGMA application_id is 0x46535741
("FSWA") and whose PRAGMA user_version is the schema version,
SCHEMA_VERSION (1):

    sessions  id INTEGER PRIMARY KEY, project TEXT, port TEXT, baud INTEGER,
              started REAL (host time, s since the epoch), ended REAL (NULL:
              never ended — the station was killed, or still runs),
              layout TEXT (the link layout's JSON, `layout.raw`), fswkit TEXT
              (the version that wrote it)
    chunks    id INTEGER PRIMARY KEY, session, dir INTEGER (0 from the target,
              1 to it: fswkit.link.log's RX, TX), t_ns INTEGER (host time, ns
              since the epoch), data BLOB — the bytes as read or written
    frames    id INTEGER PRIMARY KEY, session, kind TEXT (sample | snapshot |
              hello | health | ack), seq INTEGER, time (target time, the
              layout's unit), host_time REAL (s), region TEXT (a sample
              frame's region, else NULL), info TEXT (JSON: the fields of a
              hello, health, ack or snapshot, bytes as hex; NULL for samples)
    samples   frame (frames.id), i INTEGER (place in the frame), time (target
              time), vals TEXT (JSON object {element: value}); WITHOUT ROWID,
              keyed (frame, i)
    commands  id INTEGER PRIMARY KEY, session, who TEXT, text TEXT, op INTEGER,
              args BLOB, sent REAL (host time), cmd_seq INTEGER, status INTEGER
              (NULL: no acknowledgement came), words TEXT, acked REAL (host
              time of the acknowledgement, or NULL)
    notes     id INTEGER PRIMARY KEY, session (NULL: before any), t REAL, text TEXT
    sample_rows  a view: session, seq, host_time, region, i, time, vals

Indexes: chunks (session, t_ns), frames (session, host_time), commands
(session, sent), notes (session, t). JSON is strict (SQLite's json_extract
reads it): a float that is not finite is the string "NaN", "Infinity" or
"-Infinity"; a whole number beyond SQLite's 64 bits is stored as REAL.

Crash safety: the journal is a write-ahead log (WAL), with
synchronous=NORMAL. The bytes and frames wait in memory and are written in
one transaction that `tick()` commits at most every 0.5 s (and `close()`); a
command or a note goes into that transaction at once. A committed
transaction is in the WAL file, which the operating system keeps when the
process dies: `kill -9` at any moment loses only the uncommitted batch (the
last half second and the time to the next tick), and never what was
committed before. Rows kept in memory until the commit are lost by a kill
exactly as rows in an uncommitted transaction are, and writing them at once
costs a few statements a batch, where a statement each cost the station's
reader more than anything else it does for a frame; the write lock is held
only while a batch is written (or from a command or a note to the commit).
NORMAL, not FULL: FULL would wait for the disk (fsync) at every commit,
while the station's serial thread waits for the archive's lock — on an SD
card or a USB stick, long enough to overrun the port's buffer; NORMAL syncs
the WAL at checkpoints only, so a power cut (not a killed process) may lose
the commits since the last checkpoint, the database still whole. A new
archive is made complete in a temporary file beside its path and takes the
name only then: no reader ever sees half an archive. A file deleted while
it is written (SQLite would write on into the deleted file) is written
again at its name at the next commit, with all the connection held
(`_kept`), and said in `notices`.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import sqlite3
import tempfile
import threading
import time
from pathlib import Path

from fswkit.autocode.diagnostics import ranges
from fswkit.outputs import ARCHIVE_ID as APPLICATION_ID  # "FSWA"; outputs never overwrite an archive
from fswkit.outputs import recording

SCHEMA_VERSION = 1
COMMIT_EVERY = 0.5  # s: the most a tick() lets a batch wait
_INT64 = (-(1 << 63), (1 << 63) - 1)

_SCHEMA = f"""
PRAGMA application_id = {APPLICATION_ID};
PRAGMA user_version = {SCHEMA_VERSION};
CREATE TABLE sessions (
    id INTEGER PRIMARY KEY, project TEXT NOT NULL, port TEXT NOT NULL, baud INTEGER NOT NULL,
    started REAL NOT NULL, ended REAL, layout TEXT NOT NULL, fswkit TEXT NOT NULL);
CREATE TABLE chunks (
    id INTEGER PRIMARY KEY, session INTEGER NOT NULL REFERENCES sessions(id),
    dir INTEGER NOT NULL CHECK (dir IN (0, 1)), t_ns INTEGER NOT NULL, data BLOB NOT NULL);
CREATE INDEX chunks_by_time ON chunks(session, t_ns);
CREATE TABLE frames (
    id INTEGER PRIMARY KEY, session INTEGER NOT NULL REFERENCES sessions(id), kind TEXT NOT NULL,
    seq INTEGER NOT NULL, time NOT NULL, host_time REAL NOT NULL, region TEXT, info TEXT);
CREATE INDEX frames_by_time ON frames(session, host_time);
CREATE TABLE samples (
    frame INTEGER NOT NULL REFERENCES frames(id), i INTEGER NOT NULL, time NOT NULL, vals TEXT NOT NULL,
    PRIMARY KEY (frame, i)) WITHOUT ROWID;
CREATE TABLE commands (
    id INTEGER PRIMARY KEY, session INTEGER NOT NULL REFERENCES sessions(id), who TEXT NOT NULL,
    text TEXT NOT NULL, op INTEGER NOT NULL, args BLOB NOT NULL, sent REAL NOT NULL, cmd_seq INTEGER,
    status INTEGER, words TEXT NOT NULL, acked REAL);
CREATE INDEX commands_by_time ON commands(session, sent);
CREATE TABLE notes (
    id INTEGER PRIMARY KEY, session INTEGER REFERENCES sessions(id), t REAL NOT NULL, text TEXT NOT NULL);
CREATE INDEX notes_by_time ON notes(session, t);
CREATE VIEW sample_rows AS
    SELECT f.session, f.seq, f.host_time, f.region, s.i, s.time, s.vals
    FROM samples s JOIN frames f ON f.id = s.frame;
"""


class ArchiveError(Exception):
    """A user-facing failure of an archive: message printed, non-zero exit."""


def is_archive(path) -> bool:
    """Whether `path` is an fswkit archive: a regular SQLite file with our
    application_id (read from its header, the file left as it is)."""
    return recording(str(path)) == "a ground station archive"


def _sql_error(path, e: sqlite3.Error, doing: str) -> ArchiveError:
    return ArchiveError(f"cannot {doing} the archive {path}: {e}")


def _num(v):
    """A number SQLite can hold: a whole number beyond 64 bits as REAL."""
    if isinstance(v, int) and not isinstance(v, bool) and not _INT64[0] <= v <= _INT64[1]:
        return float(v)
    return v


def _finite(v):
    """A value for strict JSON: non-finite floats named as strings."""
    if isinstance(v, float) and not math.isfinite(v):
        return "NaN" if math.isnan(v) else ("Infinity" if v > 0 else "-Infinity")
    if isinstance(v, dict):
        return {k: _finite(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_finite(x) for x in v]
    if isinstance(v, (bytes, bytearray, memoryview)):
        return bytes(v).hex()
    return v


_ENCODE = json.JSONEncoder(separators=(",", ":"), allow_nan=False).encode  # keys in the layout's order


def _json(v) -> str:
    try:  # the common case, at the link's rate: numbers, all finite
        return _ENCODE(v)
    except (ValueError, TypeError):  # a NaN or an infinity, bytes
        return _ENCODE(_finite(v))


def _check_version(con: sqlite3.Connection, path) -> None:
    (v,) = con.execute("PRAGMA user_version").fetchone()
    if v != SCHEMA_VERSION:
        newer = "a newer" if v > SCHEMA_VERSION else "an older"
        raise ArchiveError(f"{path}: an archive of schema version {v}, written by {newer} fswkit: this one "
                           f"reads version {SCHEMA_VERSION}")


def _ident(path) -> tuple[int, int] | None:
    """The file at `path` (its device and inode), or None when there is none."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_dev, st.st_ino


class Archive:
    """The writer: sessions appended to an archive (a new file, or an
    archive that exists). Thread-safe: every call takes one lock. Chunks
    and frames wait in memory, commands and notes in a transaction, until
    tick() writes and commits them every COMMIT_EVERY seconds; close()
    commits and marks the session ended. Calls after close() are ignored
    (a reading thread may race the close)."""

    def __init__(self, path: str):
        self.path = str(path)
        self._lock = threading.Lock()
        self._con: sqlite3.Connection | None = None
        self._session: int | None = None
        self._last_tick: float | None = None
        # the open batch's chunks and frames, inserted when it is committed (_flush)
        self._chunks: list[tuple] = []
        self._frames: list[tuple] = []
        self._regions: list[tuple[str, tuple[str, ...]]] = []  # the session's streams: (region, element names)
        if os.path.isdir(self.path):
            raise ArchiveError(f"cannot write the archive {path}: it is a folder (name a file)")
        if not os.path.lexists(self.path):
            self._create()
        if not is_archive(self.path):
            raise ArchiveError(f"{path} exists and is not an fswkit archive: it is left as it is; "
                               "name a new file (or an archive to add sessions to)")
        try:
            con = sqlite3.connect(self.path, timeout=5.0, isolation_level=None, check_same_thread=False)
        except sqlite3.Error as e:
            raise _sql_error(path, e, "open") from None
        try:
            _check_version(con, path)
            con.execute("PRAGMA journal_mode = WAL")
            con.execute("PRAGMA synchronous = NORMAL")
        except sqlite3.Error as e:
            con.close()
            raise _sql_error(path, e, "open") from None
        except ArchiveError:
            con.close()
            raise
        self._con = con
        self._ident = _ident(self.path)  # the file written: one deleted under it is written again (_kept)
        self.notices: list[str] = []  # what the archive did of itself that the station must say (taken by it)

    def _create(self) -> None:
        """A new archive, made whole in a temporary file beside the path and
        linked to it only if nothing took the name meanwhile."""
        folder = os.path.dirname(os.path.abspath(self.path))
        try:
            fd, tmp = tempfile.mkstemp(prefix=f".{os.path.basename(self.path)}.", suffix=".part", dir=folder)
        except OSError as e:
            raise ArchiveError(f"cannot write the archive {self.path}: {e.strerror or e}") from None
        try:
            os.fchmod(fd, 0o644)
            os.close(fd)
            con = sqlite3.connect(tmp, isolation_level=None)
            try:
                con.executescript(_SCHEMA)
                con.execute("PRAGMA journal_mode = WAL")
            finally:
                con.close()  # the last connection: the WAL is folded into the file, its header written
            try:
                os.link(tmp, self.path)  # fails when the name was taken meanwhile: that file is kept
            except FileExistsError:
                pass
            except OSError:  # a file system without hard links (FAT): a rename
                if not os.path.lexists(self.path):
                    os.replace(tmp, self.path)
        except sqlite3.Error as e:
            raise _sql_error(self.path, e, "create") from None
        except OSError as e:
            raise ArchiveError(f"cannot write the archive {self.path}: {e.strerror or e}") from None
        finally:
            with contextlib.suppress(OSError):
                os.unlink(tmp)

    # ---- writing ------------------------------------------------------------------------

    def _exec(self, sql: str, params=()) -> sqlite3.Cursor:
        """A statement in the open batch (one begun if none is). IMMEDIATE:
        the batch holds the write lock from its first statement, so the
        frames' numbers taken in `_flush` are the ones they get."""
        self._begin()
        return self._con.execute(sql, params)

    def _begin(self) -> None:
        if not self._con.in_transaction:
            self._con.execute("BEGIN IMMEDIATE")

    def _flush(self) -> None:
        """The rows waiting in memory (chunks and frames, as they came),
        inserted into the open batch: a few statements for half a second of
        the link, where one per chunk and per frame cost the station's
        reader more than anything else it does for a frame."""
        chunks, frames = self._chunks, self._frames
        if not chunks and not frames:
            return
        self._chunks, self._frames = [], []
        # the rows are made before the write lock is taken, so that the lock
        # is held only while SQLite inserts them: another program writing
        # the archive waits for that, not for this thread's Python
        rows, samples = [], []
        for k, (session, ev) in enumerate(frames):
            region = info = None
            if ev.kind == "sample":
                reg = self._regions[ev.stream] if 0 <= ev.stream < len(self._regions) else None
                region = reg[0] if reg else f"stream {ev.stream}"
                names = reg[1] if reg else ()
                samples += [(k, i, _num(t), _json(dict(zip(names, vals)) if names else list(vals)))
                            for i, (t, vals) in enumerate(ev.samples)]
            else:
                info = _json(ev.info)
            rows.append((k, session, ev.kind, _num(ev.seq), _num(ev.time), float(ev.host_time), region, info))
        con = self._con
        self._begin()
        if chunks:
            con.executemany("INSERT INTO chunks (session, dir, t_ns, data) VALUES (?, ?, ?, ?)", chunks)
        if rows:
            (last,) = con.execute("SELECT coalesce(max(id), 0) FROM frames").fetchone()
            first = last + 1  # the frames' numbers, taken under the lock
            con.executemany("INSERT INTO frames (id, session, kind, seq, time, host_time, region, info) "
                            "VALUES (?, ?, ?, ?, ?, ?, ?, ?)", ((first + r[0],) + r[1:] for r in rows))
            if samples:
                con.executemany("INSERT INTO samples (frame, i, time, vals) VALUES (?, ?, ?, ?)",
                                ((first + r[0],) + r[1:] for r in samples))

    def _commit(self) -> None:
        try:
            self._flush()
            if self._con.in_transaction:
                self._con.execute("COMMIT")
        except sqlite3.Error:  # a full disk, a lock: the batch is lost, the archive as of the last commit
            with contextlib.suppress(sqlite3.Error):
                if self._con.in_transaction:
                    self._con.execute("ROLLBACK")
            raise

    @contextlib.contextmanager
    def _writing(self, need_session: bool = True):
        """The lock, the open connection (None after close: nothing to do)
        and sqlite3's errors as ArchiveErrors."""
        with self._lock:
            if self._con is None:
                yield None
                return
            if need_session and self._session is None:
                raise ArchiveError(f"{self.path}: nothing can be archived before a session begins")
            try:
                yield self._con
            except sqlite3.Error as e:
                raise _sql_error(self.path, e, "write") from None

    @property
    def session(self) -> int | None:
        """The session being written (None: none begun, or the archive closed)."""
        return self._session if self._con is not None else None

    def begin(self, *, layout, project: str, port: str, baud: int, started: float) -> int:
        """A new session (the one open before, if any, ended); its id."""
        from fswkit import __version__

        with self._writing(need_session=False) as con:
            if con is None:
                raise ArchiveError(f"{self.path}: the archive is closed")
            if self._session is not None:
                self._flush()  # the rows of the session that ends, under its number
                self._exec("UPDATE sessions SET ended = ? WHERE id = ?", (started, self._session))
            cur = self._exec("INSERT INTO sessions (project, port, baud, started, layout, fswkit) "
                             "VALUES (?, ?, ?, ?, ?, ?)",
                             (str(project), str(port), int(baud), float(started),
                              json.dumps(layout.raw, sort_keys=True), __version__))
            self._session = cur.lastrowid
            self._regions = [(s.region.name, s.region.names) for s in layout.streams]
            self._commit()  # the session exists on disk before any of its data
            return self._session

    def rx(self, t_ns: int, data: bytes) -> None:
        """Bytes read from the target at host time `t_ns` (ns since the epoch)."""
        self._chunk(0, t_ns, data)

    def tx(self, t_ns: int, data: bytes) -> None:
        """Bytes written to the target."""
        self._chunk(1, t_ns, data)

    def _chunk(self, direction: int, t_ns: int, data: bytes) -> None:
        if not data:
            return
        with self._writing() as con:
            if con is not None:
                self._chunks.append((self._session, direction, int(t_ns), bytes(data)))

    def event(self, ev) -> None:
        """One decoded frame (fswkit.link.session.Event). Its rows are made
        when the batch is written (`_flush`): an event is not changed once
        decoded."""
        with self._writing() as con:
            if con is not None:
                self._frames.append((self._session, ev))

    def received(self, t_ns: int, data: bytes, events=(), now: float | None = None) -> None:
        """What one read of the port brought, as the station archives it: the
        bytes (`rx`), the frames decoded from them (`event` each) and a
        `tick`, under the lock once."""
        with self._writing() as con:
            if con is None:
                return
            if data:
                self._chunks.append((self._session, 0, int(t_ns), bytes(data)))
            session = self._session
            self._frames += [(session, ev) for ev in events]
            self._tick(time.monotonic() if now is None else now)

    def command(self, *, who: str, text: str, op: int, args: bytes, sent: float, cmd_seq, status, words: str,
                acked) -> None:
        """A command a client sent and its acknowledgement: `status` None
        when none came; `acked` the host time it came (or None)."""
        with self._writing() as con:
            if con is not None:
                self._exec("INSERT INTO commands (session, who, text, op, args, sent, cmd_seq, status, words, "
                           "acked) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                           (self._session, str(who), str(text), int(op), bytes(args), float(sent),
                            _num(cmd_seq), _num(status), str(words), None if acked is None else float(acked)))

    def note(self, t: float, text: str) -> None:
        """A station note ("port went away"), in the current session if any."""
        with self._writing(need_session=False) as con:
            if con is not None:
                self._exec("INSERT INTO notes (session, t, text) VALUES (?, ?, ?)",
                           (self._session, float(t), str(text)))

    def tick(self, now: float | None = None) -> None:
        """Commits when COMMIT_EVERY seconds passed since the last tick that
        committed. `now`: the caller's clock, the same one at every call
        (default time.monotonic())."""
        now = time.monotonic() if now is None else now
        with self._writing(need_session=False) as con:
            if con is not None:
                self._tick(now)

    def _tick(self, now: float) -> None:
        if self._last_tick is None or now - self._last_tick >= COMMIT_EVERY or now < self._last_tick:
            self._commit()
            self._last_tick = now
            self._kept()

    def _kept(self) -> None:
        """After a commit: the file deleted meanwhile (an `rm`, a cleanup
        script) is written again at its path, with all the open connection
        still holds (SQLite writes on into a deleted file, which vanishes
        with everything when it is closed), and recording goes on there.
        Said in `notices`."""
        now = _ident(self.path)
        if now == self._ident or self._ident is None:
            return
        if now is not None:  # another file took the name: it is left as it is
            self.notices.append(f"the archive {self.path} was replaced by another file while recording: "
                                "recording goes on in the file it was (no longer under that name)")
            self._ident = None  # said once
            return
        folder = os.path.dirname(os.path.abspath(self.path))
        tmp = None
        try:
            fd, tmp = tempfile.mkstemp(prefix=f".{os.path.basename(self.path)}.", suffix=".part", dir=folder)
            os.close(fd)
            dest = sqlite3.connect(tmp, isolation_level=None)
            try:
                self._con.backup(dest)
                dest.execute("PRAGMA journal_mode = WAL")
            finally:
                dest.close()
        except (OSError, sqlite3.Error) as e:
            if tmp is not None:
                with contextlib.suppress(OSError):
                    os.unlink(tmp)
            raise ArchiveError(f"the archive {self.path} was deleted while recording and cannot be written "
                               f"again: {getattr(e, 'strerror', None) or e}") from None
        # the deleted file's connection closed first: its WAL and index (still under the path's
        # names, unless they went too) are folded into it and removed, not taken for the new file's
        old, self._con = self._con, None
        with contextlib.suppress(sqlite3.Error):
            old.close()
        try:
            os.link(tmp, self.path)  # fails when the name was taken meanwhile: that file is kept
            os.unlink(tmp)
            con = sqlite3.connect(self.path, timeout=5.0, isolation_level=None, check_same_thread=False)
            con.execute("PRAGMA journal_mode = WAL")
            con.execute("PRAGMA synchronous = NORMAL")
        except (OSError, sqlite3.Error) as e:
            kept = tmp if os.path.exists(tmp) else self.path
            raise ArchiveError(f"the archive {self.path} was deleted while recording; all it held is in {kept}, "
                               f"but recording cannot go on: {getattr(e, 'strerror', None) or e}") from None
        self._con = con
        self._ident = _ident(self.path)
        self.notices.append(f"the archive {self.path} was deleted while recording: written again there with "
                            "all it held; recording goes on in it")

    def close(self) -> None:
        """Commits, marks the session ended, closes the file (again: nothing)."""
        with self._lock:
            con = self._con
            if con is None:
                return
            try:
                if self._session is not None:
                    self._flush()
                    self._exec("UPDATE sessions SET ended = ? WHERE id = ?", (time.time(), self._session))
                self._commit()
            except sqlite3.Error as e:
                raise _sql_error(self.path, e, "write") from None
            finally:
                self._con = None
                con.close()

    def abandon(self) -> None:
        """Closes the file at once, the open batch dropped and the session
        left not ended: after a write failed (a lock another program holds, a
        full disk), when no further write could be waited for."""
        with self._lock:
            con, self._con = self._con, None
            self._chunks, self._frames = [], []
            if con is not None:
                with contextlib.suppress(sqlite3.Error):
                    con.rollback()
                con.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


# ---- reading ----------------------------------------------------------------------------

def _connect_ro(path) -> sqlite3.Connection:
    """A read-only connection to an archive (refused before SQLite opens
    anything that is not one)."""
    if os.path.isdir(path):
        raise ArchiveError(f"cannot read {path}: it is a folder")
    if not os.path.exists(path):
        raise ArchiveError(f"cannot read {path}: no such file")
    if not is_archive(path):
        raise ArchiveError(f"{path}: not an fswkit archive")
    try:
        con = sqlite3.connect(f"{Path(path).absolute().as_uri()}?mode=ro", uri=True, timeout=5.0)
        _check_version(con, path)
    except sqlite3.Error as e:
        raise _sql_error(path, e, "read") from None
    return con


class ArchiveReader:
    """One session of an archive, read as fswkit.link.log.LogReader reads a
    log: `layout`, `header`, `path`, `records()`. `session` None: the
    newest. `truncated`: the session was never ended (the station was
    killed, or is still writing it); `incomplete` says so in words."""

    def __init__(self, path: str, session: int | None = None):
        from fswkit.link.layout import LayoutError, from_dict

        self.path = str(path)
        self._con = _connect_ro(self.path)
        try:
            if session is None:
                row = self._con.execute("SELECT * FROM sessions ORDER BY id DESC LIMIT 1").fetchone()
                if row is None:
                    raise ArchiveError(f"{path}: the archive has no sessions yet")
            else:
                row = self._con.execute("SELECT * FROM sessions WHERE id = ?", (session,)).fetchone()
                if row is None:
                    ids = [r[0] for r in self._con.execute("SELECT id FROM sessions ORDER BY id")]
                    there = f"its sessions are {ranges(ids)}" if ids else "it has no sessions yet"
                    raise ArchiveError(f"{path}: no session {session} in the archive: {there} "
                                       "(`fsw archive list` shows them)")
            cols = [d[0] for d in self._con.execute("SELECT * FROM sessions LIMIT 0").description]
        except sqlite3.Error as e:
            raise _sql_error(path, e, "read") from None
        s = dict(zip(cols, row))
        self.session = s["id"]
        self.header = {"session": s["id"], "project": s["project"], "port": s["port"], "baud": s["baud"],
                       "started": s["started"], "ended": s["ended"]}
        self.truncated = s["ended"] is None
        self.incomplete = (f"session {self.session} was never ended (the station was killed, or still runs): "
                           "what it committed is read") if self.truncated else None
        try:
            self.layout = from_dict(json.loads(s["layout"]))
        except (ValueError, LayoutError) as e:
            raise ArchiveError(f"{path}: session {self.session}: not a valid layout: {e}") from None
        except RecursionError:
            raise ArchiveError(f"{path}: session {self.session}: not a valid layout: JSON nested too deeply "
                               "to read") from None

    def records(self):
        """(direction, host time in seconds, bytes) in the order they were archived."""
        con = self._con
        try:
            lo, hi = con.execute("SELECT min(id), max(id) FROM chunks WHERE session = ?", (self.session,)).fetchone()
            if lo is None:
                return
            # the session's rows lie between lo and hi, in rowid order (`+session`: not by the time index)
            cur = con.execute("SELECT dir, t_ns, data FROM chunks WHERE id BETWEEN ? AND ? AND +session = ? "
                              "ORDER BY id", (lo, hi, self.session))
            for d, t, data in cur:
                yield d, t / 1e9, bytes(data)
        except sqlite3.Error as e:
            raise _sql_error(self.path, e, "read") from None

    def close(self) -> None:
        self._con.close()


def sessions(path) -> list[dict]:
    """Every session of an archive: id, project, port, baud, started, ended
    (None: never ended), frames, commands and bytes (both ways)."""
    con = _connect_ro(path)
    try:
        frames = dict(con.execute("SELECT session, count(*) FROM frames GROUP BY session"))
        commands = dict(con.execute("SELECT session, count(*) FROM commands GROUP BY session"))
        nbytes = dict(con.execute("SELECT session, sum(length(data)) FROM chunks GROUP BY session"))
        rows = con.execute("SELECT id, project, port, baud, started, ended FROM sessions ORDER BY id").fetchall()
    except sqlite3.Error as e:
        raise _sql_error(path, e, "read") from None
    finally:
        con.close()
    return [{"id": i, "project": project, "port": port, "baud": baud, "started": started, "ended": ended,
             "frames": frames.get(i, 0), "commands": commands.get(i, 0), "bytes": nbytes.get(i, 0)}
            for i, project, port, baud, started, ended in rows]


# ---- fsw archive list --------------------------------------------------------------------

def _clock(t: float | None) -> str:
    return "-" if t is None else time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(t))


def _span(s: float) -> str:
    s = max(0, int(round(s)))
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}"


def sessions_text(rows: list[dict]) -> str:
    """The sessions as a table (`fsw archive list`)."""
    head = ("session", "started", "length", "project", "port", "baud", "frames", "commands", "bytes")
    table = [head] + [(str(r["id"]), _clock(r["started"]),
                       _span(r["ended"] - r["started"]) if r["ended"] is not None else "not ended",
                       r["project"], r["port"], str(r["baud"]), str(r["frames"]), str(r["commands"]),
                       str(r["bytes"])) for r in rows]
    widths = [max(len(row[i]) for row in table) for i in range(len(head))]
    right = {0, 5, 6, 7, 8}  # numbers
    return "".join("  ".join(c.rjust(w) if i in right else c.ljust(w) for i, (c, w) in enumerate(zip(row, widths)))
                   .rstrip() + "\n" for row in table)
