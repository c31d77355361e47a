"""`fsw monitor` and `fsw cmd` on a target's serial link, decoded through
fswkit.link (one decoder); the live view is fswkit.ground.view, the
recordings' tools fswkit.ground.logs."""

from __future__ import annotations

import os
import sys
import time

from fswkit import outputs
from fswkit.link import wire
from fswkit.link.layout import Layout
from fswkit.link.session import Session
from fswkit.usage import UsageError, unknown_name

from .view import View


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

# ---- fsw monitor -----------------------------------------------------------------

def monitor(layout: Layout, project: str, port_name: str, baud: int, log_path: str | None, headless: bool,
            ignore_schema: bool, duration: float | None, max_frames: int | None, force: bool = False,
            spark=()) -> int:
    from fswkit.link.client import LinkTimeout
    from fswkit.link.log import LogError, LogWriter
    from fswkit.link.port import port_errors

    from .client import StationRefused, connect

    session = Session(layout, ignore_schema=ignore_schema)
    # the log is checked first and takes its name only once the target is known
    # to be the right one: a refused session leaves an old recording as it was
    log = LogWriter(log_path, layout, force=force, port=port_name, project=project) if log_path else None
    try:
        ground = connect(port_name, baud, session, "fsw monitor", log)
    except BaseException as e:
        if log is not None:
            log.close(keep=False)
        if isinstance(e, StationRefused):
            raise GroundError(str(e)) from None
        raise
    if ground.via != "the port":
        sys.stderr.write(f"fsw monitor: {port_name}: through {ground.via}\n")
    refused = False
    verified = False  # the target answered as the right one: the log may replace what was there
    view = View(session, headless, f"{layout.name} on {port_name}", spark=spark)
    start = time.monotonic()
    status = 0
    shown = 0  # frames decoded and shown (--frames counts these: a read may bring more than are left)

    def show(ev) -> None:
        nonlocal shown
        if max_frames is None or shown < max_frames:
            view.event(ev)
            shown += 1

    try:
        with outputs.stopped_by_signals(), view:
            try:
                ground.handshake(timeout=3.0 if layout.has_uplink else 12.0, on_event=show)
            except LinkTimeout as e:
                if not ignore_schema:
                    raise GroundError(f"{e}: is the firmware running on {port_name}, at {baud} baud? "
                                      "(--ignore-schema decodes without one)\n  " + summary(session)) from None
            if session.hello is not None and not session.hello["schema_ok"] and not ignore_schema:
                raise GroundError(schema_message(session, project))
            verified = True
            if log is not None:
                log.commit()
            if layout.has_uplink and (max_frames is None or shown < max_frames):
                try:
                    ground.command(wire.OP_SNAPSHOT, timeout=1.0, on_event=show)
                except LinkTimeout:
                    pass
            while max_frames is None or shown < max_frames:
                for ev in ground.read():
                    show(ev)
                    if ev.kind == "hello" and not ev.info["schema_ok"] and not ignore_schema:
                        raise GroundError(schema_message(session, project))
                view.note = ground.note  # the station's word on its link (went away, reconnected)
                view.update()
                if duration is not None and time.monotonic() - start >= duration:
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
        ground.close()
    sys.stderr.write(summary(session) + "\n")
    return status


# ---- fsw cmd -------------------------------------------------------------------------

def command(layout: Layout, project: str, port_name: str, baud: int, what: str, args: list[str],
            ignore_schema: bool) -> int:
    from fswkit.link.client import LinkTimeout
    from fswkit.link.layout import LayoutError, encode_value
    from fswkit.link.port import port_errors

    from .client import StationRefused, connect
    from fswkit.autocode.app import TASK_MODES

    if not layout.has_uplink:
        raise UsageError(f"{project}: the application has no `uplink` task: the target takes no commands")
    # the command is checked before the port is opened
    if what == "set":
        if len(args) != 2:
            raise UsageError("usage: fsw cmd set ELEMENT VALUE")
        el = layout.element(args[0])
        if el is None:
            raise UsageError("set: " + unknown_name("element", [args[0]], [e.name for e in layout.elements]))
        try:
            value = encode_value(el, args[1])
        except LayoutError as e:
            raise UsageError(str(e)) from None
        op, payload = wire.OP_SET, el.index.to_bytes(2, "little") + value
    elif what == "mode":
        if len(args) != 2:
            raise UsageError("usage: fsw cmd mode TASK disabled|safed|enabled")
        ti = layout.task_index(args[0])
        if ti is None:
            raise UsageError("mode: " + unknown_name("task", [args[0]], [n for n, _ in layout.tasks]))
        modes = TASK_MODES
        if args[1] not in modes:
            raise UsageError(f"mode: unknown mode `{args[1]}`: one of disabled, safed, enabled")
        op, payload = wire.OP_MODE, bytes((ti, modes[args[1]]))
    elif what in ("ping", "hello", "snapshot"):
        if args:
            raise UsageError(f"`{what}` takes no arguments")
        op, payload = {"ping": wire.OP_PING, "hello": wire.OP_HELLO, "snapshot": wire.OP_SNAPSHOT}[what], b""
    else:
        raise UsageError(f"unknown command `{what}`: set, mode, ping, hello or snapshot")

    session = Session(layout, ignore_schema=ignore_schema)
    try:
        ground = connect(port_name, baud, session, "fsw cmd")
    except StationRefused as e:
        raise GroundError(str(e)) from None
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
            ack = ground.command(op, payload, text=" ".join([what, *args]))
        except LinkTimeout as e:
            raise GroundError(str(e)) from None
        rtt = (time.monotonic() - sent) * 1000
    except port_errors() as e:
        raise GroundError(f"{port_name}: the port went away ({e})") from None
    finally:
        ground.close()
    if ack["status"] != 0:
        sys.stderr.write(f"fsw cmd: refused: {ack['status_name']}: {ack['reason']} (command {ack['cmd_seq']})\n")
        return 1
    said = " ".join([what, *args])
    print(f"fsw cmd: {said}: OK (command {ack['cmd_seq']}, {rtt:.1f} ms round trip)")
    return 0
