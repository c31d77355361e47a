"""The schema hash: a fingerprint of the state vector layout (and, for an
application, of what flows over the link), shared by the generated code,
the firmware's hello frame and the host decoder."""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from fractions import Fraction

from . import model as M
from .protocol import (ACK_PAYLOAD, CRC, HEADER, HEALTH_PAYLOAD, HEALTH_PYRO, HEALTH_SENSOR, HEALTH_TASK,
                       HELLO_PAYLOAD, PROTOCOL, RELOAD_INFO_SIZE, SNAPSHOT_OFFSET, encoded_max)
from .sensors import sensor_name


def layout_text(sv: M.StateVector) -> str:
    """A canonical description of the layout: what the hash covers."""
    lines = [f"lock {int(sv.lock)}"]
    for r in sv.regions:
        lines.append(f"region {r.name} {r.offset} {r.size}")
        lines += [f"  {e.type.name} {e.name} {e.offset}" for e in r.elements]
    return "\n".join(lines) + "\n"


def schema_hash(sv: M.StateVector, extra: str = "") -> int:
    """A 32-bit fingerprint of the layout (and `extra`)."""
    digest = hashlib.sha256((layout_text(sv) + extra).encode()).digest()
    return int.from_bytes(digest[:4], "little")


# ---- the serial link: what flows over it, decided once for both ends -------------

BATCH_PAYLOAD = 96  # a sample frame batches samples up to this many payload bytes...
BATCH_MIN_FRAME_HZ = 20  # ...while it still goes out at least this often
HEALTH_HZ = 1  # health frames per second (at most one per telemetry run)
HELLO_EVERY = 10  # health frames between two unsolicited hellos


@dataclass(frozen=True)
class LinkStream:
    index: int
    region: M.Region
    rate: Fraction  # samples per second
    every: int  # telemetry-task runs between samples
    batch: int  # samples per frame


@dataclass(frozen=True)
class LinkPlan:
    """The link of an application as both ends see it: streams with their
    batching, frame sizes, which tasks carry it. The generator emits it as
    tables; the host decoder reads it; the schema hash covers it."""
    streams: tuple[LinkStream, ...]
    writable: tuple[M.Element, ...]
    telemetry_task: int | None  # index in app.tasks
    uplink_task: int | None
    health_every: int  # telemetry runs between health frames (0: no telemetry task)
    hello_every: int
    health_payload: int
    snapshot_chunk: int
    tx_cap: int  # the transmit buffer: the longest encoded frame


def _batch(size: int, rate: Fraction) -> int:
    if size <= 0:
        return 1
    return max(1, min(BATCH_PAYLOAD // size, int(rate // BATCH_MIN_FRAME_HZ)))


def link_plan(app) -> LinkPlan:
    """The link plan of a checked Application (autocode.app)."""
    tele = next((i for i, t in enumerate(app.tasks) if t.kind == "telemetry"), None)
    up = next((i for i, t in enumerate(app.tasks) if t.kind == "uplink"), None)
    streams = []
    for i, s in enumerate(app.telemetry):
        tele_rate = app.tasks[tele].rate
        every = int(tele_rate / s.rate)
        streams.append(LinkStream(i, s.region, s.rate, every, _batch(s.region.size, s.rate)))
    health_every = max(1, int(app.tasks[tele].rate // HEALTH_HZ)) if tele is not None else 0
    health_payload = (HEALTH_PAYLOAD.size + HEALTH_TASK.size * len(app.tasks) + HEALTH_PYRO * len(app.pyro)
                      + HEALTH_SENSOR * len(app.sensors))
    bodies = [HELLO_PAYLOAD.size, ACK_PAYLOAD.size, health_payload] + [s.batch * s.region.size for s in streams]
    if getattr(app, "reload", None) is not None:  # MACHINE_INFO's ack (docs/reload.md)
        bodies.append(ACK_PAYLOAD.size + RELOAD_INFO_SIZE)
    longest = max(bodies)
    sv_size = max(app.sv.size, 1)
    snapshot_chunk = max(1, min(sv_size, longest - SNAPSHOT_OFFSET))
    tx_cap = encoded_max(HEADER + longest + CRC)
    return LinkPlan(tuple(streams), tuple(app.writable), tele, up, health_every,
                    HELLO_EVERY if tele is not None else 0, health_payload, snapshot_chunk, tx_cap)


def link_text(app) -> str:
    """What the link schema covers beyond the layout: the protocol, the
    executor, the tasks, the streams and the writable elements."""
    plan = link_plan(app)
    lines = [f"protocol {PROTOCOL}", f"rate {app.rate}", f"time {app.time_source} {app.time_unit}"]
    for t in app.tasks:
        mode = t.mode.name if t.mode is not None else "-"
        lines.append(f"task {t.name} {t.kind} {t.divider} {mode} {t.start}")
    for s in plan.streams:
        lines.append(f"stream {s.index} {s.region.name} {s.every} {s.batch}")
    for e in plan.writable:
        lines.append(f"writable {e.name}")
    for m in app.machines:  # S is shown by state name
        lines.append(f"machine {m.name} {m.vars[m.s].name} " + " ".join(f"{st.id}={st.name}" for st in m.states))
    for p in app.pyro:  # a status byte each in health frames
        lines.append(f"pyro {p.element.name}")
    for p in app.sensors:  # a health code each in health frames, after the pyro bytes
        lines.append(f"sensor {sensor_name(p)}")
    if getattr(app, "reload", None) is not None:  # MACHINE_* commands: the slots and their size
        rl = app.reload
        lines.append(f"reload {app.machines[rl.machine].name} {rl.size} {rl.ram} " + " ".join(rl.activate))
    lines.append(f"health {plan.health_every} {plan.hello_every} snapshot {plan.snapshot_chunk}")
    return "\n".join(lines) + "\n"


def app_schema_hash(app) -> int:
    """The schema hash a hello frame carries: the layout and the link."""
    return schema_hash(app.sv, link_text(app))
