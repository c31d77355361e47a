"""fswkit sensor tape v1: read, check, write; and the tape's truth file.

A tape (docs/tapes.md) is a small CSV of a real flight:

    # fswkit sensor tape v1
    # source: OWNER/REPO@COMMIT:PATH (LICENCE)      one a source file
    # flight: NAME, DATE, recorder, pad altitude    what flew
    # derived: how a column was made                one or more
    # note: anything worth knowing                  optional
    time_s,pressure_pa,accel_g
    -0.30,86334,1.15
    ...

`time_s` counts from liftoff (negative before), strictly increasing;
`pressure_pa` is static pressure in Pa; `accel_g` axial acceleration in g,
+1 at rest on the pad. An empty cell is "not available at that row" and is
NaN in the arrays (NaN, inf or any other spelling in the file is refused).

`read_tape` reads a file the user named the way the kit reads every user
file (fswkit.autocode.diagnostics.read_input: regular files only, a size
limit, MAX_TAPE here), and raises TapeError with located messages
`PATH:LINE:COL: message` for anything it cannot take. A line ends in LF,
CRLF or CR alone. `write_tape` writes
through fswkit.outputs: a temporary file renamed into place, and an
existing file is replaced only when asked (`force`).

`read_truth` reads `NAME.truth.toml` (events computed from the tape, as
../shared/flights/README.md describes) into a Truth: `name` required,
every other key optional, unknown keys kept in `extra`.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fswkit.autocode.diagnostics import MAX_INPUT, InputError, read_input, toml_error_at

MAGIC = "# fswkit sensor tape v1"
COLUMNS = ("time_s", "pressure_pa", "accel_g")
COLUMN_LINE = ",".join(COLUMNS)
MAX_TAPE = 64 << 20  # bytes: a whole flight at 1 kHz for an hour is ~100 MB; 100 Hz fits 64 MiB many times
HEADER_KEYS = ("source", "flight", "derived", "note")
MAX_ERRORS = 20  # located messages kept in one TapeError (the rest counted)
LINE_END = re.compile(r"\r\n|\r|\n")  # LF, CRLF, or CR alone (Excel for Mac's "CSV (Macintosh)")
LINE_END_BYTES = re.compile(LINE_END.pattern.encode())  # the same, in the file's bytes


def split_lines(text: str) -> list[str]:
    """The text's lines, each ended by LF, CRLF or CR alone (the ends dropped)."""
    return text.split("\n") if "\r" not in text else LINE_END.split(text)

# ISA standard atmosphere (troposphere), the formula of every tape and truth file
ISA_P0 = 101325.0  # Pa
ISA_H0 = 44330.77  # m
ISA_N = 0.190263


def isa_altitude(p):
    """Pressure altitude in m above the ISA sea level: H(p) = 44330.77 * (1 - (p / 101325)^0.190263).
    Takes a number or a numpy array."""
    return ISA_H0 * (1.0 - np.power(np.asarray(p, dtype=float) / ISA_P0, ISA_N))


def isa_pressure(h):
    """ISA pressure in Pa at `h` m above sea level: p(H) = 101325 * (1 - H / 44330.77)^(1 / 0.190263),
    the inverse of isa_altitude. Takes a number or a numpy array."""
    return ISA_P0 * np.power(1.0 - np.asarray(h, dtype=float) / ISA_H0, 1.0 / ISA_N)


# The physical range of each column (docs/tapes.md, "Ranges"): what a small rocket's recorder can log.
# A cell beyond it is no flight's (a wrong unit, a glitch row, a clock that jumped) and is refused where it
# is, by the reader (so by `fsw tape show`, `fsw tape truth` and `fsw sim --tape`), the writer and the
# converters (at the log's cell).
TIME_RANGE_S = (-3600.0, 3600.0)  # from liftoff: an hour either side (a replay flies at most an hour of tape)
MIN_STEP_S = 1e-6  # rows at least 1 µs apart: no recorder samples at 1 MHz (the kit's formats: 10 Hz to 1 kHz)
MAX_STEP_S = 60.0  # and at most 60 s apart: the slowest of them logs at 1 Hz or more; more is a clock that jumped
PRESSURE_RANGE_PA = (1_000.0, 120_000.0)  # 10 to 1,200 hPa: the MS5607/MS5611's, the widest of these barometers
ACCEL_RANGE_G = (-250.0, 250.0)  # the widest accelerometer of these recorders reads ±200 g (ADXL375), 1 g offset
# and its calibration left room
RANGES = {"time_s": (TIME_RANGE_S, "s"), "pressure_pa": (PRESSURE_RANGE_PA, "Pa"), "accel_g": (ACCEL_RANGE_G, "g")}
_WHY = {"time_s": "a tape holds the hour either side of liftoff: check the time's unit, or cut the tape to the "
                  "flight",
        "pressure_pa": "no barometer of a flight recorder reads it (10 to 1,200 hPa): a cell in another unit, or "
                       "a glitch row: leave the cell empty",
        "accel_g": "no accelerometer of a flight recorder reads it (the widest reads ±200 g): a cell in another "
                   "unit, or a glitch row: leave the cell empty"}


def beyond_range(column: str, value: float) -> str | None:
    """What is wrong with `value` (a finite number) in tape column `column`
    (time_s, pressure_pa, accel_g): None when within its range (RANGES);
    else the words after the value, `is beyond ... (the range): why and
    what to do`. A pressure not above 0 keeps its own words."""
    (lo, hi), unit = RANGES[column]
    if lo <= value <= hi:
        return None
    if column == "pressure_pa" and not value > 0:
        return "is not above 0 Pa"
    return f"is beyond {lo:,.0f} to {hi:,.0f} {unit}: {_WHY[column]}"


def step_problem(step: float) -> str | None:
    """What is wrong with a time step of `step` s (> 0) between consecutive
    rows: None within MIN_STEP_S to MAX_STEP_S, else the words saying why."""
    if step < MIN_STEP_S:
        return ("rows lie at least 1 µs apart (no recorder samples at 1 MHz): a time in another unit? delete "
                "the row or fix its time")
    if step > MAX_STEP_S:
        return (f"rows of a flight lie at most {MAX_STEP_S:g} s apart (every recorder of the kit's formats logs "
                "at 1 Hz or more): a clock that jumped? cut the tape there, or fix the times after the jump")
    return None


def step_text(step: float) -> str:
    return f"{step:,.6g}"


class TapeError(Exception):
    """A tape, truth file or log that cannot be read: every message located
    (`PATH:LINE:COL: message`, or `PATH: message` for the file as a whole)."""

    def __init__(self, messages: list[str], hidden: int = 0):
        self.messages = list(messages)
        self.hidden = hidden
        text = "\n".join(self.messages)
        if hidden:
            text += f"\n({hidden} more not shown)"
        super().__init__(text)


class _Errors:
    """Located messages of one file, at most MAX_ERRORS kept."""

    def __init__(self, path: str):
        self.path, self.items, self.hidden = path, [], 0

    def at(self, line: int | None, col: int | None, message: str) -> None:
        if len(self.items) >= MAX_ERRORS:
            self.hidden += 1
            return
        where = self.path
        if line is not None:
            where += f":{line}"
            if col is not None:
                where += f":{col}"
        self.items.append(f"{where}: {message}")

    def raise_if_any(self) -> None:
        if self.items:
            raise TapeError(self.items, self.hidden)


@dataclass(frozen=True, eq=False)
class Tape:
    """One tape: three aligned float64 arrays (NaN = empty cell) and its header.
    Compared by identity (arrays have no single truth value).

    `time` is strictly increasing, in s from liftoff. `sources`, `flight`,
    `derived` and `notes` are the header lines' texts after their key
    (`flight` the first `# flight:` line, "" if none); `comments` any other
    `#` line of the header, kept as written (without the `#`).
    """

    path: str
    time: np.ndarray
    pressure: np.ndarray
    accel: np.ndarray
    sources: tuple[str, ...] = ()
    flight: str = ""
    derived: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    comments: tuple[str, ...] = ()
    first_line: int = 0  # the file's line of row 0 (read_tape's; 0: a tape made in memory)

    @property
    def rows(self) -> int:
        return int(self.time.size)

    @property
    def start(self) -> float:
        return float(self.time[0])

    @property
    def end(self) -> float:
        return float(self.time[-1])

    @property
    def span(self) -> float:
        return self.end - self.start

    def available(self, column: str) -> np.ndarray:
        """A boolean mask of the rows where `column` ("pressure_pa" or "accel_g") has a value."""
        return ~np.isnan(self.pressure if column == "pressure_pa" else self.accel)

    def columns_available(self) -> tuple[str, ...]:
        """The sensor columns with a value in at least one row."""
        return tuple(c for c in COLUMNS[1:] if self.available(c).any())

    def rate_hz(self, column: str | None = None, t0: float | None = None, t1: float | None = None) -> float:
        """The median sample rate (1 / median time step) of the rows where
        `column` has a value (every row for None), within [t0, t1] if given;
        0 when fewer than two such rows."""
        mask = np.ones(self.rows, dtype=bool) if column is None else self.available(column)
        if t0 is not None:
            mask &= self.time >= t0
        if t1 is not None:
            mask &= self.time <= t1
        t = self.time[mask]
        if t.size < 2:
            return 0.0
        with np.errstate(over="ignore", divide="ignore"):  # times at binary64's ends: inf Hz, not a warning
            return float(1.0 / np.median(np.diff(t)))

    def altitude_agl(self, pad_pa: float | None = None) -> np.ndarray:
        """ISA pressure altitude above the pad, m (NaN where no pressure):
        H(p) - H(pad), the pad being `pad_pa` or else the mean pressure of the
        rows before liftoff (the first pressure when there are none), as the
        truth files do."""
        if pad_pa is None:
            pad_pa = self.pad_pressure()
        return isa_altitude(self.pressure) - float(isa_altitude(pad_pa))

    def pad_pressure(self) -> float:
        """Mean pressure of the rows before liftoff; the first pressure if there
        are none; NaN if the tape has no pressure."""
        have = self.available("pressure_pa")
        before = have & (self.time < 0)
        if before.any():
            return float(np.mean(self.pressure[before]))
        return float(self.pressure[have][0]) if have.any() else math.nan


# ---- reading ------------------------------------------------------------------------

_EMPTY = {"tape": "a tape starts with the line `# fswkit sensor tape v1` (docs/tapes.md)",
          "log": "a recorder's log holds a column line and rows (docs/tapes.md, Converters)",
          "truth": "a truth file holds at least `name = \"...\"`"}
_UTF8 = {"tape": "a tape is UTF-8 text (docs/tapes.md)", "log": "the log is read as UTF-8 text (docs/tapes.md)",
         "truth": "a truth file is UTF-8 text"}


def _text(data: bytes, err: _Errors, what: str = "tape") -> str | None:
    """The file's text: UTF-8 (a byte order mark dropped), no NUL bytes;
    a located error at the first bad byte otherwise. `what` the file is
    ("tape", "log", "truth") words the message."""
    if not data:
        err.at(None, None, f"empty file: {_EMPTY[what]}")
        return None
    bad = data.find(b"\0")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        bad = e.start if bad < 0 else min(bad, e.start)
    if bad >= 0:
        ends = [m.end() for m in LINE_END_BYTES.finditer(data, 0, bad)]
        line = len(ends) + 1
        col = bad - (ends[-1] if ends else 0) + 1
        err.at(line, col, f"not a text file (binary data here): {_UTF8[what]}")
        return None
    return text


def number(text: str) -> float | None:
    """The number a stripped cell writes as CSV writes one (ASCII digits, a
    point, an exponent), None if it writes none: float() takes more
    (`1_000`, digits of any script, `infinity`), and NaN and infinities are
    no finite number. Checked after float() (the usual cell is a number)."""
    try:
        v = float(text)
    except ValueError:
        return None
    if not math.isfinite(v) or "_" in text or not text.isascii():
        return None
    return v


def _cell_value(cell: str) -> float | None:
    """A cell's number, math.nan for an empty cell, None if not a finite number."""
    s = cell.strip()
    if not s:
        return math.nan
    return number(s)


def parse_tape(data: bytes | str, path: str) -> Tape:
    """Parses a tape's bytes (or text); TapeError with every located problem
    (at most MAX_ERRORS shown)."""
    err = _Errors(path)
    if isinstance(data, bytes):
        text = _text(data, err)
        err.raise_if_any()
    else:
        text = data
        if not text:
            err.at(None, None, "empty file: a tape starts with the line `# fswkit sensor tape v1` "
                               "(docs/tapes.md)")
            err.raise_if_any()
    lines = split_lines(text)
    if lines and lines[-1] == "":
        lines.pop()  # the final newline
    lines = [l[:-1] if l.endswith("\r") else l for l in lines]
    if not lines or lines[0].rstrip() != MAGIC:
        err.at(1, 1, f"not a fswkit sensor tape: its first line must be `{MAGIC}` (docs/tapes.md); a "
                     "recorder's log is made a tape with `fsw tape import FORMAT LOG -o TAPE.csv`")
        err.raise_if_any()
    header: dict[str, list[str]] = {k: [] for k in HEADER_KEYS}
    comments: list[str] = []
    n = 1
    while n < len(lines) and lines[n].startswith("#"):
        body = lines[n][1:].strip()
        m = re.match(r"([a-z]+):\s?(.*)$", body)
        if m and m.group(1) in header:
            header[m.group(1)].append(m.group(2).strip())
        else:
            comments.append(body)
        n += 1
    if n >= len(lines):
        err.at(n, 1, f"the header ends without the column line `{COLUMN_LINE}`")
        err.raise_if_any()
    column_line = lines[n]
    if column_line.strip() != COLUMN_LINE:
        err.at(n + 1, 1, f"expected the column line `{COLUMN_LINE}`, found `{column_line.strip()[:60]}`")
        err.raise_if_any()
    first = n + 2  # the first data row's line number (1-based)
    rows = lines[n + 1:]
    # trailing empty lines are tolerated (an editor's); an empty line inside is not
    while rows and not rows[-1].strip():
        rows.pop()
    if not rows:
        err.at(n + 1, len(column_line) + 1, "no data rows after the column line")
        err.raise_if_any()
    # the columns gathered as Python floats, made arrays at the end
    t: list[float] = []
    p: list[float] = []
    a: list[float] = []
    names = COLUMNS
    prev = -math.inf
    isfinite, nan = math.isfinite, math.nan
    for i, line in enumerate(rows):
        ln = first + i
        if line.startswith("#"):
            err.at(ln, 1, "a `#` line among the data rows: header lines come before the column line")
            t.append(math.nan), p.append(math.nan), a.append(math.nan)
            continue
        cells = line.split(",")
        if len(cells) != 3:
            err.at(ln, 1, f"expected 3 cells ({COLUMN_LINE}), found {len(cells)}")
            t.append(math.nan), p.append(math.nan), a.append(math.nan)
            continue
        # the usual row, read in one go: ASCII without `_`, each cell a finite number (float() of the cell
        # is `number` of the stripped cell: float() strips no more than str.strip) or empty (math.nan; the
        # time never); any other row is read cell by cell below, with its errors
        c0, c1, c2 = cells
        values = None
        if line.isascii() and "_" not in line:
            try:
                tv, pv, av = float(c0), float(c1) if c1 else nan, float(c2) if c2 else nan
            except ValueError:
                pass
            else:
                if isfinite(tv) and (isfinite(pv) or not c1) and (isfinite(av) or not c2):
                    values = tv, pv, av
        if values is None:
            col = 1
            values = []
            for k, cell in enumerate(cells):
                v = _cell_value(cell)
                if v is None:
                    s = cell.strip()
                    what = "not a finite number" if s.lower().lstrip("+-") in ("nan", "inf", "infinity") \
                        else "not a number"
                    err.at(ln, col, f"{names[k]}: `{s[:40]}` is {what} (leave the cell empty for "
                                    "\"not available\")" if k else f"{names[k]}: `{s[:40]}` is {what}")
                    v = math.nan
                elif k == 0 and math.isnan(v):
                    err.at(ln, col, "time_s is empty: every row needs its time")
                values.append(v)
                col += len(cell) + 1
        tv, pv, av = values
        t.append(tv), p.append(pv), a.append(av)
        if not math.isnan(tv):
            if tv <= prev:
                err.at(ln, 1, f"time_s {cells[0].strip()} is not after the previous row's "
                              f"{prev:g}: times increase strictly")
            prev = max(prev, tv)
        if not math.isnan(pv) and pv <= 0:
            err.at(ln, len(cells[0]) + 2, f"pressure_pa {cells[1].strip()} is not above 0 Pa")
    t, p, a = np.array(t, dtype=float), np.array(p, dtype=float), np.array(a, dtype=float)
    err.raise_if_any()
    _range_errors(err, rows, first, t, p, a)
    err.raise_if_any()
    return Tape(path, t, p, a, tuple(header["source"]), header["flight"][0] if header["flight"] else "",
                tuple(header["derived"]), tuple(header["note"]), tuple(comments), first)


def _range_errors(err: _Errors, rows: list[str], first: int, t: np.ndarray, p: np.ndarray, a: np.ndarray) -> None:
    """Located errors (`err`) for the cells of a parsed tape (times strictly
    increasing) beyond their column's range (RANGES), and the rows closer to
    or further from the previous row than MIN_STEP_S to MAX_STEP_S (the
    previous row within the range of times); `rows[i]`, the text of row `i`,
    at line `first + i`. Found with numpy (a long tape reads in the time it
    did), worded row by row."""
    beyond = {}
    for name, v in zip(COLUMNS, (t, p, a)):
        (lo, hi), _unit = RANGES[name]
        with np.errstate(invalid="ignore"):
            beyond[name] = ~np.isnan(v) & ((v < lo) | (v > hi)) & ~((name == "pressure_pa") & (v <= 0))
    within = np.flatnonzero(~beyond["time_s"])
    steps = np.diff(t[within])
    jumped = np.zeros(t.size, dtype=bool)
    jumped[within[1:][(steps < MIN_STEP_S) | (steps > MAX_STEP_S)]] = True
    for i in np.flatnonzero(beyond["time_s"] | beyond["pressure_pa"] | beyond["accel_g"] | jumped).tolist():
        cells = rows[i].split(",")
        col = 1
        for k, name in enumerate(COLUMNS):
            if beyond[name][i]:
                v = (t, p, a)[k][i]
                err.at(first + i, col, f"{name} {v:g} {beyond_range(name, float(v))}")
            col += len(cells[k]) + 1
        if jumped[i]:
            prev = float(t[within[np.searchsorted(within, i) - 1]])
            step = float(t[i]) - prev
            err.at(first + i, 1, f"time_s {t[i]:g} is {step_text(step)} s after the previous row's {prev:g} s: "
                                 f"{step_problem(step)}")


def read_file(path: str, limit: int) -> bytes:
    """The bytes of a user's file (fswkit.autocode.diagnostics.read_input:
    size limit, no FIFOs or devices); TapeError when it cannot be read."""
    try:
        return read_input(path, limit)
    except FileNotFoundError:
        raise TapeError([f"{path}: no such file"]) from None
    except InputError as e:
        raise TapeError([f"{path}: {e}"]) from None
    except OSError as e:
        raise TapeError([f"{path}: cannot read: {e.strerror or e}"]) from None


def read_tape(path: str) -> Tape:
    """Reads and checks the tape at `path`; TapeError (located messages) for a
    file it cannot read or take."""
    return parse_tape(read_file(path, MAX_TAPE), path)


# ---- writing ------------------------------------------------------------------------

def _num(v: float, digits: int) -> str:
    if math.isnan(v):
        return ""
    s = f"{v:.{digits}f}"
    if "." in s:
        s = s.rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def format_tape(tape: Tape, *, time_digits: int = 5, pressure_digits: int = 1, accel_digits: int = 4) -> str:
    """The tape as the text of a v1 file (header, column line, rows). Numbers
    are written with at most the given decimals, trailing zeros dropped; but
    what the file must keep apart is written exactly (Python's shortest
    round-trip text) where those decimals would merge or zero it: every time
    of a tape whose rows lie closer than the time's precision, and a
    pressure above 0 that would round to 0. So what is written reads back."""
    out = [MAGIC]
    out += [f"# source: {s}" for s in tape.sources]
    if tape.flight:
        out.append(f"# flight: {tape.flight}")
    out += [f"# derived: {d}" for d in tape.derived]
    out += [f"# note: {n}" for n in tape.notes]
    out += [f"# {c}" for c in tape.comments]
    out.append(COLUMN_LINE)
    times = [_num(t, time_digits) for t in tape.time.tolist()]
    back = [float(c) if c else math.nan for c in times]
    if any(b <= a for a, b in zip(back, back[1:])):  # rows closer than the precision: written exactly
        times = [_exact(t) for t in tape.time.tolist()]
    for t, p, a in zip(times, tape.pressure.tolist(), tape.accel.tolist()):
        pressure = _num(p, pressure_digits)
        if pressure and float(pressure) <= 0:  # a pressure above 0 that rounds to 0 (0.01 Pa): exactly
            pressure = _exact(p)
        out.append(f"{t},{pressure},{_num(a, accel_digits)}")
    return "\n".join(out) + "\n"


def _exact(v: float) -> str:
    """The shortest text that reads back as `v` exactly ("" for NaN)."""
    return "" if math.isnan(v) else repr(float(v))


def check_tape(tape: Tape) -> None:
    """Raises TapeError when the arrays would not make a valid file (what
    parse_tape refuses): a writer's own check before writing."""
    err = _Errors(tape.path)
    t = tape.time
    if t.size == 0:
        err.at(None, None, "no rows to write")
    elif not (t.shape == tape.pressure.shape == tape.accel.shape):
        err.at(None, None, "the three columns differ in length")
    else:
        if not np.isfinite(t).all():
            err.at(None, None, "a time that is not a finite number")
        elif t.size > 1 and not (np.diff(t) > 0).all():
            i = int(np.argmin(np.diff(t) > 0)) + 1
            err.at(None, None, f"row {i + 1}: time {t[i]:g} s is not after the previous row's {t[i - 1]:g} s")
        for name, v in (("pressure_pa", tape.pressure), ("accel_g", tape.accel)):
            if np.isinf(v).any():
                err.at(None, None, f"{name} holds an infinite value")
        for name, v in (("time_s", t), ("pressure_pa", tape.pressure), ("accel_g", tape.accel)):
            (lo, hi), _unit = RANGES[name]
            with np.errstate(invalid="ignore"):
                beyond = np.isfinite(v) & ((v < lo) | (v > hi))
            for i in np.flatnonzero(beyond).tolist():
                err.at(None, None, f"row {i + 1}: {name} {v[i]:g} {beyond_range(name, float(v[i]))}")
        if not err.items and t.size > 1:
            steps = np.diff(t)
            for i in np.flatnonzero((steps < MIN_STEP_S) | (steps > MAX_STEP_S)).tolist():
                err.at(None, None, f"row {i + 2}: time_s {t[i + 1]:g} is {step_text(steps[i])} s after the "
                                   f"previous row's {t[i]:g} s: {step_problem(float(steps[i]))}")
    for line in tape.sources + tape.derived + tape.notes + (tape.flight,):
        if "\n" in line or "\r" in line:
            err.at(None, None, "a header text holds a line break")
    err.raise_if_any()


def write_tape(path: str, tape: Tape, *, force: bool = False, inputs=()) -> None:
    """Writes `tape` to `path` ("-": standard output) through fswkit.outputs:
    whole or not at all. An existing file is replaced only with `force`
    (OutputError otherwise), never one of `inputs`."""
    from fswkit.outputs import output

    check_tape(tape)
    text = format_tape(tape)
    with output(path, inputs, force=force, ask=True, what="tape") as f:
        f.write(text)


# ---- truth files --------------------------------------------------------------------

TRUTH_FLOATS = (
    "liftoff_s", "accel_over_2g_s", "burnout_s", "max_boost_accel_g", "max_accel_g", "max_accel_s",
    "pad_pressure_pa", "apogee_s", "apogee_m_agl", "apogee_band5m_from_s", "apogee_band5m_to_s",
    "raw_max_alt_m_agl", "landing_s", "landing_alt_m_agl", "log_end_s",
)


ALTITUDE_RANGE_M = (-12_000.0, 12_000.0)  # above the pad: the ISA troposphere the altitudes are worked in is 12 km
# deep (-1 to 11 km ASL)
# A truth file's numbers, by their key's ending (its unit): the range of the tape column each is worked out from
TRUTH_RANGES = {"_m_agl": (ALTITUDE_RANGE_M, "m", "altitude above its pad"),
                "_s": (TIME_RANGE_S, "s", "time from liftoff"),
                "_pa": (PRESSURE_RANGE_PA, "Pa", "pressure"),
                "_g": (ACCEL_RANGE_G, "g", "acceleration")}


@dataclass(frozen=True)
class Truth:
    """A tape's `.truth.toml`: the values computed from the tape (all optional
    but `name`; None when absent), the recording altimeter's own events
    (`recorder_*` keys, as written), and every other key in `extra`."""

    path: str
    name: str
    recorder: str | None = None
    liftoff_s: float | None = None
    accel_over_2g_s: float | None = None
    burnout_s: float | None = None
    max_boost_accel_g: float | None = None
    max_accel_g: float | None = None
    max_accel_s: float | None = None
    pad_pressure_pa: float | None = None
    apogee_s: float | None = None
    apogee_m_agl: float | None = None
    apogee_band5m_from_s: float | None = None
    apogee_band5m_to_s: float | None = None
    raw_max_alt_m_agl: float | None = None
    landing_s: float | None = None
    landing_alt_m_agl: float | None = None
    log_end_s: float | None = None
    recorder_events: dict[str, Any] = field(default_factory=dict)
    extra: dict[str, Any] = field(default_factory=dict)
    lines: dict[str, int] = field(default_factory=dict)  # key -> its line in the file (read_truth's)

    def events(self) -> list[tuple[str, float]]:
        """The event times (keys ending `_s`, recorder's included), earliest first."""
        out = [(k, float(getattr(self, k))) for k in TRUTH_FLOATS
               if k.endswith("_s") and getattr(self, k) is not None]
        out += [(k, float(v)) for k, v in self.recorder_events.items()
                if k.endswith("_s") and "_minus_" not in k and isinstance(v, (int, float))
                and not isinstance(v, bool)]
        return sorted(out, key=lambda kv: kv[1])


def truth_path(tape_path: str) -> str:
    """Where a tape's truth file sits: NAME.csv -> NAME.truth.toml beside it."""
    base = tape_path[:-4] if tape_path.lower().endswith(".csv") else tape_path
    return base + ".truth.toml"


def _key_line(text: str, key: str) -> int | None:
    m = re.search(rf"(?m)^[ \t]*{re.escape(key)}[ \t]*=", text)
    return text.count("\n", 0, m.start()) + 1 if m else None


def read_truth(path: str) -> Truth:
    """Reads a `.truth.toml`; TapeError with a located message when it cannot."""
    data = read_file(path, MAX_INPUT)
    err = _Errors(path)
    text = _text(data, err, "truth") if data else ""
    err.raise_if_any()
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise TapeError([f"{path}:{toml_error_at(e, text)}"]) from None
    except ValueError as e:  # an integer of more digits than Python converts
        raise TapeError([f"{path}: {e}"]) from None
    if not isinstance(doc.get("name"), str) or not doc["name"]:
        err.at(_key_line(text, "name") or 1, 1, "a truth file needs `name = \"...\"` (the tape's name)")
    kw: dict[str, Any] = {}
    for k in TRUTH_FLOATS:
        if k in doc:
            v = doc[k]
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                err.at(_key_line(text, k), 1, f"`{k}` must be a finite number, found {v!r}")
            else:
                kw[k] = float(v)
    for k, v in doc.items():  # every number whose key says its unit, the recorder's own included: a flight's
        if isinstance(v, bool) or not isinstance(v, (int, float)) or k in TRUTH_FLOATS and k not in kw:
            continue
        if not math.isfinite(v):
            err.at(_key_line(text, k), 1, f"`{k}` must be a finite number, found {v!r}")
            continue
        for suffix, ((lo, hi), unit, what) in TRUTH_RANGES.items():
            if k.endswith(suffix) and not lo <= v <= hi:
                err.at(_key_line(text, k), 1, f"`{k}` {v:g} is beyond {lo:,.0f} to {hi:,.0f} {unit}: no "
                                              f"flight's {what} (docs/tapes.md, Ranges): the truth of another "
                                              "tape, or a value in another unit?")
                break
    if "recorder" in doc:
        if not isinstance(doc["recorder"], str):
            err.at(_key_line(text, "recorder"), 1, "`recorder` must be a string")
        else:
            kw["recorder"] = doc["recorder"]
    err.raise_if_any()
    known = set(TRUTH_FLOATS) | {"name", "recorder"}
    recorder = {k: v for k, v in doc.items() if k.startswith("recorder_")}
    extra = {k: v for k, v in doc.items() if k not in known and k not in recorder}
    lines = {k: _key_line(text, k) for k in kw if _key_line(text, k) is not None}
    return Truth(path, doc["name"], recorder_events=recorder, extra=extra, lines=lines, **kw)
