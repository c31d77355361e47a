"""`fsw monitor`, `fsw replay`, `fsw log2csv`, `fsw plot`, `fsw cmd`: the
ground station of the serial link. Every one of them decodes through
fswkit.link (one decoder); the live view uses rich."""

from __future__ import annotations

import csv
import os
import sys
import time

from fswkit import outputs
from fswkit.link import wire
from fswkit.link.layout import Layout
from fswkit.link.session import Event, Session, describe
from fswkit.web.source import reset_words


class GroundError(Exception):
    """A user-facing failure: message printed, non-zero exit."""


def schema_message(session: Session, project: str) -> str:
    h = session.hello
    return (f"schema mismatch: the target's firmware has schema 0x{h['schema']:08x} (protocol {h['protocol']}), "
            f"but the configs of {project} give 0x{session.layout.schema:08x} (protocol {wire.PROTOCOL}).\n"
            "  The firmware was built from other configs: build and flash it again from these, "
            "or pass --ignore-schema to decode anyway.")


def summary(session: Session) -> str:
    st, ws = session.stats, session.deframer.stats
    h = session.health or {}
    return (f"link: {st.frames} frames, {ws.bytes} bytes, {st.lost} lost in {st.gaps} gaps, "
            f"{ws.crc_errors} CRC errors, {ws.framing_errors} framing errors, {ws.oversized} oversized, "
            f"{ws.invalid} invalid, target dropped {h.get('dropped', '?')}")


# ---- the live view ---------------------------------------------------------------------

def render(session: Session, now: float, title: str):
    from rich.console import Group
    from rich.table import Table

    lay = session.layout
    t = Table(title=title, expand=False)
    t.add_column("element")
    t.add_column("type")
    t.add_column("value", justify="right")
    t.add_column("detail")
    for e in lay.elements:
        v = session.values.get(e.name)
        detail = ""
        cal = lay.analog.get(e.name)
        if cal is not None and isinstance(v, float) and cal["scale"]:
            volts = (v - cal["offset"]) / cal["scale"]
            detail = f"pin {cal['pin']}: {volts:.3f} V  (= V×{cal['scale']:g} {cal['offset']:+g})"
        elif e.name in lay.states:
            detail = "state"
        elif e.name in lay.writable:
            detail = "writable"
        t.add_row(e.name, e.type, lay.show(e.name, v), detail)
    st, ws = session.stats, session.deframer.stats
    link = Table(title="link", show_header=False)
    link.add_column("k")
    link.add_column("v", justify="right")
    lat = f"{session.latency * 1000:.1f} ms" if session.latency is not None else "—"
    schema = ("ok" if session.schema_ok else "MISMATCH") if session.hello else "waiting for hello"
    for k, v in (("schema", schema), ("frames/s", f"{session.frames_per_second(now):.1f}"),
                 ("frames", st.frames), ("lost (sequence gaps)", f"{st.lost} in {st.gaps}"),
                 ("CRC errors", ws.crc_errors), ("framing errors", ws.framing_errors),
                 ("oversized (no delimiter)", ws.oversized),
                 ("latency (above least)", lat)):
        link.add_row(k, str(v))
    h = session.health
    if h is not None:
        link.add_row("target dropped", str(h["dropped"]))
        link.add_row("executor late cycles", str(h["late"]))
        link.add_row("reset cause", f"{reset_words(h['reset_cause'])} (0x{h['reset_cause']:02x})")
        link.add_row("uplink ok/refused", f"{h['rx_ok']}/{h['rx_refused']}")
        link.add_row("uplink crc/malformed/replayed",
                     f"{h['rx_crc']}/{h['rx_malformed']}/{h['rx_replayed']}")
        tasks = Table(title="tasks")
        for c in ("task", "kind", "mode", "overruns", "worst µs", "faults"):
            tasks.add_column(c)
        for x in h["tasks"]:
            tasks.add_row(x["name"], x["kind"], x["mode_name"], str(x["overruns"]), str(x["worst_us"]),
                          str(x["faults"]))
        return Group(t, link, tasks)
    return Group(t, link)


class View:
    """Headless lines or the live rich view, fed events."""

    def __init__(self, session: Session, headless: bool, title: str, out=None):
        self.session = session
        self.headless = headless
        self.title = title
        self.out = out or outputs.stdout()
        self._live = None
        self._last = 0.0

    def __enter__(self):
        if not self.headless:
            from rich.console import Console
            from rich.live import Live

            # the live view writes through the same stream: a full terminal or pipe
            # is an output error, not the port going away
            self._live = Live(render(self.session, time.time(), self.title), refresh_per_second=8,
                              screen=False, auto_refresh=False, console=Console(file=self.out))
            self._live.__enter__()
        return self

    def __exit__(self, *exc):
        if self._live is not None:
            self.update(force=True)
            self._live.__exit__(*exc)
        return False

    def event(self, ev: Event) -> None:
        if self.headless:
            self.out.write(describe(ev, self.session.layout) + "\n")
            self.out.flush()

    def update(self, now: float | None = None, force: bool = False) -> None:
        if self._live is None:
            return
        now = time.time() if now is None else now
        if force or now - self._last >= 0.12:
            self._last = now
            self._live.update(render(self.session, now, self.title), refresh=True)


# ---- fsw monitor -----------------------------------------------------------------

def monitor(layout: Layout, project: str, port_name: str, baud: int, log_path: str | None, headless: bool,
            ignore_schema: bool, duration: float | None, max_frames: int | None, force: bool = False) -> int:
    from fswkit.link.client import Ground, LinkTimeout
    from fswkit.link.log import LogError, LogWriter
    from fswkit.link.port import open_port, port_errors

    session = Session(layout, ignore_schema=ignore_schema)
    # the log is checked first and takes its name only once the target is known
    # to be the right one: a refused session leaves an old recording as it was
    log = LogWriter(log_path, layout, force=force, port=port_name, project=project) if log_path else None
    try:
        port = open_port(port_name, baud)
    except BaseException:
        if log is not None:
            log.close(keep=False)
        raise
    ground = Ground(port, session, log)
    refused = False
    verified = False  # the target answered as the right one: the log may replace what was there
    view = View(session, headless, f"{layout.name} on {port_name}")
    start = time.monotonic()
    status = 0
    try:
        with outputs.stopped_by_signals(), view:
            try:
                ground.handshake(timeout=3.0 if layout.has_uplink else 12.0, on_event=view.event)
            except LinkTimeout as e:
                if not ignore_schema:
                    raise GroundError(f"{e}: is the firmware running on {port_name}, at {baud} baud? "
                                      "(--ignore-schema decodes without one)\n  " + summary(session)) from None
            if session.hello is not None and not session.hello["schema_ok"] and not ignore_schema:
                raise GroundError(schema_message(session, project))
            verified = True
            if log is not None:
                log.commit()
            if layout.has_uplink:
                try:
                    ground.command(wire.OP_SNAPSHOT, timeout=1.0, on_event=view.event)
                except LinkTimeout:
                    pass
            while True:
                for ev in ground.read():
                    view.event(ev)
                    if ev.kind == "hello" and not ev.info["schema_ok"] and not ignore_schema:
                        raise GroundError(schema_message(session, project))
                view.update()
                if duration is not None and time.monotonic() - start >= duration:
                    break
                if max_frames is not None and session.stats.frames >= max_frames:
                    break
    except KeyboardInterrupt as e:  # Ctrl-C: 0; SIGTERM, SIGHUP: 128 + the signal
        status = 128 + e.signum if isinstance(e, outputs.Stopped) else 0
    except BrokenPipeError:  # our standard output was closed (`| head`)
        status = 0
    except GroundError:
        refused = True
        raise
    except (LogError, outputs.OutputError) as e:  # a full disk is not the port's fault
        sys.stderr.write(f"fsw monitor: {e}\n")
        if isinstance(e, outputs.OutputError):
            outputs.discard_stdout()
        status = 1
    except port_errors() as e:
        sys.stderr.write(f"fsw monitor: {port_name}: the port went away ({e})\n")
        status = 1
    finally:
        if log is not None:  # stopped before the target answered: what was at the path stays
            log.close(keep=not refused and (verified or not os.path.lexists(log_path)))
        try:
            port.close()
        except Exception:  # noqa: BLE001 - closing a port that went away
            pass
    sys.stderr.write(summary(session) + "\n")
    return status


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


# ---- fsw cmd -------------------------------------------------------------------------

def command(layout: Layout, project: str, port_name: str, baud: int, what: str, args: list[str],
            ignore_schema: bool) -> int:
    from fswkit.link.client import Ground, LinkTimeout
    from fswkit.link.layout import LayoutError, encode_value
    from fswkit.link.port import open_port, port_errors
    from fswkit.autocode.app import TASK_MODES

    if not layout.has_uplink:
        raise GroundError(f"{project}: the application has no `uplink` task: the target takes no commands")
    # the command is checked before the port is opened
    if what == "set":
        if len(args) != 2:
            raise GroundError("usage: fsw cmd set ELEMENT VALUE")
        el = layout.element(args[0])
        if el is None:
            raise GroundError(f"unknown element `{args[0]}`: elements are "
                              + ", ".join(e.name for e in layout.elements))
        try:
            value = encode_value(el, args[1])
        except LayoutError as e:
            raise GroundError(str(e)) from None
        op, payload = wire.OP_SET, el.index.to_bytes(2, "little") + value
    elif what == "mode":
        if len(args) != 2:
            raise GroundError("usage: fsw cmd mode TASK disabled|safed|enabled")
        ti = layout.task_index(args[0])
        if ti is None:
            raise GroundError(f"unknown task `{args[0]}`: tasks are " + ", ".join(n for n, _ in layout.tasks))
        modes = TASK_MODES
        if args[1] not in modes:
            raise GroundError(f"unknown mode `{args[1]}`: one of disabled, safed, enabled")
        op, payload = wire.OP_MODE, bytes((ti, modes[args[1]]))
    elif what in ("ping", "hello", "snapshot"):
        if args:
            raise GroundError(f"`{what}` takes no arguments")
        op, payload = {"ping": wire.OP_PING, "hello": wire.OP_HELLO, "snapshot": wire.OP_SNAPSHOT}[what], b""
    else:
        raise GroundError(f"unknown command `{what}`: set, mode, ping, hello or snapshot")

    session = Session(layout, ignore_schema=ignore_schema)
    port = open_port(port_name, baud)
    ground = Ground(port, session)
    try:
        try:
            ground.handshake(timeout=3.0)
        except LinkTimeout as e:
            if not ignore_schema:
                raise GroundError(f"{e}: is the firmware running on {port_name}, at {baud} baud?\n  "
                                  + summary(session)) from None
        if session.hello is not None and not session.hello["schema_ok"] and not ignore_schema:
            raise GroundError(schema_message(session, project))
        sent = time.monotonic()
        try:
            ack = ground.command(op, payload)
        except LinkTimeout as e:
            raise GroundError(str(e)) from None
        rtt = (time.monotonic() - sent) * 1000
    except port_errors() as e:
        raise GroundError(f"{port_name}: the port went away ({e})") from None
    finally:
        try:
            port.close()
        except Exception:  # noqa: BLE001 - closing a port that went away
            pass
    if ack["status"] != 0:
        sys.stderr.write(f"fsw cmd: refused: {ack['status_name']}: {ack['reason']} (command {ack['cmd_seq']})\n")
        return 1
    print(f"fsw cmd: {what} {' '.join(args)}: OK (command {ack['cmd_seq']}, {rtt:.1f} ms round trip)".replace("  ", " "))
    return 0
