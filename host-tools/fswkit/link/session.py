"""Decoding a link session: verified frames (wire.Deframer) checked against
the layout, with 8-bit sequence numbers and 32-bit times extended to full
width, sample values decoded, and link health counted. Used by the monitor,
the log tools and simulations alike."""

from __future__ import annotations

import struct
from collections import deque
from dataclasses import dataclass

from fswkit.autocode.app import TASK_MODES
from fswkit.autocode.protocol import (ACK_PAYLOAD, HEALTH_PAYLOAD, HEALTH_TASK, HELLO_PAYLOAD, PYRO_ARMED,
                                     PYRO_CONTINUITY, PYRO_FIRED, PYRO_FIRING, PYRO_NO_SENSE, RESET_RESUMED,
                                     SENSOR_HEALTH, SENSOR_NO_ANSWER)

from . import wire
from .layout import Layout

_HELLO, _HEALTH, _TASK, _ACK = HELLO_PAYLOAD, HEALTH_PAYLOAD, HEALTH_TASK, ACK_PAYLOAD
_U16 = struct.Struct("<H")
TASK_MODE_NAMES = {v: k for k, v in TASK_MODES.items()}  # a task's mode on the wire -> its name


class Event:
    """A decoded frame. kind: sample | snapshot | hello | health | ack;
    seq: its full sequence number; time: the target's time (the unit of
    `G`); host_time: seconds (host clock) when its bytes arrived; samples
    (sample frames): [(time, values tuple)]; info: the other frames' fields."""

    __slots__ = ("kind", "seq", "time", "host_time", "stream", "samples", "info")

    def __init__(self, kind, seq, time, host_time, stream=-1, samples=(), info=None):
        self.kind, self.seq, self.time, self.host_time = kind, seq, time, host_time
        self.stream, self.samples, self.info = stream, samples, info if info is not None else {}


@dataclass
class LinkStats:
    frames: int = 0  # frames accepted (verified and consistent with the layout)
    lost: int = 0  # frames missing from the sequence
    gaps: int = 0  # places where frames were missing
    undecoded: int = 0  # frames before the schema was confirmed
    restarts: int = 0  # target resets seen (frame counter went back)
    samples: int = 0


ACKS_KEPT = 1024  # acknowledgements a session keeps (its latest): a long session's are not all held

RESET_CAUSES = ((0x01, "power-on"), (0x02, "external reset"), (0x04, "brown-out"), (0x08, "watchdog"))


def reset_words(cause: int | None) -> str:
    """An AVR reset cause (MCUSR bits) in words, and whether the firmware
    resumed its flight's state (RESET_RESUMED, docs/safety.md)."""
    if cause is None:
        return "unknown"
    words = [w for bit, w in RESET_CAUSES if cause & bit]
    text = ", ".join(words) if words else f"none reported (0x{cause & ~RESET_RESUMED:02x})"
    return text + ", flight resumed" if cause & RESET_RESUMED else text


def sensor_status(name: str, code: int) -> dict:
    """A sensor part's health code of a health frame (fsw_sensor.h kSensor*)."""
    words = SENSOR_HEALTH.get(code, f"UNKNOWN CODE {code}")
    return {"name": name, "code": code, "fault": code >= SENSOR_NO_ANSWER, "words": words}


def pyro_status(name: str, bits: int) -> dict:
    """A pyro channel's status byte of a health frame (fsw_io.h kPyro*)."""
    sense = None if bits & PYRO_NO_SENSE else bool(bits & PYRO_CONTINUITY)
    words = ["armed" if bits & PYRO_ARMED else "disarmed",
             "no continuity input" if sense is None else "continuity" if sense else "OPEN",
             "FIRING" if bits & PYRO_FIRING else "fired" if bits & PYRO_FIRED else "not fired"]
    return {"name": name, "armed": bool(bits & PYRO_ARMED), "continuity": sense, "fired": bool(bits & PYRO_FIRED),
            "firing": bool(bits & PYRO_FIRING), "bits": bits, "words": ", ".join(words)}


class SchemaMismatch(Exception):
    pass


def max_frame(layout: Layout) -> int:
    """The longest encoded frame the layout allows (hello, health, a whole
    snapshot chunk or a stream's full batch), without its delimiter."""
    payload = max([_HELLO.size, layout.health_payload, 2 + layout.sv_size]
                  + [s.region.size * s.batch for s in layout.streams])
    return wire.encoded_size(wire.HEADER + payload)


class Session:
    def __init__(self, layout: Layout, ignore_schema: bool = False):
        self.layout = layout
        self.deframer = wire.Deframer(self.consistent, max_frame(layout))
        self.stats = LinkStats()
        self.ignore_schema = ignore_schema
        self.schema_ok: bool | None = True if ignore_schema else None
        self.target_schema: int | None = None
        self.values: dict[str, object] = {e.name: None for e in layout.elements}
        self.hello: dict | None = None
        self.health: dict | None = None
        self.acks: deque = deque(maxlen=ACKS_KEPT)  # the latest acknowledgements' fields, oldest first
        self.last_seq: int | None = None
        # whether last_seq is the target's whole frame counter (from a hello or
        # health frame), or only extended from the first frame's 8 bits
        self.seq_known = False
        self.t_ref: int | None = None
        self.delay_min: float | None = None
        self.latency: float | None = None  # seconds above the least delay seen
        self._recent: deque = deque(maxlen=4096)
        self._snap = bytearray(layout.sv_size)
        self._snap_at = -1  # bytes of the snapshot received in order so far (-1: none)
        self._per_second = 1000.0 if layout.time_unit == "ms" else 1e6
        self._hs = len(self.layout.tasks)

    def numbering(self) -> dict:
        """Where this session's frame numbers and times stand (for `adopt`)."""
        return {"last_seq": self.last_seq, "seq_known": self.seq_known, "t_ref": self.t_ref}

    def adopt(self, hello: dict | None, health: dict | None = None, numbering: dict | None = None) -> None:
        """The target's last hello and health, and the numbering, as another
        decoder (a ground station) had them just before the bytes this
        session will be fed, for a session that attaches mid-stream: the
        schema is judged as from a hello of its own, the frames get their
        full numbers from the first, and frames (losses too) are counted
        from the first this session sees."""
        if numbering is not None and numbering.get("last_seq") is not None:
            self.last_seq = numbering["last_seq"]
            self.seq_known = bool(numbering.get("seq_known"))
            self.t_ref = numbering.get("t_ref")
        if hello is not None:
            info = dict(hello, expected_schema=self.layout.schema)
            ok = info["schema"] == self.layout.schema and info["protocol"] == wire.PROTOCOL
            info["schema_ok"] = ok
            self.hello = info
            self.target_schema = info["schema"]
            if not self.ignore_schema:
                self.schema_ok = ok
        if health is not None:
            self.health = dict(health)

    # ---- wire ---------------------------------------------------------------------

    def feed(self, data: bytes, host_time: float = 0.0) -> list[Event]:
        out = []
        append = out.append
        streams = self.layout.streams
        n_streams = len(streams)
        st = self.stats
        values = self.values
        n_fast = n_samples = 0
        for ftype, s8, t32, payload in self.deframer.feed(data):
            # the common case inline: a one-sample frame of a known stream, in
            # sequence, its time within the current 2^32 window
            last = self.last_seq
            if (ftype & 0x80 and self.schema_ok and last is not None and (last + 1) & 0xFF == s8
                    and (ftype & 0x7F) < n_streams):
                stream = streams[ftype & 0x7F]
                region = stream.region
                size = region.size
                n = len(payload)
                ref = self.t_ref
                if ref is not None and size and (n == size or (n % size == 0 and n <= size * stream.batch)):
                    t = (ref & ~0xFFFFFFFF) | t32
                    if abs(t - ref) < 0x40000000:
                        n_fast += 1
                        self.last_seq = seq = last + 1
                        if t > ref:
                            self.t_ref = t
                        if n == size:
                            vals = region.decode(payload)
                            samples = [(t, vals)]
                            n_samples += 1
                        else:
                            period = stream.period
                            rows = region.decode_all(payload)
                            samples = [(t + i * period, v) for i, v in enumerate(rows)]
                            vals = rows[-1]
                            n_samples += len(rows)
                        values.update(zip(region.names, vals))
                        if host_time:
                            self._delay(samples[-1][0], host_time)
                        append(Event("sample", seq, t, host_time, stream.index, samples))
                        continue
            ev = self._frame(ftype, s8, t32, payload, host_time)
            if ev is not None:
                append(ev)
        st.frames += n_fast
        st.samples += n_samples
        if n_fast:
            self._recent.append((host_time, n_fast))
        return out

    def frames_per_second(self, now: float, window: float = 2.0) -> float:
        r = self._recent
        while r and r[0][0] < now - window:
            r.popleft()
        return sum(n for _, n in r) / window

    # ---- frames ---------------------------------------------------------------------

    def consistent(self, ftype: int, body: bytes) -> bool:
        """Whether a verified frame body (header + payload + CRC) has a type
        and length this layout allows: a second check after the CRC."""
        n = len(body) - wire.HEADER - 2
        lay = self.layout
        if ftype & 0x80:
            si = ftype & 0x7F
            if si >= len(lay.streams):
                return False
            stream = lay.streams[si]
            size = stream.region.size
            return size > 0 and n % size == 0 and 1 <= n // size <= stream.batch
        if ftype == wire.HELLO:
            return n == _HELLO.size
        if ftype == wire.HEALTH:
            return n == lay.health_payload
        if ftype == wire.ACK:  # a parameter command's data may follow
            return n >= _ACK.size
        if ftype == wire.SNAPSHOT:
            return n >= 2 and _U16.unpack_from(body, wire.HEADER)[0] + n - 2 <= lay.sv_size
        return False

    def _extend_time(self, t32: int) -> int:
        ref = self.t_ref
        if ref is None:
            return t32
        t = (ref & ~0xFFFFFFFF) | t32
        if t - ref > 0x80000000:
            t -= 0x100000000
        elif ref - t > 0x80000000:
            t += 0x100000000
        return t

    def _frame(self, ftype, s8, t32, payload, host_time) -> Event | None:
        lay = self.layout
        n = len(payload)
        if ftype & 0x80:
            stream = lay.streams[ftype & 0x7F]
            k = n // stream.region.size
        st = self.stats
        st.frames += 1
        self._recent.append((host_time, 1))
        # sequence: 8 bits on the wire, extended; hello and health carry all 32
        if self.last_seq is None:
            seq = s8
            gap = 0
        else:
            gap = (s8 - self.last_seq - 1) & 0xFF
            seq = self.last_seq + 1 + gap
        if ftype == wire.HELLO or ftype == wire.HEALTH:
            full = struct.unpack_from("<I", payload, 9 if ftype == wire.HELLO else 4)[0]
            time_hi = struct.unpack_from("<I", payload, 5 if ftype == wire.HELLO else 0)[0]
            restarted = False
            if self.seq_known and full <= self.last_seq:
                restarted = True  # the counter went back: the target was reset
            if self.seq_known and not restarted:
                if full > seq:
                    st.lost += full - seq  # whole wraps of the 8-bit number went missing
                    if gap == 0:
                        st.gaps += 1
            # Joined mid-stream, the ground numbered its first frame with its
            # 8 bits alone: the whole counter renumbers the frames seen so far,
            # and only the gaps between them (counted above) were lost.
            if restarted:
                st.restarts += 1
                gap = 0
            seq = full
            self.seq_known = True
            self.t_ref = (time_hi << 32) | t32
            time = self.t_ref
        else:
            time = self._extend_time(t32)
            if self.t_ref is None or time > self.t_ref:
                self.t_ref = time
        if gap:
            st.lost += gap
            st.gaps += 1
        self.last_seq = seq

        if ftype == wire.HELLO:
            return self._hello(seq, time, host_time, payload)
        if ftype != wire.ACK and self.schema_ok is not True:
            st.undecoded += 1
            return None
        if ftype & 0x80:
            return self._sample(stream, seq, time, host_time, payload, k)
        if ftype == wire.HEALTH:
            return self._health(seq, time, host_time, payload)
        if ftype == wire.ACK:
            cseq, op, status, last = _ACK.unpack_from(payload)
            name, why = wire.STATUS.get(status, (f"STATUS_{status}", "unknown status"))
            info = {"cmd_seq": cseq, "op": op, "op_name": wire.OP_NAMES.get(op, f"op_{op}"), "status": status,
                    "status_name": name, "reason": why, "last_seq": last, "data": bytes(payload[_ACK.size:])}
            self.acks.append(info)
            return Event("ack", seq, time, host_time, info=info)
        return self._snapshot(seq, time, host_time, payload)

    def _delay(self, time: int, host_time: float) -> None:
        if not host_time:
            return
        d = host_time - time / self._per_second
        if self.delay_min is None or d < self.delay_min:
            self.delay_min = d
        self.latency = d - self.delay_min

    def _hello(self, seq, time, host_time, payload) -> Event:
        proto, schema, _hi, frames, major, minor, patch, cause, last, params = _HELLO.unpack(payload)
        info = {"protocol": proto, "schema": schema, "frames": frames, "runtime": f"{major}.{minor}.{patch}",
                "reset_cause": cause, "last_seq": last, "params": params, "expected_schema": self.layout.schema}
        self.hello = info
        self.target_schema = schema
        ok = schema == self.layout.schema and proto == wire.PROTOCOL
        info["schema_ok"] = ok
        if not self.ignore_schema:
            self.schema_ok = ok
        return Event("hello", seq, time, host_time, info=info)

    def _sample(self, stream, seq, time, host_time, payload, k) -> Event:
        region = stream.region
        if k == 1:
            samples = [(time, region.decode(payload))]
        else:
            period = stream.period
            samples = [(time + i * period if i else time, v) for i, v in enumerate(region.decode_all(payload))]
        last = samples[-1][1]
        vals = self.values
        for e, v in zip(region.names, last):
            vals[e] = v
        self.stats.samples += k
        self._delay(samples[-1][0], host_time)
        return Event("sample", seq, time, host_time, stream=stream.index, samples=samples)

    def _health(self, seq, time, host_time, payload) -> Event:
        f = _HEALTH.unpack_from(payload)
        keys = ("time_hi", "frames", "dropped", "cycles", "late", "reset_cause", "rx_ok", "rx_crc",
                "rx_malformed", "rx_oversized", "rx_replayed", "rx_refused", "last_seq", "params")
        info = dict(zip(keys, f))
        tasks = []
        for i, (name, kind) in enumerate(self.layout.tasks):
            mode, faults, over, worst = _TASK.unpack_from(payload, _HEALTH.size + i * _TASK.size)
            tasks.append({"name": name, "kind": kind, "mode": mode, "mode_name": TASK_MODE_NAMES.get(mode, "safed"),
                          "faults": faults, "overruns": over, "worst_us": worst})
        info["tasks"] = tasks
        at = _HEALTH.size + len(self.layout.tasks) * _TASK.size
        info["pyro"] = [pyro_status(name, payload[at + i]) for i, name in enumerate(self.layout.pyro)]
        at += len(self.layout.pyro)
        info["sensors"] = [sensor_status(name, payload[at + i]) for i, name in enumerate(self.layout.sensors)
                           if at + i < len(payload)]
        self.health = info
        self._delay(time, host_time)
        return Event("health", seq, time, host_time, info=info)

    def _snapshot(self, seq, time, host_time, payload) -> Event:
        off = _U16.unpack_from(payload)[0]
        data = payload[2:]
        if off == 0:
            self._snap_at = 0
        complete = False
        if self._snap_at == off:
            self._snap[off:off + len(data)] = data
            self._snap_at = off + len(data)
            if self._snap_at == self.layout.sv_size:
                complete = True
                self._snap_at = -1
                snap = {}
                for r in self.layout.regions:
                    snap.update(zip(r.names, r.decode(bytes(self._snap), r.offset)))
                self.values.update(snap)
        info = {"offset": off, "length": len(data), "complete": complete}
        if complete:
            info["values"] = snap
        return Event("snapshot", seq, time, host_time, info=info)


def describe(ev: Event, layout: Layout) -> str:
    """One line for an event (headless monitor, replay)."""
    head = f"seq={ev.seq} t={ev.time}"
    if ev.kind == "sample":
        st = layout.streams[ev.stream]
        names = [e.name for e in st.region.elements]
        parts = []
        for t, vals in ev.samples:
            parts.append(f"t={t:g} " + " ".join(f"{n}={layout.show(n, v)}" for n, v in zip(names, vals)))
        return f"{head} sample {st.region.name} " + " | ".join(parts)
    i = ev.info
    if ev.kind == "hello":
        ok = "matches" if i["schema_ok"] else f"MISMATCH (configs give 0x{i['expected_schema']:08x})"
        return (f"{head} hello protocol={i['protocol']} schema=0x{i['schema']:08x} {ok} runtime={i['runtime']} "
                f"reset_cause=0x{i['reset_cause']:02x} last_cmd={i['last_seq']}")
    if ev.kind == "health":
        tasks = " ".join(f"{t['name']}:{t['mode_name']},over={t['overruns']},worst={t['worst_us']}us"
                         for t in i["tasks"])
        return (f"{head} health frames={i['frames']} dropped={i['dropped']} cycles={i['cycles']} late={i['late']} "
                f"reset_cause=0x{i['reset_cause']:02x} rx_ok={i['rx_ok']} rx_crc={i['rx_crc']} "
                f"rx_malformed={i['rx_malformed']} rx_oversized={i['rx_oversized']} "
                f"rx_replayed={i['rx_replayed']} rx_refused={i['rx_refused']} {tasks}"
                + "".join(f" pyro {p['name']}: {p['words']}" for p in i.get("pyro", ()))
                + "".join(f" sensor {s['name']}: {s['words']}" for s in i.get("sensors", ())))
    if ev.kind == "ack":
        return f"{head} ack cmd={i['cmd_seq']} {i['op_name']} {i['status_name']}"
    if ev.kind == "snapshot":
        return f"{head} snapshot offset={i['offset']} length={i['length']}" + (" complete" if i["complete"] else "")
    return f"{head} {ev.kind}"
