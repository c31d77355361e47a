"""The page's archive browser: the sessions of the station's archive and,
for one session, its samples thinned to what a plot can show, its state
transitions, its commands and its notes. Every call opens the archive
read-only (fswkit.ground.archive) and closes it again: the station goes on
writing it meanwhile (WAL), never locked out. Plain functions that block:
the web app calls them in a worker thread.

Times are seconds from the session's start (host time): a sample is placed
at its frame's arrival less what its batch waited (a batch's samples are
a stream period apart, its last one sent as the frame went out)."""

from __future__ import annotations

import json
import math
import os
import sqlite3
import threading
import time
from collections import OrderedDict

from fswkit.autocode.types import TYPES

MAX_POINTS = 5000  # per element and request: what a plot a few thousand pixels wide can show
LIST_MAX = 5000  # transitions, commands and notes listed per session at most
CACHE_ENTRIES = 64  # answers kept for ended sessions (zooming out again is then immediate)

_CACHE: OrderedDict = OrderedDict()
_CACHE_LOCK = threading.Lock()


class BrowseError(Exception):
    """A request the archive cannot answer: an HTTP status and the words."""

    def __init__(self, status: int, words: str):
        super().__init__(words)
        self.status, self.words = status, words


class Thinning:
    """Rows (x, y1, .., yk) — k series sampled together — thinned to at
    most `points` per series, of those with lo <= x <= hi: all of them
    while they are that few, else for each series the least and the
    greatest y of each of points // 2 equal spans of [lo, hi] (a span's
    extremes kept in x order), so a spike survives any range. y None (no
    value) is a gap; in a thinned span it stays only where the span has no
    value at all. `n`: the rows in the range."""

    def __init__(self, lo: float, hi: float, points: int, k: int = 1):
        if points < 2:
            raise ValueError("points must be 2 or more")
        self.lo, self.hi, self.points, self.k, self.n = lo, hi, points, k, 0
        self._spans = points // 2
        self._scale = self._spans / (hi - lo) if hi > lo else 0.0
        self._raw: list | None = []  # the rows while they are few enough
        self._buckets: list[dict] = [{} for _ in range(k)]  # per series: span -> [x lo, y lo, x hi, y hi]

    def feed(self, rows) -> None:
        lo, hi, points = self.lo, self.hi, self.points
        rows = iter(rows)
        raw = self._raw
        if raw is not None:
            for row in rows:
                if lo <= row[0] <= hi:
                    raw.append(row)
                    if len(raw) > points:  # too many: from now on, the extremes of each span
                        self._raw = None
                        self._spread(raw)
                        break
            else:
                self.n = len(raw)
                return
        self._spread(rows)

    def _spread(self, rows) -> None:
        lo, hi, scale, top = self.lo, self.hi, self._scale, self._spans - 1
        columns = list(enumerate(self._buckets, 1))
        n = 0
        for row in rows:
            x = row[0]
            if not lo <= x <= hi:
                continue
            n += 1
            b = int((x - lo) * scale)
            if b > top:
                b = top
            for i, buckets in columns:
                y = row[i]
                cur = buckets.get(b)
                if cur is None:
                    buckets[b] = [x, y, x, y]
                elif y is not None:
                    if cur[1] is None:
                        cur[:] = [x, y, x, y]
                    elif y < cur[1]:
                        cur[0], cur[1] = x, y
                    elif y > cur[3]:
                        cur[2], cur[3] = x, y
        self.n += n

    def result(self) -> list[tuple[list, list]]:
        """Per series, (xs, ys) in x order."""
        if self._raw is not None:
            rows = sorted(self._raw, key=lambda r: r[0])
            xs = [r[0] for r in rows]
            return [(xs, [r[i] for r in rows]) for i in range(1, self.k + 1)]
        out = []
        for buckets in self._buckets:
            pts = []
            for b in sorted(buckets):
                x0, y0, x1, y1 = buckets[b]
                if x0 == x1:
                    pts.append((x0, y0))
                else:
                    pts += [(x0, y0), (x1, y1)] if x0 < x1 else [(x1, y1), (x0, y0)]
            out.append(([p[0] for p in pts], [p[1] for p in pts]))
        return out


def decimate(pairs, lo: float, hi: float, points: int) -> tuple[list, list]:
    """(xs, ys) of the (x, y) pairs from lo to hi, thinned to `points` at
    most (Thinning)."""
    t = Thinning(lo, hi, points)
    t.feed(pairs)
    return t.result()[0]


def _connect(path: str) -> sqlite3.Connection:
    from fswkit.ground.archive import ArchiveError, _connect_ro

    try:
        return _connect_ro(path)
    except ArchiveError as e:
        raise BrowseError(503, str(e)) from None


def _read(path: str, fn):
    """fn(connection) on a read-only connection, closed after; SQLite's
    errors as the archive's words."""
    con = _connect(path)
    try:
        return fn(con)
    except sqlite3.Error as e:
        raise BrowseError(503, f"cannot read the archive {path}: {e}") from None
    finally:
        con.close()


def list_sessions(path: str, live: int | None) -> list[dict]:
    """The archive's sessions (fswkit.ground.archive.sessions), each with
    its `end` (when it ended; a session not ended: its last frame, or now
    for the live one), `duration` (s) and `live` (the one the station is
    writing)."""
    from fswkit.ground.archive import ArchiveError, sessions

    try:
        rows = sessions(path)
    except ArchiveError as e:
        raise BrowseError(503, str(e)) from None
    open_ = [r["id"] for r in rows if r["ended"] is None and r["id"] != live]

    def last_frames(con):
        return {i: con.execute("SELECT max(host_time) FROM frames WHERE session = ?", (i,)).fetchone()[0]
                for i in open_}

    last = _read(path, last_frames) if open_ else {}
    now = time.time()
    for r in rows:
        r["live"] = r["id"] == live
        if r["ended"] is not None:
            r["end"] = r["ended"]
        elif r["live"]:
            r["end"] = max(now, r["started"])
        else:
            r["end"] = last.get(r["id"]) or r["started"]
        r["duration"] = max(0.0, r["end"] - r["started"])
    return rows


def _session_id(text: str) -> int:
    if not (text.isascii() and text.isdigit()) or len(text) > 18:
        raise BrowseError(404, f"no session `{text}`: a session is named by its number "
                               "(the sessions list shows them)")
    return int(text)


def _state(names: dict, v):
    if v is None:
        return None
    if isinstance(v, (int, float)) and not isinstance(v, bool) and v == int(v):
        return names.get(int(v), str(int(v)))
    return str(v)


class Session:
    """One session of the archive: its header, layout and span, read on
    construction (BrowseError 404 naming the sessions there are when it
    is not one of them)."""

    def __init__(self, path: str, session: str | int, live: int | None = None):
        from fswkit.autocode.diagnostics import ranges
        from fswkit.link.layout import LayoutError, from_dict

        self.path = path
        sid = _session_id(str(session))

        def head(con):
            row = con.execute("SELECT id, project, port, baud, started, ended, layout FROM sessions WHERE id = ?",
                              (sid,)).fetchone()
            if row is None:
                ids = [r[0] for r in con.execute("SELECT id FROM sessions ORDER BY id")]
                there = f"its sessions are {ranges(ids)}" if ids else "it has no sessions yet"
                raise BrowseError(404, f"no session {sid} in the archive {path}: {there}")
            last, = con.execute("SELECT max(host_time) FROM frames WHERE session = ?", (sid,)).fetchone()
            return row, last

        (self.id, self.project, self.port, self.baud, self.started, self.ended, text), last = _read(path, head)
        try:
            self.layout = from_dict(json.loads(text))
        except (ValueError, LayoutError) as e:
            raise BrowseError(422, f"session {self.id} of {path}: not a valid layout: {e}") from None
        except RecursionError:
            raise BrowseError(422, f"session {self.id} of {path}: not a valid layout: JSON nested too deeply "
                                   "to read") from None
        self.live = self.id == live
        end = self.ended if self.ended is not None else (time.time() if self.live else (last or self.started))
        self.span = max(0.0, end - self.started)
        self.per_second = 1000.0 if self.layout.time_unit == "ms" else 1e6

    def info(self) -> dict:
        lay = self.layout
        elements = [{"name": e.name, "type": e.type, "kind": TYPES[e.type].kind, "region": e.region,
                     "states": {str(k): v for k, v in lay.states[e.name].items()} if e.name in lay.states else None}
                    for e in lay.elements]
        return {"id": self.id, "project": self.project, "port": self.port, "baud": self.baud,
                "started": self.started, "ended": self.ended, "live": self.live, "span": self.span,
                "name": lay.name, "schema": f"0x{lay.schema:08x}", "time_unit": lay.time_unit,
                "elements": elements, "state_elements": list(lay.states)}

    # ---- the samples of an element --------------------------------------------------------

    def _rows(self, con, region: str, names: list[str], lo: float | None = None, hi: float | None = None):
        """(x, the value of each of `names`) of every sample of `region`'s
        frames in frame order (x from lo to hi, and a batch's wait either
        side: the caller keeps what it needs; None: the whole session).
        A value that is not a finite number is None."""
        stream = next((st for st in self.layout.streams if st.region.name == region), None)
        if stream is None:  # a region no stream sends
            return
        wait = (stream.batch - 1) * stream.period / self.per_second  # a batch's first sample, before its frame
        if lo is None:
            bounds = con.execute("SELECT min(id), max(id) FROM frames WHERE session = ?", (self.id,))
        else:
            bounds = con.execute("SELECT min(id), max(id) FROM frames WHERE session = ? AND host_time BETWEEN ? AND ?",
                                 (self.id, self.started + lo, self.started + hi + wait))
        first, last = bounds.fetchone()
        if first is None:
            return
        # a value that is not a number (the archive's "NaN", "Infinity") a gap
        values = ", ".join(f"CASE WHEN typeof(v{i}) IN ('integer', 'real') THEN v{i} END" for i in range(len(names)))
        extract = ", ".join(f"json_extract(s.vals, ?) AS v{i}" for i in range(len(names)))
        # the session's frames by their ids (`+f.session`: not through the time index), their samples by
        # the samples' key: rows come in the order they were archived, with no sort
        yield from con.execute(
            f"SELECT x, {values} FROM (SELECT f.host_time - ? + (s.time - f.time) / ? AS x, {extract} "
            "FROM frames f JOIN samples s ON s.frame = f.id "
            "WHERE f.id BETWEEN ? AND ? AND +f.session = ? AND f.kind = 'sample' AND f.region = ? "
            "ORDER BY f.id, s.i)",
            (self.started + wait, self.per_second, *[f'$."{n}"' for n in names], first, last, self.id, region))

    def check_elements(self, text: str | None) -> list[str]:
        names = [n.strip() for n in (text or "").split(",") if n.strip()]
        unknown = [n for n in names if self.layout.element(n) is None]
        if unknown:
            raise BrowseError(422, f"unknown element(s) {', '.join(unknown)}: session {self.id}'s elements are "
                                   + ", ".join(e.name for e in self.layout.elements))
        return list(dict.fromkeys(names))

    def _cached(self, key, fn):
        """fn() once for an ended session (what it holds no longer
        changes), again each time for one still written."""
        if self.ended is None:
            return fn()
        key = (self.path, self.id, self.started) + key
        with _CACHE_LOCK:
            if key in _CACHE:
                _CACHE.move_to_end(key)
                return _CACHE[key]
        v = fn()
        with _CACHE_LOCK:
            _CACHE[key] = v
            while len(_CACHE) > CACHE_ENTRIES:
                _CACHE.popitem(last=False)
        return v

    def series(self, names: list[str], lo: float, hi: float, points: int) -> list[dict]:
        """Each element's samples from `lo` to `hi` s, thinned to `points`
        at most (Thinning): {name, x, y, total (samples in the range),
        thinned}. One pass over the frames of each region."""
        def read(con):
            by_region: dict = {}
            for n in names:
                by_region.setdefault(self.layout.element(n).region, []).append(n)
            out = {}
            for region, group in by_region.items():
                thin = Thinning(lo, hi, points, len(group))
                thin.feed(self._rows(con, region, group, lo, hi))
                for n, (xs, ys) in zip(group, thin.result()):
                    out[n] = {"name": n, "x": [round(x, 6) for x in xs], "y": ys, "total": thin.n,
                              "thinned": thin.n > len(xs)}
            return [out[n] for n in names]

        return self._cached(("series", tuple(names), lo, hi, points), lambda: _read(self.path, read))

    # ---- transitions, commands, notes -------------------------------------------------------

    def events(self) -> dict:
        """The session's state transitions ({t, machine, from, to}; the
        first of each machine its state as the session began), commands
        ({t, who, text, status, ok, words, acked}: acked in s after it was
        sent, None when no acknowledgement came) and notes ({t, text}),
        each in time order, LIST_MAX at most (`more`: how many were left out)."""
        lay = self.layout

        def read(con):
            transitions, more = [], 0
            machines: dict = {}
            for m in lay.states:
                machines.setdefault(lay.element(m).region, []).append(m)
            for region, group in machines.items():
                last = [None] * len(group)
                for row in self._rows(con, region, group):
                    for k, m in enumerate(group):
                        v = row[k + 1]
                        if v is None or v == last[k]:
                            continue
                        if len(transitions) < LIST_MAX:
                            transitions.append({"t": round(row[0], 6), "machine": m,
                                                "from": _state(lay.states[m], last[k]),
                                                "to": _state(lay.states[m], v)})
                        else:
                            more += 1
                        last[k] = v
            transitions.sort(key=lambda r: r["t"])
            commands = [{"t": sent - self.started, "who": who, "text": text, "status": status, "ok": status == 0,
                         "words": words, "acked": None if acked is None else acked - sent}
                        for who, text, sent, status, words, acked in con.execute(
                            "SELECT who, text, sent, status, words, acked FROM commands WHERE session = ? "
                            "ORDER BY sent LIMIT ?", (self.id, LIST_MAX))]
            n_commands, = con.execute("SELECT count(*) FROM commands WHERE session = ?", (self.id,)).fetchone()
            notes = [{"t": t - self.started, "text": text} for t, text in con.execute(
                "SELECT t, text FROM notes WHERE session = ? ORDER BY t LIMIT ?", (self.id, LIST_MAX))]
            n_notes, = con.execute("SELECT count(*) FROM notes WHERE session = ?", (self.id,)).fetchone()
            return {"transitions": transitions, "commands": commands, "notes": notes,
                    "more": {"transitions": more, "commands": n_commands - len(commands),
                             "notes": n_notes - len(notes)}}

        return self._cached(("events",), lambda: _read(self.path, read))


def range_args(session: Session, query) -> tuple[float, float]:
    """`from` and `to` (s from the session's start; default: all of it)."""
    def number(key, default):
        text = query.get(key)
        if text is None or text == "":
            return default
        try:
            v = float(text)
        except ValueError:
            v = math.nan
        if not math.isfinite(v):
            raise BrowseError(422, f"{key}={text}: give seconds from the session's start (a number)")
        return v

    lo, hi = number("from", 0.0), number("to", session.span)
    if lo >= hi and not (lo == hi == session.span == 0.0):
        raise BrowseError(422, f"from={lo:g} is not before to={hi:g}: nothing to show")
    return lo, hi


def points_arg(query) -> int:
    text = query.get("points")
    if text is None or text == "":
        return MAX_POINTS
    try:
        n = int(text)
    except ValueError:
        n = -1
    if not 2 <= n <= MAX_POINTS:
        raise BrowseError(422, f"points={text}: give a whole number from 2 to {MAX_POINTS} (points per element)")
    return n


def export(path: str, session: Session, fmt: str, query, ignore_schema: bool, folder: str) -> tuple[str, str]:
    """The session as CSV (the text of `fsw log2csv`) or Parquet
    (fswkit.ground.logs.export) in a file in `folder`, its rows from
    `from` to `to` s when given: (the file, a name for the download)."""
    from fswkit.ground.archive import ArchiveError
    from fswkit.ground.logs import export as export_rows
    from fswkit.ground.monitor import GroundError
    from fswkit.outputs import OutputError

    t_from = t_to = None
    if query.get("from") or query.get("to"):
        lo, hi = range_args(session, query)
        t_from = lo if query.get("from") else None
        t_to = hi if query.get("to") else None
    name = "".join(c if c.isalnum() or c in "-_." else "-"
                   for c in os.path.basename(os.path.normpath(session.project)).strip(".") or session.layout.name)
    out = os.path.join(folder, f"{name}-session-{session.id}.{fmt}")
    try:
        export_rows(path, out, session=session.id, t_from=t_from, t_to=t_to, force=True, ignore_schema=ignore_schema)
    except (ArchiveError, GroundError, OutputError) as e:
        raise BrowseError(422, str(e)) from None
    return out, os.path.basename(out)
