"""Reading recordings of the link: `fsw log2csv`, `fsw replay`, `fsw plot`."""

from __future__ import annotations

import csv
import os
import sys
import time

from fswkit import outputs
from fswkit.link.session import Session

from .monitor import GroundError, summary
from .view import View


# ---- logs --------------------------------------------------------------------------

def _log_session(path: str, ignore_schema: bool):
    from fswkit.link.log import RX, LogReader

    reader = LogReader(path)
    session = Session(reader.layout, ignore_schema=ignore_schema)

    def events():
        for direction, t, data in reader.records():
            if direction == RX:
                for ev in session.feed(data, t):
                    if ev.kind == "hello" and not ev.info["schema_ok"] and not ignore_schema:
                        raise GroundError(
                            f"{path}: the log's hello has schema 0x{ev.info['schema']:08x}, its header "
                            f"0x{reader.layout.schema:08x}: pass --ignore-schema to decode anyway")
                    yield ev
    return reader, session, events()


def log2csv(path: str, out, ignore_schema: bool) -> int:
    reader, session, events = _log_session(path, ignore_schema)
    lay = reader.layout
    names = [e.name for e in lay.elements]
    w = csv.writer(out, lineterminator="\n")
    w.writerow(["seq", "sample", "time", "host_time", "frame"] + names)
    rows = 0
    known = {n: None for n in names}  # the values as of the row being written
    for ev in events:
        if ev.kind == "sample":
            region = lay.streams[ev.stream].region
            for i, (t, vals) in enumerate(ev.samples):
                known.update(zip(region.names, vals))
                w.writerow([ev.seq, i, _num(t), f"{ev.host_time:.6f}", region.name]
                           + [_cell(known[n]) for n in names])
                rows += 1
        elif ev.kind == "snapshot" and ev.info["complete"]:
            known.update(ev.info["values"])
            w.writerow([ev.seq, 0, _num(ev.time), f"{ev.host_time:.6f}", "snapshot"]
                       + [_cell(known[n]) for n in names])
            rows += 1
    if reader.truncated:
        sys.stderr.write(f"fsw log2csv: {path}: the last record is cut short (the recording stopped mid-write)\n")
    sys.stderr.write(f"fsw log2csv: {rows} rows; " + summary(session) + "\n")
    return 0


def _num(t) -> str:
    return str(int(t)) if float(t).is_integer() else repr(float(t))


def _cell(v) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "1" if v else "0"
    if isinstance(v, float):
        return repr(v)
    return str(v)


def replay(path: str, headless: bool, speed: float, ignore_schema: bool) -> int:
    reader, session, events = _log_session(path, ignore_schema)
    view = View(session, headless, f"{reader.layout.name}: replay of {path}")
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


def plot(path: str, elements: list[str], out: str, ignore_schema: bool) -> int:
    fmt = image_format(out)
    outputs.check(out, [path], what="plot")
    reader, session, events = _log_session(path, ignore_schema)
    lay = reader.layout
    missing = [e for e in elements if lay.element(e) is None]
    if missing:
        raise GroundError(f"unknown element(s) {', '.join(missing)}: the log's elements are "
                          + ", ".join(e.name for e in lay.elements))
    series = {e: ([], []) for e in elements}
    s_names = list(lay.states)
    transitions = []  # (time, element, state name)
    last_state = {}
    for ev in events:
        if ev.kind != "sample":
            continue
        region = lay.streams[ev.stream].region
        for t, vals in ev.samples:
            row = dict(zip(region.names, vals))
            for e in elements:
                if e in row:
                    series[e][0].append(t)
                    series[e][1].append(float(row[e]))
            for s in s_names:
                if s in row and last_state.get(s) != row[s]:
                    if s in last_state:
                        transitions.append((t, s, lay.states[s].get(int(row[s]), str(row[s]))))
                    last_state[s] = row[s]
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(elements), 1, sharex=True, figsize=(10, 2.6 * len(elements)), squeeze=False)
    for ax, e in zip(axes[:, 0], elements):
        ts, vs = series[e]
        ax.plot(ts, vs, drawstyle="steps-post" if lay.element(e).type in ("bool", "U8", "U16", "U32") else "default",
                label=e)
        ax.set_ylabel(e)
        for t, s, name in transitions:
            ax.axvline(t, color="tab:red", linestyle="--", linewidth=0.8)
        ax.grid(True, alpha=0.3)
    top = axes[0, 0]
    for t, s, name in transitions:
        top.annotate(name, (t, 1.0), xycoords=("data", "axes fraction"), rotation=90, fontsize=7,
                     va="top", ha="right", color="tab:red")
    axes[-1, 0].set_xlabel(f"target time ({lay.time_unit})")
    fig.suptitle(f"{lay.name}: {path}")
    fig.tight_layout()
    with outputs.output(out, [path], binary=True, what="plot") as f:
        try:
            fig.savefig(f.raw, format=fmt)
        except OSError as e:
            raise GroundError(f"cannot write {out}: {e.strerror or e}") from None
    plt.close(fig)
    sys.stderr.write(f"fsw plot: {out}: {sum(len(v[0]) for v in series.values())} points, "
                     f"{len(transitions)} state transitions\n")
    return 0
