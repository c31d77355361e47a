"""Converters from commercial altimeters' CSV logs to fswkit sensor tapes
(`fsw tape import FORMAT LOG -o TAPE.csv`). Each format below states its
columns, units, time base and liftoff convention, and how it was verified;
docs/tapes.md says the same for users.

Shared rules
    * The log is read as the kit reads every user file (regular files only,
      at most MAX_LOG bytes), UTF-8 text; the column line is the first line
      whose cells (a leading `#` dropped, case and spaces ignored) name the
      format's required columns. Lines before it are the log's preamble;
      after it, blank lines and `#` lines are skipped. Cells are split at
      `,` as CSV does (not inside double quotes; a quoted cell's quotes are
      not part of it); a column line of `;` or tabs is refused, saying so.
    * A cell that is empty or `NaN` in a sensor column is "not available"
      (an empty tape cell); a time that is not a finite number, a sensor cell
      that is not a number, a row too short for the columns used, a row with
      a non-empty cell beyond the columns of the column line, a last line
      cut short (no line end, fewer cells than the column line) are located
      errors `LOG:LINE:COL: message`, as is a log without the format's
      columns (the wrong FORMAT chosen) or a pressure whose unit cannot be
      told from its magnitude.
    * Where the log has no pressure, pressure is made from its altitude AGL
      through the ISA standard atmosphere with the pad at `pad_alt` m ASL
      (0 when not given, said in the header):
      p = 101325 * (1 - (pad_alt + h) / 44330.77)^(1 / 0.190263) Pa. Altitudes
      above the pad come back exactly (H(p) - H(p_pad) = h); only the absolute
      level depends on `pad_alt`.
    * Acceleration is axial, in g, +1 at rest on the pad.
    * Rows keep the log's own times (no resampling), strictly increasing:
      rows whose time is not after the previous kept row are dropped (the
      header counts them).
    * Liftoff: the log's own time origin where the recorder counts from its
      liftoff detection (AltOS, CATS, Eggtimer); otherwise it is defined here
      from the data (Raven, RRC3) by one of two rules, said in the header:
      ACCEL: the first sample above 2 g that stays above 2 g for 0.1 s (the
      rule of ../shared/flights' truth files); BARO: the last sample within
      1 m of the pad before the first sample that is 10 m above the pad and
      stays above it for 0.5 s (the pad being the median pressure altitude of
      the log's first second, of its samples before the rise).

Formats
    altos     AltOS (TeleMega, TeleMetrum, EasyMega...) CSV export.
    cats      CATS flight computer: the filtered-data export
              (ts, filtered_altitude_AGL, filtered_acceleration) or a Vega
              barometer log (ts, id, T, P).
    raven     Featherweight Raven, FIP CSV export (per-channel time columns).
    eggtimer  Eggtimer flight data download (T, Alt, Veloc, FAlt, ...).
    rrc3      Missile Works RRC3, mDACS CSV export (time, altitude, pressure, ...).
Each converter's docstring says what it reads and how it was verified.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Callable

import numpy as np

from fswkit.tape.tape import (MAX_ERRORS, MAX_STEP_S, MIN_STEP_S, RANGES, Tape, TapeError, _Errors, _text,
                              beyond_range, isa_altitude, isa_pressure, number, read_file, split_lines, step_problem,
                              step_text)

MAX_LOG = 256 << 20  # bytes of a log read: an AltOS export with GPS columns runs ~3 MB a flight
G0 = 9.80665  # m/s^2, AltOS's standard gravity
G_CATS = 9.81  # m/s^2, the GRAVITY constant CATS subtracts
FT = 0.3048  # m


class Rows:
    """A log's data rows as (line number, cells), kept as their lines and
    split when a row is asked for: split up front, with a str a cell, a
    long log took about 25 times its size in memory (a 65 MB AltOS export
    1 GB)."""

    def __init__(self, lines: list[tuple[int, str]]):
        self._lines = lines

    def __len__(self) -> int:
        return len(self._lines)

    def __getitem__(self, i: int) -> tuple[int, list[str]]:
        ln, line = self._lines[i]
        return ln, _split(line)

    def __iter__(self):
        for ln, line in self._lines:
            yield ln, _split(line)

    def where(self, keep: Callable[[list[str]], bool]) -> "Rows":
        """The rows whose cells `keep` takes, as Rows."""
        return Rows([(ln, line) for ln, line in self._lines if keep(_split(line))])

    def lines(self) -> np.ndarray:
        """The rows' line numbers in the log (1-based), as an int array."""
        return np.fromiter((ln for ln, _ in self._lines), dtype=np.int64, count=len(self._lines))

    def line_text(self, ln: int) -> str:
        """The text of the row at log line `ln` (one of these rows)."""
        i = int(np.searchsorted(self.lines(), ln))
        return self._lines[i][1]

    def take(self, indices) -> "Rows":
        """The rows at `indices` (in that order), as Rows."""
        return Rows([self._lines[i] for i in indices])


@dataclass
class Log:
    """A CSV log: its column names (normalised: lower case, spaces kept
    single, a leading `#` dropped), the 1-based line of the column line, and
    its data rows as (line number, cells)."""

    path: str
    fmt: str
    names: list[str]
    raw_names: list[str]
    column_line: int
    rows: Rows

    def index(self, *aliases: str) -> int | None:
        """The first column named one of `aliases` (normalised), or None."""
        for a in aliases:
            a = _norm(a)
            if a in self.names:
                return self.names.index(a)
        return None

    def err(self) -> _Errors:
        return _Errors(self.path)

    def numbers(self, col: int, what: str, *, required: bool = False, rows=None) -> np.ndarray:
        """Column `col` as float64 (NaN for an empty or `NaN` cell); TapeError
        for a cell that is not a number, a row too short, or (`required`) a
        missing value."""
        err = self.err()
        rows = self.rows if rows is None else rows
        out = np.empty(len(rows))
        for i, (ln, cells) in enumerate(rows):
            if col >= len(cells):
                err.at(ln, None, f"the row has {len(cells)} cells: no `{self.raw_names[col]}` "
                                 f"(column {col + 1} of the column line at line {self.column_line})")
                out[i] = math.nan
                continue
            s = _unquote(cells[col])
            if s == "" or s.lower() == "nan":
                if required:
                    err.at(ln, _col_of(cells, col), f"{what} (`{self.raw_names[col]}`) is empty: "
                                                    "every row needs it" if s == "" else
                                                    f"{what} (`{self.raw_names[col]}`): `{s}` is not a finite number")
                out[i] = math.nan
                continue
            v = number(s)
            if v is None:
                v = math.nan
                comma = " (a decimal comma: save the log with `.` as the decimal point)" \
                    if "," in s and number(s.replace(",", ".")) is not None else ""
                err.at(ln, _col_of(cells, col), f"{what} (`{self.raw_names[col]}`): `{s[:40]}` is not "
                                                f"a finite number{comma}")
            out[i] = v
        err.raise_if_any()
        return out


def _norm(name: str) -> str:
    return " ".join(_unquote(_unquote(name).lstrip("#")).lower().split())


def _unquote(cell: str) -> str:
    """A cell's text as CSV reads it: spaces around it dropped, and the
    quotes around a quoted cell (`"1.5"`, `"ts"`; `""` inside is one `"`)."""
    s = cell.strip()
    if len(s) >= 2 and s[0] == '"' and s[-1] == '"':
        s = s[1:-1].replace('""', '"').strip()
    return s


def _split(line: str, sep: str = ",") -> list[str]:
    """A line's cells as written (quotes and spaces kept, so a cell's column
    is where its text starts): split at `sep` outside double quotes, as CSV
    does (a spreadsheet quotes a cell holding a comma)."""
    if '"' not in line:
        return line.split(sep)
    cells, start, quoted = [], 0, False
    for i, ch in enumerate(line):
        if ch == '"':
            quoted = not quoted
        elif ch == sep and not quoted:
            cells.append(line[start:i])
            start = i + 1
    cells.append(line[start:])
    return cells


def _col_of(cells: list[str], k: int) -> int:
    """The 1-based column of cell `k`'s first character that is not a space."""
    cell = cells[k] if k < len(cells) else ""
    return sum(len(c) + 1 for c in cells[:k]) + 1 + len(cell) - len(cell.lstrip())


def read_log(path: str, fmt: str, wanted: Callable[[list[str]], bool], expected: str, *,
             wider_rows: bool = False) -> Log:
    """Reads a CSV log; its column line is the first line for which
    `wanted(normalised names)` holds. TapeError (located) otherwise, and
    for a row with a non-empty cell beyond the columns the column line
    names, unless `wider_rows` (a recorder whose own writer writes rows
    wider than its column line, after the columns used)."""
    data = read_file(path, MAX_LOG)
    err = _Errors(path)
    text = _text(data, err, "log")
    del data  # (a long log: the bytes, the text and the lines are not all kept at once)
    err.raise_if_any()
    lines = split_lines(text)  # LF, CRLF or CR alone
    del text
    header = None
    for n, line in enumerate(lines):
        line = line.rstrip("\r")
        if "," not in line:
            continue
        names = [_norm(c) for c in _split(line)]
        if wanted(names):
            header = n
            break
    if header is None:
        for n, line in enumerate(lines):  # a spreadsheet's CSV of another separator: said, not guessed
            for sep, said in ((";", "`;`"), ("\t", "tabs")):
                if sep in line and wanted([_norm(c) for c in _split(line.rstrip("\r"), sep)]):
                    raise TapeError([f"{path}:{n + 1}:1: not a {FORMATS[fmt].title} log as fswkit reads one: "
                                     f"its column line separates its cells with {said} (as a spreadsheet saves "
                                     "CSV where the decimal mark is a comma): save the log as CSV with `,` "
                                     "between cells and `.` as the decimal point"])
        first = next((l.strip() for l in lines if l.strip()), "")
        raise TapeError([f"{path}:1:1: not a {FORMATS[fmt].title} log: no line names its columns "
                         f"({expected}); the first line is `{first[:80]}`"])
    raw = [_unquote(_unquote(c).lstrip("#")) for c in _split(lines[header].rstrip("\r"))]
    rows = []
    cells: list[str] = []
    for n in range(header + 1, len(lines)):
        line = lines[n].rstrip("\r")
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        cells = _split(line)
        rows.append((n + 1, line))
        if len(cells) > len(raw) and not wider_rows:  # read by position, cells would land in wrong columns
            extra = next((k for k in range(len(raw), len(cells)) if cells[k].strip()), None)
            if extra is not None:  # empty cells beyond the columns (a spreadsheet's `,,,`) are harmless
                err.at(n + 1, _col_of(cells, extra), f"the row has {len(cells)} cells, the column line (line "
                       f"{header + 1}) names {len(raw)}: `{_unquote(cells[extra])[:40]}` lies beyond its columns "
                       "(a decimal comma, or a comma in a cell not quoted, shifts the cells): save the log with "
                       "`.` as the decimal point and one cell a column")
    last = lines[-1].rstrip("\r")
    if rows and rows[-1][0] == len(lines) and len(cells) < len(raw):  # (cells: the last row's)
        # no line end, cells missing: a log cut short, whose last cell may be a number cut short too
        err.at(len(lines), len(last) + 1, f"the log ends inside a row: its last line has {len(cells)} cells "
               f"of the column line's {len(raw)} and no line end (a download cut short?): complete the row or "
               "delete it")
    err.raise_if_any()
    if not rows:
        raise TapeError([f"{path}:{header + 1}: no data rows after the column line"])
    return Log(path, fmt, [_norm(c) for c in raw], raw, header + 1, Rows(rows))


# ---- helpers shared by the converters ---------------------------------------------------

def _increasing(t: np.ndarray) -> np.ndarray:
    """A mask keeping the rows whose time is after the previous kept row's."""
    keep = np.zeros(t.size, dtype=bool)
    last = -math.inf
    for i, v in enumerate(t.tolist()):
        if v > last:
            keep[i] = True
            last = v
    return keep


def _from_liftoff(t: np.ndarray, t_lift: float) -> tuple[np.ndarray, np.ndarray]:
    """The times counted from liftoff, and a mask of the rows kept: two log
    times closer than binary64 tells apart at the shifted magnitude (0 and
    1e-320, liftoff at 1 s) become one time, and the later row is dropped
    as a row whose time is not after the previous one."""
    shifted = t - t_lift
    kept = _increasing(shifted)
    return shifted[kept], kept


def _pressure_pa(p: np.ndarray, log: Log, col: int, rows=None) -> tuple[np.ndarray, str]:
    """A pressure column in Pa, its unit told from its magnitude: Pa (median
    10,000 to 120,000) or hPa = mbar (100 to 1,200); TapeError otherwise.
    `p` holds one value per row of `rows` (the log's rows when None)."""
    have = p[~np.isnan(p)]
    if have.size == 0:
        raise TapeError([f"{log.path}:{log.column_line}:{_col_of(log.raw_names, col)}: "
                         f"`{log.raw_names[col]}` holds no value"])
    med = float(np.median(have))
    if 10_000 <= med <= 120_000:
        return _positive(p, log, col, "Pa", rows), "Pa"
    if 100 <= med <= 1_200:
        with np.errstate(over="ignore"):  # a cell beyond binary64 once scaled: refused below, located
            return _positive(p * 100.0, log, col, "hPa", rows), "hPa (mbar)"
    raise TapeError([f"{log.path}:{log.column_line}:{_col_of(log.raw_names, col)}: cannot tell the unit of "
                     f"`{log.raw_names[col]}`: its median {med:g} is neither Pa (10,000 to 120,000) nor "
                     "hPa/mbar (100 to 1,200)"])


def _positive(p: np.ndarray, log: Log, col: int, unit: str, rows=None) -> np.ndarray:
    """`p` (Pa, one value per row of `rows`, the log's rows when None) when every value is a pressure
    within the tape's range (fswkit.tape.PRESSURE_RANGE_PA); otherwise TapeError at each cell that is
    not: a glitch row of a sensor (0, negative), a cell in another unit, is the log's cell to locate,
    not a tape the writer refuses later without a line."""
    _check_cells(p, log, col, "pressure_pa", log.raw_names[col], rows, unit=unit)
    return p


def _check_cells(v: np.ndarray, log: Log, col: int, column: str, what: str, rows=None, unit: str = "") -> None:
    """TapeError at each cell of log column `col` whose value `v` (in the
    unit of tape column `column`, one a row of `rows`, the log's rows when
    None; NaN for an empty cell) is beyond that column's range
    (fswkit.tape.RANGES): the cell, the value it makes, the range, what to
    do. `unit`, a unit the cells were read in and scaled from ("hPa"), is
    said with a value it makes."""
    (lo, hi), _u = RANGES[column]
    with np.errstate(invalid="ignore"):
        bad = np.flatnonzero(~np.isnan(v) & ~((v >= lo) & (v <= hi)))
    if bad.size == 0:
        return
    err = log.err()
    rows = log.rows if rows is None else rows
    err.hidden += max(0, bad.size - MAX_ERRORS)  # counted, not split (a whole column in a wrong unit)
    for i in bad[:MAX_ERRORS].tolist():
        ln, cells = rows[i]
        cell = _unquote(cells[col])[:40]
        x = float(v[i])
        read = f" read as {unit}" if unit and unit != _u else ""
        if not math.isfinite(x):
            why = f"{read} is beyond the largest number once in {_u}"
        else:
            made = "" if number(cell) == x else f"{read} makes {column} {x:g}, which"
            why = f"{made} {beyond_range(column, x)}"
        err.at(ln, _col_of(cells, col), f"{what} (`{log.raw_names[col]}`): `{cell}`{why}")
    err.raise_if_any()


def _check_steps(t: np.ndarray, log: Log, lines: np.ndarray, cols, whats) -> None:
    """TapeError at each row of the tape to be written whose time `t` (s,
    strictly increasing) lies closer to or further from the previous row's
    than a recorder's (fswkit.tape.MIN_STEP_S, MAX_STEP_S): located at the
    row's time cell in the log (its line in `lines`; its column `cols`, one
    or one a row, named by `whats[col]`)."""
    if t.size < 2:
        return
    steps = np.diff(t)
    bad = np.flatnonzero((steps < MIN_STEP_S) | (steps > MAX_STEP_S)).tolist()
    if not bad:
        return
    err = log.err()
    err.hidden += max(0, len(bad) - MAX_ERRORS)
    for i in bad[:MAX_ERRORS]:
        ln = int(lines[i + 1])
        col = int(cols if np.isscalar(cols) else cols[i + 1])
        cells = _split(log.rows.line_text(ln))
        err.at(ln, _col_of(cells, col), f"{whats[col]} (`{log.raw_names[col]}`): `{_unquote(cells[col])[:40]}` is "
                                        f"{step_text(float(steps[i]))} s after the previous row's (line "
                                        f"{int(lines[i])}): {step_problem(float(steps[i]))}")
    err.raise_if_any()


def _liftoff_accel(t: np.ndarray, a: np.ndarray) -> float | None:
    """ACCEL rule: the first sample above 2 g that stays above 2 g for 0.1 s."""
    ok = ~np.isnan(a)
    t, a = t[ok], a[ok]
    above = a > 2.0
    for i in np.flatnonzero(above):
        j = np.searchsorted(t, t[i] + 0.1, side="right")
        if above[i:j].all() and t[j - 1] >= t[i] + 0.1 - 1e-9:
            return float(t[i])
    return None


def _liftoff_baro(t: np.ndarray, h: np.ndarray) -> float | None:
    """BARO rule on altitude `h` (m, any origin): the last sample within 1 m
    of the pad before the first sample 10 m above the pad that stays above
    it for 0.5 s; the pad = median altitude of the log's first second, of the
    samples before the rise (the first sample 10 m above the log's first
    sample for 0.5 s)."""
    ok = ~np.isnan(h)
    t, h = t[ok], h[ok]
    if t.size == 0:
        return None

    def rise(base: float) -> int | None:
        up = h - base > 10.0
        for i in np.flatnonzero(up):
            j = np.searchsorted(t, t[i] + 0.5, side="right")
            if up[i:j].all() and t[j - 1] >= t[i] + 0.5 - 1e-9:
                return int(i)
        return None

    i0 = rise(float(h[0]))  # the rise seen from the first sample: the pad is what comes before it
    if i0 is None:
        return None
    pre = (t <= t[0] + 1.0) & (np.arange(t.size) < i0)
    pad = float(np.median(h[pre])) if pre.any() else float(h[0])
    i = rise(pad)
    if i is None:
        return None
    near = np.flatnonzero(np.abs(h[:i] - pad) <= 1.0)
    return float(t[near[-1]]) if near.size else float(t[0])


def _source(path: str, fmt: str) -> str:
    return f"{os.path.basename(path)} (imported with `fsw tape import {fmt}`; licence as its owner states)"


def _pad_text(pad_alt: float | None) -> str:
    return f"{pad_alt:g} m ASL (given)" if pad_alt is not None else "0 m ASL assumed (no --pad-alt given)"


def _from_altitude(h_agl: np.ndarray, pad_alt: float | None, what: str) -> tuple[np.ndarray, str]:
    pad = 0.0 if pad_alt is None else pad_alt
    p = isa_pressure(pad + h_agl)
    p0 = float(isa_pressure(pad))
    return p, (f"pressure_pa = from {what} through the ISA standard atmosphere with the pad at "
               f"{_pad_text(pad_alt)}, P0 = {p0:.1f} Pa: p = 101325*(1-({pad:g}+h)/44330.77)^(1/0.190263); "
               "absolute level set by the pad altitude")


def _dropped(n: int) -> list[str]:
    return [f"rows dropped: {n} with a time not after the previous row"] if n else []


def _check_altitude_range(h: np.ndarray, pad_alt: float | None, log: Log, col: int, unit: str, rows=None) -> None:
    """An altitude column (m above the pad, one value per row of `rows`, the
    log's rows when None) has values, each within the ISA troposphere;
    TapeError otherwise, at each cell beyond it (a wrong unit, a wrong
    --pad-alt, a glitch row)."""
    if np.isnan(h).all():
        raise TapeError([f"{log.path}:{log.column_line}:{_col_of(log.raw_names, col)}: "
                         f"`{log.raw_names[col]}` holds no value"])
    pad = pad_alt or 0.0
    asl = h + pad
    bad = np.flatnonzero(~np.isnan(asl) & ((asl >= 11_000) | (asl < -1_000)))
    if bad.size == 0:
        return
    err = log.err()
    name = log.raw_names[col]
    rows = log.rows if rows is None else rows
    err.hidden += max(0, bad.size - MAX_ERRORS)  # counted, not split (a whole log in the wrong unit)
    for i in bad[:MAX_ERRORS].tolist():
        ln, cells = rows[i]
        err.at(ln, _col_of(cells, col), f"{name} (`{name}`): `{_unquote(cells[col])[:40]}` is {asl[i]:.0f} m ASL "
                                        f"(read as {unit}, the pad at {pad:g} m ASL): beyond the ISA troposphere "
                                        "the tapes use (-1 to 11 km); check the unit and --pad-alt")
    err.raise_if_any()


# ---- AltOS ------------------------------------------------------------------------

def altos(path: str, pad_alt: float | None = None) -> Tape:
    """AltOS CSV export (AltosUI "Export data", TeleMega, TeleMetrum,
    EasyMega, EasyMini...).

    Columns used: `time` (s since AltOS's boost detection: 0 = its liftoff,
    negative on the pad; kept as is), `pressure` (Pa in the exports of
    current AltOS, hPa/mbar in old versions: told by magnitude),
    `acceleration` (axial, m/s^2, with the 1 g rest reading removed: 0 on
    the pad; accel_g = acceleration / 9.80665 + 1). The column line may start
    with `#`; `altitude` names two columns (barometric, then GPS): the first
    is used. AltOS writes a row for every GPS or state record carrying the
    last sensor values: rows that repeat the previous kept row's sensor
    values (acceleration, pressure, altitude, height, speed) exactly are
    dropped, like rows whose time is not after the previous one.
    `--pad-alt` is not used (the log has pressure).

    Verified: the column names and their order against AltosCSV.java
    (altoslib, `write_general_header` ... `write_basic_header`); units and the
    time origin against the two AltOS logs of ../shared/flights (Prometheus,
    TeleMega and TeleMetrum), whose conversion this reproduces row by row."""
    # AltosCSV.java writes 9 values (accel, gyro, mag) under the 6 names of its advanced header: a
    # TeleMega's rows are wider than its column line, after the basic columns this reads
    log = read_log(path, "altos", lambda n: "time" in n and "pressure" in n and
                   ("version" in n or "state_name" in n or "acceleration" in n),
                   "time, pressure, acceleration, with version or state_name", wider_rows=True)
    it, ip, ia = log.index("time"), log.index("pressure"), log.index("acceleration")
    t = log.numbers(it, "time", required=True)
    _check_cells(t, log, it, "time_s", "time")
    p_raw = log.numbers(ip, "pressure")
    a = log.numbers(ia, "acceleration") if ia is not None else np.full(t.size, math.nan)
    if ia is not None:
        _check_cells(a / G0 + 1.0, log, ia, "accel_g", "acceleration")
    sensor_cols = [c for c in (ia, ip, log.index("altitude"), log.index("height"),
                               log.index("speed", "accel_speed"), log.index("baro_speed")) if c is not None]
    sensors = [log.numbers(c, log.raw_names[c]) for c in sensor_cols]
    keep = np.zeros(t.size, dtype=bool)
    last_t, last = -math.inf, None
    late = repeat = 0
    for i in range(t.size):
        if not t[i] > last_t:
            late += 1
            continue
        row = tuple(s[i] for s in sensors)
        if last is not None and all((x == y) or (math.isnan(x) and math.isnan(y)) for x, y in zip(row, last)):
            repeat += 1
            continue
        keep[i] = True
        last_t, last = t[i], row
    p, unit = _pressure_pa(p_raw, log, ip)
    _check_steps(t[keep], log, log.rows.lines()[keep], it, {it: "time"})
    t, p, a = t[keep], p[keep], a[keep]
    accel = a / G0 + 1.0
    flight = "recorder AltOS"
    isr, ifl = log.index("serial"), log.index("flight")
    cells = log.rows[0][1]
    if isr is not None and ifl is not None and max(isr, ifl) < len(cells):
        flight += f" serial {_unquote(cells[isr])} flight {_unquote(cells[ifl])}"
    derived = ["time_s = log column 'time' as is (AltOS: seconds since its boost detection, so 0 = AltOS liftoff)",
               f"pressure_pa = log column 'pressure' ({unit})" + (" * 100" if unit != "Pa" else " as is"),
               "accel_g = log column 'acceleration' / 9.80665 + 1 (AltOS reports axial acceleration in m/s^2 "
               "with the +1 g rest reading removed)" if ia is not None else
               "accel_g empty: the log has no 'acceleration' column"]
    if late or repeat:
        derived.append(f"rows dropped: {late} with a time not after the previous row, {repeat} that repeat the "
                       "previous row's sensor values exactly (AltOS writes a row for each GPS or state record)")
    return Tape(path, t, p, accel, (_source(path, "altos"),), flight, tuple(derived))


# ---- CATS ------------------------------------------------------------------------

def cats(path: str, pad_alt: float | None = None) -> Tape:
    """CATS flight computer (CATS Vega) logs, one of two layouts, told by
    their columns:

    filtered-data export `ts, filtered_altitude_AGL, filtered_acceleration`:
        `ts` s from CATS's liftoff detection (kept as is);
        `filtered_altitude_AGL` m above the pad, median-filtered by the
        recorder (pressure made through ISA with the pad at --pad-alt);
        `filtered_acceleration` m/s^2 axial, CATS's GRAVITY = 9.81 removed
        (accel_g = value / 9.81 + 1). Once its state machine reaches DROGUE,
        CATS writes exactly 0.0 instead of a measurement: a final run of
        exact zeros after liftoff becomes empty cells.
    barometer log `ts, id, T, P` (the Vega's baro.csv): `P` in Pa as is (hPa
        told by magnitude), the rows of the first row's sensor id only, read
        on their own (their times, unit and cells; another sensor's rows do
        not count); no
        acceleration (the IMU log is a separate file whose rocket axis depends
        on mounting: not read here).

    Verified: layouts and units against the five CATS logs of
    ../shared/flights (Camoes, Genesis, Lince, Halcyon filtered exports;
    Hedy baro.csv), whose conversions this reproduces; the zero-after-DROGUE
    rule as those tapes' headers state it (cats-embedded task_state_est.cpp).
    No CATS documentation was found with the search tool."""
    log = read_log(path, "cats", lambda n: "ts" in n and ("filtered_altitude_agl" in n or "p" in n),
                   "ts with filtered_altitude_AGL, or ts, id, T, P")
    ih = log.index("filtered_altitude_agl")
    if ih is not None:
        its = log.index("ts")
        t = log.numbers(its, "ts", required=True)
        _check_cells(t, log, its, "time_s", "ts")
        keep = _increasing(t)
        late = int((~keep).sum())
        h = log.numbers(ih, "filtered_altitude_AGL")
        _check_altitude_range(h, pad_alt, log, ih, "m AGL")
        ia = log.index("filtered_acceleration")
        a = log.numbers(ia, "filtered_acceleration") if ia is not None else np.full(t.size, math.nan)
        if ia is not None:
            _check_cells(a / G_CATS + 1.0, log, ia, "accel_g", "filtered_acceleration")
        _check_steps(t[keep], log, log.rows.lines()[keep], its, {its: "ts"})
        t, h, a = t[keep], h[keep], a[keep]
        p, how = _from_altitude(h, pad_alt, "'filtered_altitude_AGL' (m, CATS's median-filtered barometric "
                                            "altitude; not the raw sensor)")
        accel = a / G_CATS + 1.0
        derived = ["time_s = log column 'ts' as is (CATS: seconds from its liftoff detection)", how]
        if ia is None:
            derived.append("accel_g empty: the log has no 'filtered_acceleration' column")
        else:
            derived.append("accel_g = 'filtered_acceleration' / 9.81 + 1 (CATS logs median-filtered axial "
                           "acceleration in m/s^2 minus its GRAVITY = 9.81)")
            nz = np.flatnonzero(a != 0.0)
            start = int(nz[-1]) + 1 if nz.size else 0
            if start < a.size - 1 and t[start] > 0:
                accel[start:] = math.nan
                derived.append(f"accel_g left empty from t = {t[start]:g} s on: from there to the end the log "
                               "holds exactly 0.0, which CATS writes instead of a measurement once its state "
                               "machine reaches DROGUE")
        layout = "filtered-data export"
    else:
        # the first sensor's rows, read on their own: another sensor's rows (their times, units,
        # cells) neither drop nor scale nor refuse them
        ip, iid = log.index("p"), log.index("id")
        rows = log.rows
        first = ""
        if iid is not None:
            err = log.err()
            for ln, c in rows:
                if iid >= len(c):
                    err.at(ln, None, f"the row has {len(c)} cells: no `{log.raw_names[iid]}` (column {iid + 1} "
                                     f"of the column line at line {log.column_line})")
            err.raise_if_any()
            first = _unquote(rows[0][1][iid])
            rows = rows.where(lambda c: _unquote(c[iid]) == first)
        its = log.index("ts")
        t = log.numbers(its, "ts", required=True, rows=rows)
        _check_cells(t, log, its, "time_s", "ts", rows)
        keep = _increasing(t)
        late = int((~keep).sum())
        p, unit = _pressure_pa(log.numbers(ip, "P", rows=rows), log, ip, rows)
        _check_steps(t[keep], log, rows.lines()[keep], its, {its: "ts"})
        t, p = t[keep], p[keep]
        accel = np.full(t.size, math.nan)
        derived = ["time_s = log column 'ts' as is (CATS: seconds from its liftoff detection)",
                   f"pressure_pa = log column 'P' ({unit})" + (" * 100" if unit != "Pa" else " as is")
                   + (f", sensor {first} only" if first else ""),
                   "accel_g empty: a CATS barometer log holds no acceleration"]
        layout = "barometer log"
    derived += _dropped(late)
    flight = f"recorder CATS flight computer ({layout}); pad elevation {_pad_text(pad_alt)}" \
        if layout == "filtered-data export" else f"recorder CATS flight computer ({layout})"
    return Tape(path, t, p, accel, (_source(path, "cats"),), flight, tuple(derived))


# ---- Featherweight Raven ---------------------------------------------------------------

def raven(path: str, pad_alt: float | None = None) -> Tape:
    """Featherweight Raven, CSV export of the Featherweight Interface Program
    (FIP). Each channel comes as its own time column followed by its value
    columns (`Time-Axial Accel (Gs), Axial Accel (Gs), bILBA, Time (s),
    Altitude (Ft-AGL), bILBA`), channels at their own rates and lengths (a
    channel ends where its time cells end).

    Used: `Axial Accel (Gs)` (g, +1 at rest: as is) and `Altitude (Ft-AGL)`
    (ft above the pad: pressure through ISA with the pad at --pad-alt). Time:
    the Raven's seconds from power-up/recording start; liftoff is defined by
    the ACCEL rule (BARO without an accelerometer channel) and subtracted.
    Rows follow the accelerometer's clock while it lasts, holding the last
    altitude sample (sample-and-hold; empty before the first), then the
    altitude's clock.

    Verified: the layout, units and merge against the NDRT 2020 Raven log of
    ../shared/flights (RocketPy's ndrt_2020_flight_data.csv), whose
    conversion this reproduces. The Raven user's manual was found (search
    corpus pages) but not its export's column list: other FIP channels
    (pressure, temperature, voltages) are not read."""
    log = read_log(path, "raven", lambda n: any(c.startswith("time") for c in n)
                   and ("axial accel (gs)" in n or "altitude (ft-agl)" in n),
                   "Time..., Axial Accel (Gs) and/or Altitude (Ft-AGL)")

    def channel(col: int, what: str) -> tuple[np.ndarray, np.ndarray, Rows, int]:
        tcol = max(i for i in range(col) if log.names[i].startswith("time")) if any(
            log.names[i].startswith("time") for i in range(col)) else None
        if tcol is None:
            raise TapeError([f"{log.path}:{log.column_line}:{_col_of(log.raw_names, col)}: "
                             f"`{log.raw_names[col]}` has no time column before it"])
        rows = log.rows.where(lambda c: tcol < len(c) and bool(_unquote(c[tcol])))
        t = log.numbers(tcol, f"{what} time", required=True, rows=rows)  # `NaN` refused, as every log's time
        v = log.numbers(col, what, rows=rows)
        ok = ~np.isnan(v)
        t, v = t[ok], v[ok]
        if what == "Axial Accel":
            _check_cells(v, log, col, "accel_g", what, rows.take(np.flatnonzero(ok).tolist()))
        keep = _increasing(t)
        late[0] += int((~keep).sum())
        taken = rows.take(np.flatnonzero(ok)[keep].tolist())
        _check_steps(t[keep], log, taken.lines(), tcol, {tcol: f"{what} time"})  # a clock that jumped
        spans.append((t, rows.take(np.flatnonzero(ok).tolist()), tcol, f"{what} time"))
        return t[keep], v[keep], taken, tcol

    late = [0]
    spans = []  # each channel's times (all of them), rows, time column and its name: in range once liftoff is known

    ia, ih = log.index("axial accel (gs)"), log.index("altitude (ft-agl)")
    ta, a, a_rows, a_tcol = channel(ia, "Axial Accel") if ia is not None else (np.empty(0), np.empty(0), None, 0)
    th, h, h_rows, h_tcol = channel(ih, "Altitude") if ih is not None else (np.empty(0), np.empty(0), None, 0)
    if th.size:
        _check_altitude_range(h * FT, pad_alt, log, ih, "ft AGL", h_rows)
    t_lift = _liftoff_accel(ta, a) if ta.size else None
    rule = "ACCEL: first 'Axial Accel (Gs)' sample above 2 g that stays above 2 g for 0.1 s"
    if t_lift is None and th.size:
        t_lift = _liftoff_baro(th, h * FT)
        rule = "BARO: last altitude sample within 1 m of the pad before it is 10 m above for 0.5 s"
    if t_lift is None:
        raise TapeError([f"{log.path}: no liftoff found: no accel sample above 2 g for 0.1 s and no "
                         "altitude 10 m above the pad for 0.5 s"])
    for tt, rr, tcol, what in spans:
        _check_cells(tt - t_lift, log, tcol, "time_s", what, rr)
    # rows: the accel clock while it lasts, then the altitude clock
    t = np.concatenate([ta, th[th > ta[-1]]]) if ta.size else th
    later = th > ta[-1] if ta.size else np.ones(th.size, dtype=bool)
    lines = np.concatenate([a_rows.lines() if ta.size else np.empty(0, np.int64), h_rows.lines()[later]
                            if th.size else np.empty(0, np.int64)])
    cols = np.concatenate([np.full(ta.size, a_tcol), np.full(int(later.sum()), h_tcol)])
    accel = np.concatenate([a, np.full(t.size - ta.size, math.nan)])
    if th.size:
        k = np.searchsorted(th, t, side="right") - 1
        hh = np.where(k >= 0, h[np.maximum(k, 0)], math.nan)
        p, how = _from_altitude(hh * FT, pad_alt, "'Altitude (Ft-AGL)' * 0.3048")
    else:
        p, how = np.full(t.size, math.nan), "pressure_pa empty: the log has no 'Altitude (Ft-AGL)' values"
    derived = [f"liftoff defined here by the {rule}: Raven time {t_lift:.5f} s; time_s = Raven time - {t_lift:.5f}",
               f"accel_g = 'Axial Accel (Gs)' as is (g, +1 at rest); {ta.size} samples to {ta[-1]:.3f} s Raven "
               "time, empty after" if ta.size else "accel_g empty: the log has no 'Axial Accel (Gs)' channel",
               how]
    if ta.size and th.size:
        derived.append("merged onto the accel clock while it lasts, holding the last altitude sample "
                       "(sample-and-hold; empty before the first altitude sample); after the accel data end, "
                       "rows follow the altitude clock")
    t, kept = _from_liftoff(t, t_lift)
    names = {**({a_tcol: "Axial Accel time"} if ta.size else {}), **({h_tcol: "Altitude time"} if th.size else {})}
    _check_steps(t, log, lines[kept], cols[kept], names)
    p, accel = p[kept], accel[kept]
    derived += _dropped(late[0] + int((~kept).sum()))
    flight = f"recorder Featherweight Raven (FIP export); pad elevation {_pad_text(pad_alt)}"
    return Tape(path, t, p, accel, (_source(path, "raven"),), flight, tuple(derived))


# ---- Eggtimer ---------------------------------------------------------------------

def eggtimer(path: str, pad_alt: float | None = None, alt_unit: str = "ft") -> Tape:
    """Eggtimer (TRS, Quantum, Proton...) flight data download:
    `T,Alt,Veloc,FAlt,FVeloc,FVeloc2,LDA,LowV,Apogee,N-O,Drogue,Main`.

    Used: `T` (ms from the Eggtimer's flight start: 0 at liftoff, the row
    where the recorder's launch detect fired carrying its altitude in `LDA`;
    time_s = T / 1000, kept as is) and `Alt` (above the pad, the raw
    barometric altitude, in `alt_unit`: ft, the recorder's default, or m;
    `FAlt` is the recorder's filtered one and is not used): pressure
    through ISA with the pad at --pad-alt. No acceleration
    (the Eggtimer logs none).

    Verified: column names, units (ms, ft, ft/s) and the time origin against
    the Eggtimer TRS user's manual's example download (its page 35, found
    with the search tool); no Eggtimer log was available to convert, so the
    Quantum's and Proton's layouts are assumed the same where they name
    these columns (the manual of those was not found)."""
    log = read_log(path, "eggtimer", lambda n: "t" in n and "alt" in n, "T, Alt (Eggtimer)")
    it, ih = log.index("t"), log.index("alt")
    t = log.numbers(it, "T", required=True) / 1000.0
    _check_cells(t, log, it, "time_s", "T")
    scale, what = _alt_unit(alt_unit)
    h = log.numbers(ih, "Alt") * scale
    keep = _increasing(t)
    _check_altitude_range(h, pad_alt, log, ih, f"{alt_unit} AGL")
    _check_steps(t[keep], log, log.rows.lines()[keep], it, {it: "T"})
    t, h = t[keep], h[keep]
    p, how = _from_altitude(h, pad_alt, f"'Alt' {what}")
    derived = ["time_s = log column 'T' / 1000 (Eggtimer: ms from its flight start, 0 = liftoff)", how,
               "accel_g empty: an Eggtimer logs no acceleration"] + _dropped(int((~keep).sum()))
    flight = f"recorder Eggtimer; pad elevation {_pad_text(pad_alt)}"
    return Tape(path, t, p, np.full(t.size, math.nan), (_source(path, "eggtimer"),), flight, tuple(derived))


# ---- Missile Works RRC3 --------------------------------------------------------------

def rrc3(path: str, pad_alt: float | None = None, alt_unit: str = "ft") -> Tape:
    """Missile Works RRC3, CSV export of mDACS:
    `time,altitude,pressure,velocity,temperature,events,voltages`.

    Used: `time` (s from the start of the recording, 20 Hz), `pressure`
    (hPa = mbar; Pa told by magnitude) and, only where `pressure` is absent,
    `altitude` (AGL, in `alt_unit`: ft, mDACS's default unit, or m; pressure
    through ISA with the pad at --pad-alt). Liftoff is defined by the BARO rule on the pressure
    altitude and subtracted. No acceleration (the RRC3 logs none); the
    `events` column (the RRC3's Drogue/Main events) is not read.

    Verified: column names, pressure in hPa and altitude in ft against the
    Juno III RRC3 log in RocketPy (data/rockets/juno3/cots_altimeter.csv:
    861.7 hPa on the pad; 10,700 ft at the 3,213 m apogee its flight card
    gives), and the column list against a public reader of mDACS exports
    (NUSTARS launch-vehicle rrc3py: Time, Altitude, Pressure, Velocity,
    Temperature, Events, Voltages). No mDACS documentation was found with
    the search tool: the time origin of `time` (recording start, not
    liftoff) is what the Juno III log shows (rest at 0 s)."""
    log = read_log(path, "rrc3", lambda n: "time" in n and ("pressure" in n or "altitude" in n)
                   and ("velocity" in n or "events" in n), "time, altitude, pressure, velocity, events")
    it, ip, ih = log.index("time"), log.index("pressure"), log.index("altitude")
    t = t_all = log.numbers(it, "time", required=True)
    keep = _increasing(t)
    _check_steps(t[keep], log, log.rows.lines()[keep], it, {it: "time"})  # a clock that jumped: before its liftoff
    if ip is not None:
        p, unit = _pressure_pa(log.numbers(ip, "pressure"), log, ip)
        t, p = t[keep], p[keep]
        how = f"pressure_pa = log column 'pressure' ({unit})" + (" * 100" if unit != "Pa" else " as is")
        h = isa_altitude(p)
    else:
        scale, what = _alt_unit(alt_unit)
        h = log.numbers(ih, "altitude") * scale
        _check_altitude_range(h, pad_alt, log, ih, f"{alt_unit} AGL")
        t, h = t[keep], h[keep]
        p, how = _from_altitude(h, pad_alt, f"'altitude' {what}")
    t_lift = _liftoff_baro(t, h)
    if t_lift is None:
        raise TapeError([f"{log.path}: no liftoff found: the altitude is never 10 m above the pad for 0.5 s"])
    _check_cells(t_all - t_lift, log, it, "time_s", "time")  # (its steps are checked before the liftoff)
    t, kept = _from_liftoff(t, t_lift)
    _check_steps(t, log, log.rows.lines()[keep][kept], it, {it: "time"})
    p = p[kept]
    derived = ["liftoff defined here by the BARO rule: the last sample within 1 m of the pad (median pressure "
               "altitude of the log's first second before the rise) before the altitude is 10 m above it for "
               "0.5 s: RRC3 time "
               f"{t_lift:g} s; time_s = RRC3 time - {t_lift:g}", how,
               "accel_g empty: an RRC3 logs no acceleration"] + _dropped(int((~keep).sum()) + int((~kept).sum()))
    flight = "recorder Missile Works RRC3 (mDACS export)"
    if ip is None:
        flight += f"; pad elevation {_pad_text(pad_alt)}"
    return Tape(path, t, p, np.full(t.size, math.nan), (_source(path, "rrc3"),), flight, tuple(derived))


def _alt_unit(unit: str) -> tuple[float, str]:
    """An altitude column's unit (`ft` or `m`, `--alt-unit`): (metres per
    unit, how the tape's header says it)."""
    return (FT, "(ft AGL) * 0.3048") if unit == "ft" else (1.0, "(m AGL)")


@dataclass(frozen=True)
class Format:
    name: str
    title: str
    convert: Callable[..., Tape]
    alt_unit: bool = False  # its log's altitude has no unit of its own: `--alt-unit` (ft, or m)


FORMATS: dict[str, Format] = {
    "altos": Format("altos", "AltOS CSV export", altos),
    "cats": Format("cats", "CATS flight computer", cats),
    "raven": Format("raven", "Featherweight Raven (FIP export)", raven),
    "eggtimer": Format("eggtimer", "Eggtimer", eggtimer, alt_unit=True),
    "rrc3": Format("rrc3", "Missile Works RRC3 (mDACS export)", rrc3, alt_unit=True),
}


def convert(fmt: str, path: str, pad_alt: float | None = None, alt_unit: str | None = None) -> Tape:
    """The tape of the log at `path` in format `fmt` (a key of FORMATS);
    `alt_unit` (`ft`, the default, or `m`) for a format whose altitude has
    no unit of its own (Format.alt_unit). TapeError with located messages
    when it cannot be read."""
    if pad_alt is not None and not (-500.0 <= pad_alt <= 9_000.0):
        raise TapeError([f"--pad-alt {pad_alt:g}: expected a pad elevation from -500 to 9,000 m ASL"])
    f = FORMATS[fmt]
    if alt_unit is not None and not f.alt_unit:
        raise ValueError(f"{fmt} logs say their altitude's unit")  # the command line refuses it first
    tape = f.convert(path, pad_alt, alt_unit or "ft") if f.alt_unit else f.convert(path, pad_alt)
    if tape.rows == 0:
        raise TapeError([f"{path}: no rows left to write"])
    return tape
