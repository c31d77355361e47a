"""Reading recordings of the link, link logs and sessions of a ground
station's archive alike: `fsw log2csv`, `fsw replay`, `fsw plot`, `fsw
archive export`."""

from __future__ import annotations

import csv
import heapq
import math
import os
import sys
import time
from dataclasses import dataclass

from fswkit import outputs
from fswkit.link.session import Session
from fswkit.usage import UsageError, unknown_name

from .monitor import GroundError, summary
from .view import View, spark_elements


# ---- logs --------------------------------------------------------------------------

def _log_session(path: str, ignore_schema: bool, session: int | None = None):
    """A recording's reader, its decoding session and its events: a link
    log, or a session of a station's archive (`session`; None: the newest)."""
    from fswkit.link.log import RX, LogReader

    from .archive import ArchiveError, ArchiveReader, is_archive

    if is_archive(path):
        try:
            reader = ArchiveReader(path, session)
        except ArchiveError as e:
            raise GroundError(str(e)) from None
    elif session is not None and outputs.recording(path) == "a link log":  # else: said as the file it is
        raise GroundError(f"{path}: --session {session}: this is a link log, one recording; --session "
                          "chooses a session of a ground station's archive")
    else:
        reader = LogReader(path)
    decoder = Session(reader.layout, ignore_schema=ignore_schema)

    def events():
        for direction, t, data in reader.records():
            if direction == RX:
                for ev in decoder.feed(data, t):
                    if ev.kind == "hello" and not ev.info["schema_ok"] and not ignore_schema:
                        raise GroundError(
                            f"{path}: the log's hello has schema 0x{ev.info['schema']:08x}, its header "
                            f"0x{reader.layout.schema:08x}: pass --ignore-schema to decode anyway")
                    yield ev
    return reader, decoder, events()


def said_incomplete(command: str, reader) -> None:
    """Says, once a recording is read, that it ended before its end (a log
    cut short or damaged, a session never ended), as its reader words it."""
    if reader.incomplete:
        sys.stderr.write(f"fsw {command}: {reader.path}: {reader.incomplete}\n")


def log2csv(path: str, out, ignore_schema: bool, session: int | None = None) -> int:
    reader, session, events = _log_session(path, ignore_schema, session)
    columns, rows = table(reader.layout, events)
    n, boots = write_csv(out, reader.layout, columns, rows)
    said_incomplete("log2csv", reader)
    restarts = f" from {boots} boots of the target (column `{BOOT}`)" if boots > 1 else ""
    sys.stderr.write(f"fsw log2csv: {n} rows{restarts}; " + summary(session) + "\n")
    return 0


def write_csv(out, layout, columns, rows) -> tuple[int, int]:
    """`table`'s rows as CSV text: (rows written, the last row's boot)."""
    decimals = 3 if layout.time_unit == "ms" else 6  # whole target times print exactly
    w = csv.writer(out, lineterminator="\n")
    w.writerow(columns)
    n = boots = 0
    for row in rows:
        w.writerow([_seconds(row[0], decimals), f"{row[1]:.6f}", row[2], row[3]] + [_cell(v) for v in row[4:]])
        n += 1
        boots = row[2]
    return n, boots


def _seconds(v: float, decimals: int) -> str:
    """Seconds with the decimals of the target's unit (`1.250`), or all the
    digits a time between two whole units needs (a batch period of 12.5 ms)."""
    text = f"{v:.{decimals}f}"
    return text if float(text) == v else repr(v)


def _cell(v) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "1" if v else "0"
    if isinstance(v, float):
        return repr(v)
    return str(v)


# ---- the table: the rows of `fsw log2csv` (and of an archive's export) ----------------
#
# Element names are identifiers ([A-Za-z_][A-Za-z0-9_]*, unique in a state
# vector), so an element's columns are `name`, `name [unit]` or `name name`
# (a state element's state name). The fixed columns are two words each, the
# second never `name`: no element, whatever it is called, can take one.

TIME, HOST_TIME, BOOT, FRAME = "target time [s]", "host time [s]", "target boot", "from frame"
SNAPSHOT = "(snapshot)"  # the `from frame` of a whole state vector read back (a region may be named `snapshot`)
_LATE_S = 2.0  # seconds a frame may arrive behind the newest sample before it, beyond its own batching


def element_unit(layout, name: str) -> str | None:
    """The unit of an element's values where the layout knows one: volts for
    an analog channel without a calibration (an input read as volts, an
    output's duty given in volts). A calibrated input is in the engineering
    unit its `scale=` and `offset=` make, which the configs do not name."""
    cal = layout.analog.get(name)
    if cal is not None and cal.get("scale") == 1 and cal.get("offset") == 0:
        return "V"
    return None


def table_columns(layout) -> list[str]:
    """The columns of `table`: target time and host time in seconds, the
    target's boot (1, then one more after each reset the log shows), the
    frame the row comes from, then every element in state vector order
    (with its unit where the layout knows one), a state element followed by
    the name of its state."""
    cols = [TIME, HOST_TIME, BOOT, FRAME]
    for e in layout.elements:
        unit = element_unit(layout, e.name)
        cols.append(f"{e.name} [{unit}]" if unit else e.name)
        if e.name in layout.states:
            cols.append(f"{e.name} name")
    return cols


def table(layout, events):
    """(columns, rows) of a decoded recording (fswkit.link.session events):
    one row per sample (a frame that batches k samples gives k rows) and per
    whole snapshot, in target-time order within each boot of the target,
    rows of one time in the order they arrived. A row is a tuple: target
    time (s, float), host time when its frame arrived (s since the epoch,
    float), boot (int), its frame (the stream's region, or SNAPSHOT), then
    each element's value as of that row (None until one was decoded in this
    boot; bool, int or float) and for a state element its state's name (None
    for an id without one). Rows are made as they are read: the table holds
    a few seconds of them, never the recording."""
    return table_columns(layout), _rows(layout, updates(layout, events))


def updates(layout, events):
    """(boot, target time, host time, frame, names, values) of every sample
    and whole snapshot, in target-time order within a boot (stable).

    Streams interleave and a batch frame carries samples up to its batch's
    span before the frame was sent, so a sample arrives at most that span
    behind the newest one seen (plus _LATE_S of slack for a busy link): rows
    wait in a heap until no later frame can come before them. Time going
    back further is a target reset: a hello or health frame (stamped when
    sent, so never before a sample sent ahead of it) earlier than the newest
    sample, or (both lost) a sample earlier than the newest by more than
    that span. Either starts the next boot, after every row of this one."""
    per_second = 1000 if layout.time_unit == "ms" else 1_000_000
    span = max([(s.batch - 1) * s.period for s in layout.streams], default=0)
    horizon = span + _LATE_S * per_second
    heap: list = []  # (time, arrival: ties keep the order of arrival, the update)
    arrival = 0
    boot = 1
    newest = None  # the newest target time of this boot

    def drain():
        while heap:
            yield heapq.heappop(heap)[2]

    for ev in events:
        if ev.kind == "sample":
            region = layout.streams[ev.stream].region
            items = [(t, region.name, region.names, vals) for t, vals in ev.samples]
        elif ev.kind == "snapshot" and ev.info["complete"]:
            vals = ev.info["values"]
            items = [(ev.time, SNAPSHOT, tuple(vals), tuple(vals.values()))]
        else:
            if ev.kind in ("hello", "health") and newest is not None and ev.time < newest:
                yield from drain()
                boot, newest = boot + 1, None
            continue
        for t, frame, names, vals in items:
            if newest is not None and t < newest - horizon:
                yield from drain()
                boot, newest = boot + 1, None
            heapq.heappush(heap, (t, arrival, (boot, t, ev.host_time, frame, names, vals)))
            arrival += 1
            if newest is None or t > newest:
                newest = t
        while heap and heap[0][0] < newest - horizon:
            yield heapq.heappop(heap)[2]
    yield from drain()


def _rows(layout, ordered):
    per_second = 1000 if layout.time_unit == "ms" else 1_000_000
    cols = [(e.name, layout.states.get(e.name)) for e in layout.elements]
    known: dict = {}
    this_boot = None
    for boot, t, host_time, frame, names, vals in ordered:
        if boot != this_boot:  # a reset target starts from a zeroed state vector: nothing carries over
            known = {}
            this_boot = boot
        known.update(zip(names, vals))
        row = [t / per_second, host_time, boot, frame]
        for name, states in cols:
            v = known.get(name)
            row.append(v)
            if states is not None:
                row.append(None if v is None else states.get(int(v)))
        yield tuple(row)


def replay(path: str, headless: bool, speed: float, ignore_schema: bool, session: int | None = None,
           spark=()) -> int:
    reader, session, events = _log_session(path, ignore_schema, session)
    spark = spark_elements(reader.layout, spark, "the log's")  # the names checked against the log's elements
    view = View(session, headless, f"{reader.layout.name}: replay of {path}", spark=spark)
    first_host = first_wall = None
    with view:
        for ev in events:
            if speed > 0:
                if first_host is None:
                    first_host, first_wall = ev.host_time, time.monotonic()
                wait = (ev.host_time - first_host) / speed - (time.monotonic() - first_wall)
                if wait > 0:
                    time.sleep(min(wait, 3600.0))
            view.event(ev)
            view.update(ev.host_time)
    said_incomplete("replay", reader)
    sys.stderr.write(summary(session) + "\n")
    return 0


def image_format(out: str) -> str:
    """The image format an output's extension names, checked before any work
    (matplotlib would write `out.png` for `out`, and refuses `.txt` only once
    the figure is drawn)."""
    try:
        import matplotlib
    except ImportError:
        raise GroundError("matplotlib is not installed: run `make setup` (or pip install matplotlib)") from None
    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    known = Figure().canvas.get_supported_filetypes()
    ext = os.path.splitext(out)[1][1:].lower()
    if ext not in known:
        what = f"`.{ext}` is not an image format it writes" if ext else "it has no extension to say the image format"
        raise GroundError(f"-o {out}: {what}: name it .png, .svg or .pdf (or "
                          + ", ".join(f".{e}" for e in sorted(known) if e not in ("png", "svg", "pdf")) + ")")
    return ext


def plot(path: str, elements: list[str], out: str, ignore_schema: bool, session: int | None = None, *,
         force: bool = False) -> int:
    fmt = image_format(out)
    outputs.check(out, [path], force=force, ask=True, what="plot")
    elements = list(dict.fromkeys(elements))  # one panel each: `-e x x` drew (and took the time of) two
    reader, session, events = _log_session(path, ignore_schema, session)
    lay = reader.layout
    missing = [e for e in elements if lay.element(e) is None]
    if missing:
        raise UsageError("-e: " + unknown_name("element", missing, [e.name for e in lay.elements], "the log's"))
    data = plot_data(lay, events, elements)
    said_incomplete("plot", reader)
    fig, unlabelled = figure(lay, data, elements, f"{lay.name}: {path}")
    with outputs.output(out, [path], binary=True, force=force, ask=True, what="plot") as f:
        try:
            fig.savefig(f.raw, format=fmt)
        except OSError as e:
            raise GroundError(f"cannot write {out}: {e.strerror or e}") from None
    more = []
    if data.resets:
        more.append(f"{len(data.resets) + 1} boots of the target, end to end")
    if unlabelled:
        more.append(f"{unlabelled} state names left out (too close together to write)")
    sys.stderr.write(f"fsw plot: {out}: {data.points} points, {len(data.transitions)} state transitions"
                     + "".join(f"; {m}" for m in more) + "\n")
    return 0


_LABEL_ROWS = 6  # rows of state names above the panels at most; a name that fits in none is counted, not drawn


@dataclass
class PlotData:
    """What `fsw plot` draws, x in seconds of target time: each boot of the
    target after a reset placed after the previous one."""
    series: dict  # element -> (x, values, boots)
    transitions: list  # (x, state element, its new state's name)
    resets: list  # x where a boot after a reset begins
    ends: dict  # boot -> its last x
    span: tuple | None  # (first x, last x) of the whole recording
    points: int


def plot_data(layout, events, elements: list[str]) -> PlotData:
    per_second = 1000 if layout.time_unit == "ms" else 1_000_000
    gap = max([s.period for s in layout.streams], default=0) / per_second  # between two boots
    series = {e: ([], [], []) for e in elements}
    transitions, resets, ends = [], [], {}
    last_state: dict = {}
    offset, boot, first = 0.0, None, None
    for b, t, _host, _frame, names, vals in updates(layout, events):
        if b != boot:
            if boot is not None:  # the next boot starts after the last one, a gap apart
                offset = ends[boot] + gap - t / per_second
                resets.append(ends[boot] + gap)
                last_state = {}
            boot = b
        x = t / per_second + offset
        first = x if first is None else first
        ends[b] = x
        row = dict(zip(names, vals))
        for e in elements:
            if e in row:
                xs, vs, bs = series[e]
                xs.append(x)
                vs.append(row[e])
                bs.append(b)
        for s, ids in layout.states.items():
            v = row.get(s)
            if v is not None and last_state.get(s) != v:
                if s in last_state:
                    transitions.append((x, s, ids.get(int(v), str(v))))
                last_state[s] = v
    span = (first, ends[boot]) if boot is not None else None
    return PlotData(series, transitions, resets, ends, span, sum(len(v[0]) for v in series.values()))


def _true_spans(xs, vs, bs, ends) -> list[tuple[float, float]]:
    """(start, width) of the stretches where a bool is true: from a true
    sample to the next sample of its boot (or its boot's end)."""
    spans: list[list[float]] = []
    for i, v in enumerate(vs):
        if not v:
            continue
        end = xs[i + 1] if i + 1 < len(xs) and bs[i + 1] == bs[i] else ends[bs[i]]
        if spans and spans[-1][1] == xs[i]:
            spans[-1][1] = end
        else:
            spans.append([xs[i], end])
    return [(a, b - a) for a, b in spans]


def axis_label(layout, name: str) -> str:
    """An element's axis: its name and unit, or what its values mean (a
    state element's ticks are its states' names)."""
    unit = element_unit(layout, name)
    if unit:
        return f"{name} [{unit}]"
    if layout.element(name).type == "bool":
        return f"{name}\n(shaded: true)"
    return name


def figure(layout, data: PlotData, elements: list[str], title: str):
    """The matplotlib Figure of `fsw plot`: one panel per element against
    target time in seconds (a bool shaded where true, a state element with
    its states' names), each state transition a dashed line through them,
    the new state's name above in rows laid out so no two names overlap,
    and resets dotted. Returns (the figure, how many names there was no
    room for)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    n = len(elements)
    fig = Figure(figsize=(10, 1.2 + 2.2 * n))
    FigureCanvasAgg(fig)
    strip, *panels = fig.subplots(n + 1, 1, sharex=True, gridspec_kw={"height_ratios": [0.3] + [2.2] * n})
    colors = {s: f"C{1 + i % 9}" for i, s in enumerate(layout.states)}
    for ax, e in zip(panels, elements):
        xs, vs, bs = data.series[e]
        el = layout.element(e)
        if not xs:
            ax.text(0.5, 0.5, f"no sample of {e} in this recording", transform=ax.transAxes, ha="center",
                    va="center", color="0.4")
        elif el.type == "bool":
            ax.broken_barh(_true_spans(xs, vs, bs, data.ends), (0, 1), facecolor="C0", alpha=0.45)
            ax.set_ylim(0, 1)
            ax.set_yticks([])
        else:
            x, y = [], []
            for i, (xi, v, b) in enumerate(zip(xs, vs, bs)):
                if i and b != bs[i - 1]:  # no line across a reset
                    x.append(math.nan)
                    y.append(math.nan)
                x.append(xi)
                y.append(float(v))
            stepped = not el.type.startswith("F")
            ax.plot(x, y, drawstyle="steps-post" if stepped else "default", color="C0", linewidth=1.0)
            if e in layout.states:
                ids = sorted({int(v) for v in vs})
                ax.set_yticks(ids, [layout.states[e].get(i, str(i)) for i in ids], fontsize=7)
        ax.set_ylabel(axis_label(layout, e))
        ax.grid(True, alpha=0.3)
    for ax in [strip, *panels]:
        for x, s, _name in data.transitions:
            ax.axvline(x, color=colors[s], linestyle="--", linewidth=0.7, alpha=0.6, zorder=0)
        for x in data.resets:
            ax.axvline(x, color="black", linestyle=":", linewidth=1.2)
    if data.span is not None:
        a, b = data.span
        pad = max(b - a, 1.0) * 0.01
        strip.set_xlim(a - pad, b + pad)
    xlabel = "target time [s]"
    if data.resets:
        xlabel += " (after a reset, dotted, the next boot follows the last)"
    panels[-1].set_xlabel(xlabel)
    strip.set_yticks([])
    strip.tick_params(axis="x", bottom=False)
    for side in ("left", "right", "top"):
        strip.spines[side].set_visible(False)
    fig.suptitle(title)
    labels = [(x, name if len(layout.states) == 1 else f"{s}: {name}", colors[s]) for x, s, name in data.transitions]
    labels += [(x, f"reset: boot {k + 2}", "black") for k, x in enumerate(data.resets)]
    labels.sort(key=lambda item: item[0])
    texts = [(strip.text(x, 0.5, text, color=color, fontsize=8, ha="left", va="center", gid="state-label",
                         clip_on=False), x) for x, text, color in labels]
    return fig, _lay_out_labels(fig, strip, texts, n)


def _lay_out_labels(fig, strip, texts, n: int) -> int:
    """Rows for the state names (each name right of its line, or left of it
    at the right edge, in the first row with room), the strip as tall as
    the rows, checked on the final layout; the number of names left out."""
    if not texts:
        strip.axis("off")

    def fit(rows: int, hidden: int) -> None:
        strip.set_ylim(max(rows, 1), 0)
        strip.set_title(f"{hidden} more state names: too close together to write" if hidden else "", loc="right",
                        fontsize=7)

    rows, hidden = 1, 0
    for _ in range(4):  # a relayout moves the axes by a pixel at most: settled in one or two rounds
        fit(rows, hidden)
        height = 0.22 * max(rows, 1)
        strip.get_gridspec().set_height_ratios([height] + [2.2] * n)
        fig.set_size_inches(10, 1.2 + height + 2.2 * n)
        fig.tight_layout()
        placed = _rows_for(strip, texts, fig.canvas.get_renderer())
        if placed == (rows, hidden):
            return hidden
        rows, hidden = placed
    fit(rows, hidden)  # not settled: the last placement stands, on the layout it was made for
    return hidden


def _rows_for(strip, texts, renderer, pad: float = 3.0, gap: float = 6.0) -> tuple[int, int]:
    """Places each text (sorted by x) in the first row where it overlaps
    nothing (in pixels); returns (rows used, texts left out)."""
    right_edges: list[float] = []  # per row, the rightmost pixel taken
    hidden = 0
    to_data = strip.transData.inverted()
    for text, x in texts:
        text.set_visible(True)  # a hidden text measures as an empty box
        width = text.get_window_extent(renderer).width
        px = strip.transData.transform((x, 0))[0]
        left = px + pad if px + pad + width <= strip.bbox.x1 else px - pad - width
        row = next((r for r, edge in enumerate(right_edges) if left >= edge + gap), None)
        if row is None and len(right_edges) < _LABEL_ROWS:
            row = len(right_edges)
            right_edges.append(-math.inf)
        if row is None:
            text.set_visible(False)
            hidden += 1
            continue
        right_edges[row] = max(right_edges[row], left + width)
        text.set_position((to_data.transform((left, 0))[0], row + 0.5))
    return len(right_edges), hidden


# ---- an archive's session exported (`fsw archive export`) --------------------------

_EXPORT_FORMATS = {".csv": "CSV", ".parquet": "Parquet"}
_BATCH = 65536  # rows per Parquet row group: the export holds one at a time


def _arrow_types(layout, columns: list[str]) -> list:
    """Each column's Arrow type, in the order of fswkit.ground.logs.table:
    target time, host time, boot, frame, then each element by its type and
    a state element's state name (None for each — pyarrow infers them — if
    the table's columns are not those)."""
    import pyarrow as pa

    by_type = {"bool": pa.bool_(), "F32": pa.float32(), "F64": pa.float64(), "U64": pa.uint64()}
    types = [pa.float64(), pa.float64(), pa.int64(), pa.string()]
    for e in layout.elements:
        types.append(by_type.get(e.type, pa.int64()))
        if e.name in layout.states:
            types.append(pa.string())
    return types if len(types) == len(columns) else [None] * len(columns)


def export(path: str, out: str, *, session: int | None, t_from: float | None, t_to: float | None,
            force: bool, ignore_schema: bool) -> tuple[int, int]:
    """A session of an archive as CSV (the text of `fsw log2csv`) or Parquet,
    by `out`'s extension: the rows of fswkit.ground.logs.table, decoded
    again from the archived bytes, those whose host time is `t_from` to
    `t_to` seconds after the session began. (rows written, session)."""
    from .archive import ArchiveError, is_archive

    ext = os.path.splitext(out)[1].lower()
    if ext not in _EXPORT_FORMATS:
        what = f"`{ext}` is not a format it writes" if ext else "it has no extension to say the format"
        raise ArchiveError(f"-o {out}: {what}: name it .csv or .parquet")
    if t_from is not None and t_to is not None and t_from > t_to:
        raise ArchiveError(f"--from {t_from:g} is after --to {t_to:g}: nothing to export")
    if os.path.isdir(path) or not is_archive(path):
        why = "it is a folder" if os.path.isdir(path) else (
            "no such file" if not os.path.exists(path) else "not an fswkit archive (`fsw log2csv` reads a link log)")
        raise ArchiveError(f"{path}: {why}")
    what = _EXPORT_FORMATS[ext]
    outputs.check(out, [path], force=force, ask=True, what=what)
    if ext == ".parquet":
        try:
            import pyarrow  # noqa: F401  (checked before the work)
        except ImportError:
            raise ArchiveError("pyarrow is not installed (it writes Parquet): run `make setup` "
                               "(or pip install pyarrow)") from None
    reader, _decoder, events = _log_session(path, ignore_schema, session)
    columns, rows = table(reader.layout, events)
    columns = list(columns)
    at = columns.index(HOST_TIME)
    started = reader.header["started"]
    lo = -math.inf if t_from is None else started + t_from
    hi = math.inf if t_to is None else started + t_to
    chosen = (row for row in rows if lo <= row[at] <= hi)

    n = 0
    if ext == ".csv":
        with outputs.output(out, [path], newline="", force=force, ask=True, what=what) as f:
            n = write_csv(f, reader.layout, columns, chosen)[0]
        said_incomplete("archive export", reader)
        return n, reader.session
    import pyarrow as pa
    import pyarrow.parquet as pq

    types = _arrow_types(reader.layout, columns)
    with outputs.output(out, [path], binary=True, force=force, ask=True, what=what) as f:
        writer = None
        batch: list = []

        def flush():
            nonlocal writer
            t = pa.table({c: pa.array([r[i] for r in batch], type=types[i]) for i, c in enumerate(columns)})
            if writer is None:
                writer = pq.ParquetWriter(f.raw, t.schema)
            writer.write_table(t)
            batch.clear()

        try:
            for row in chosen:
                batch.append(row)
                n += 1
                if len(batch) == _BATCH:
                    flush()
            if batch or writer is None:
                flush()
            writer.close()
        except OSError as e:
            raise ArchiveError(f"cannot write {out}: {e.strerror or e}") from None
        except (pa.ArrowInvalid, pa.ArrowTypeError, OverflowError) as e:
            raise ArchiveError(f"{path}: a value does not fit its Parquet column: {e}") from None
    said_incomplete("archive export", reader)
    return n, reader.session
