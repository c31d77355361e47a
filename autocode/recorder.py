"""The flight recorder's layout (docs/recorder.md), for both ends: the
generator sizes the firmware's tables and RAM from it, and the ground
(`fsw dump`, `fsw sim`) and the tests decode records with it.

A record is `record` bytes in one of `slots` slots of the store, from
`base` (after the parameter banks; 0 on an SPI NOR flash, whose slots are
the chip's size / record, at most 65,535):

    0        kind: 0xF0 a flight's start, 0xF1 samples (written last)
    1..2     sequence number, u16 (one more for each record written)
    3        flight number, 1..255
    4..7     t0, u32 ms: the trigger (start) or the first sample (samples)
    8..      start: schema hash u32, log hash u32
             samples: each held field's value, then the first sample's
             other fields (absolute), then each later sample
    R-5..R-4 period u16, ms between samples (0: one sample)
    R-3      used: bytes 0..used-1 are the record's
    R-2..R-1 CRC-16 (CCITT-FALSE) of bytes 0..used-1 then R-5..R-3

A later sample: escapes [0x80, field, value] for held fields that change
(only when the first non-held field is a delta), then each non-held field:
a delta one signed byte, a quant two, a raw one its bytes."""

from __future__ import annotations

import hashlib
import math
import struct
from dataclasses import dataclass, field
from fractions import Fraction

from .protocol import crc16

START, DATA = 0xF0, 0xF1
HEADER = 8
TAIL = 5
ESCAPE = 0x80
MAX_SLOTS = 65535  # slot numbers are u16
NOR_SECTOR = 4096  # an SPI NOR flash's erase sector
EEPROM_WRITE_S = 0.0034  # one AVR EEPROM byte (datasheet: 3.3 ms typical, 3.4 ms with the margin avr-libc uses)


def encoded_size(enc: str, width: int) -> int:
    """Bytes a field takes in a later sample of a record."""
    return {"delta": 1, "quant": 2}.get(enc, width)


@dataclass(frozen=True)
class Field:
    name: str
    type: object  # ElemType
    enc: str
    step: Fraction | None
    width: int

    def value(self, raw: bytes):
        """The element's value from its absolute bytes in a sample."""
        if self.enc in ("delta", "quant"):
            q = int.from_bytes(raw, "little", signed=True)
            return float(q * self.step) if self.step.denominator != 1 else q * int(self.step)
        if self.width < self.type.size:  # a narrowed state number
            return int.from_bytes(raw, "little")
        v = struct.unpack("<" + self.type.fmt, raw)[0]
        return bool(v) if self.type.is_bool else v

    def encoded(self) -> int:
        return encoded_size(self.enc, self.width)


@dataclass(frozen=True)
class Plan:
    fields: tuple[Field, ...]
    record: int
    base: int
    slots: int
    newest: bool
    dividers: tuple[int, ...]  # by state id: task runs between samples, 0: none
    erase_ok: tuple[int, ...]
    trigger: int
    before_ms: int
    period_ms: Fraction  # one recorder task run
    runs_mod: int  # the run counter's wrap: a multiple of every divider
    ring_cap: int
    fifo_cap: int
    sample_size: int
    opening: int
    worst: int
    n_hold: int
    escape: bool
    hash: int
    state_element: str
    time_element: str
    machine: str
    states: tuple[str, ...]  # names by state id - 1
    store: str = "eeprom"  # or "spi_nor" (docs/recorder.md, "On an SPI NOR flash chip")
    cs_pin: int | None = None  # spi_nor: the chip select's board pin
    flash_size: int = 0  # spi_nor: bytes of the chip

    @property
    def ram(self) -> int:
        """Bytes of RAM the recorder takes: ring, fifo, previous sample, record."""
        return self.ring_cap * self.sample_size + self.fifo_cap + (self.sample_size - 2) + RECORDER_SIZE

    @property
    def size(self) -> int:
        return self.slots * self.record


RECORDER_SIZE = 35  # sizeof(fsw::Recorder) on an AVR (tests/recorder checks it against the ELF)


def log_text(log, sv) -> str:
    """What the log hash covers: the record size and each field."""
    parts = [f"record={log.record}"]
    for f in log.fields:
        parts.append(f"{f.element.name}:{f.element.type.name}:{f.enc}:{f.step}:{f.width}")
    return ";".join(parts)


def log_hash(log, sv) -> int:
    return int.from_bytes(hashlib.sha256(log_text(log, sv).encode()).digest()[:4], "little")


def _predecessors(m, target: int) -> set[int]:
    """Ids of the states with a `goto` to state id `target`."""
    out = set()

    def walk(stmts, sid):
        for s in stmts:
            if type(s).__name__ == "Goto" and m.states[s.state].id == target:
                out.add(sid)
            for sub in ("then", "orelse"):
                walk(getattr(s, sub, ()), sid)
    for st in m.states:
        for part in (st.entry, st.step, st.exit):
            walk(part, st.id)
    return out


def record_sizes(fields) -> tuple[int, int, bool, int, int]:
    """Of the `[log]` fields in record order (model.LogField): (bytes of a
    ring sample, held fields, whether held changes are escapes, bytes of a
    record's opening: its header and first sample, or a start record's 16;
    the most bytes a later sample takes)."""
    widths = sum(f.width for f in fields)
    n_hold = sum(f.enc == "hold" for f in fields)
    escape = n_hold < len(fields) and fields[n_hold].enc == "delta"
    worst = sum((2 + f.width) if escape else 0 for f in fields[:n_hold]) + \
        sum(encoded_size(f.enc, f.width) for f in fields[n_hold:])
    return 2 + widths, n_hold, escape, max(HEADER + 8, HEADER + widths), worst


def ring_capacity(log, m) -> int:
    """Samples the RAM ring holds: the `before` seconds at the rate of the
    states that lead to the trigger and one older sample, then room for
    what comes while the writer is busy: on the EEPROM a record's tail and
    kind (6 writes, 20 ms); on a flash a start record and a sector erase
    (45 ms), a pass of the loop each (one a cycle)."""
    max_rate = max(log.rates)
    pre_rate = max((log.rates[s] for s in _predecessors(m, log.trigger)), default=max_rate)
    busy_s = 0.025 if log.store == "eeprom" else 0.1
    return max(math.floor(log.before * pre_rate) + 1 + math.ceil(busy_s * max_rate) + 1, 2)


def plan(app) -> Plan | None:
    """The recorder of an application with a `[log]`, else None."""
    log = app.log
    if log is None:
        return None
    from .params import HEADER as PHEADER, app_parameters
    from .schema import app_schema_hash  # noqa: F401  (the start record carries it)

    task = next(t for t in app.tasks if t.kind == "recorder")
    m = app.machines[log.machine]
    params = app_parameters(app)
    store = log.store
    if store == "spi_nor":  # the whole chip, from 0 (slot numbers are u16)
        base = 0
        slots = min(log.flash_size // log.record, MAX_SLOTS)
    else:
        base = 2 * (PHEADER + sum(p.type.size for p in params)) if params else 0
        if app.reload is not None:  # the uploaded machines' slots come next (docs/reload.md)
            from .reloadcheck import eeprom_bytes
            base += eeprom_bytes(app.reload.size)
        slots = (app.board.eeprom - base) // log.record
    fields = tuple(Field(f.element.name, f.element.type, f.enc, f.step, f.width) for f in log.fields)
    sample_size, n_hold, escape, opening, worst = record_sizes(log.fields)
    dividers = tuple(0 if r == 0 else int(task.rate / r) for r in log.rates)
    ring_cap = ring_capacity(log, m)
    fifo_cap = max(opening - 1, worst)  # the kind byte is not queued: it is written last
    if log.store == "spi_nor":  # a program a cycle carries what the fifo holds: room for a record's opening and more
        fifo_cap = min(255, max(opening - 1, worst) + worst * 2)
    return Plan(fields, log.record, base, slots, log.newest, dividers,
                tuple(1 if sid in log.erase else 0 for sid in range(len(log.rates))), log.trigger,
                int(log.before * 1000), Fraction(1000) / task.rate, _runs_mod(dividers), ring_cap, fifo_cap,
                sample_size,
                opening, worst, n_hold, escape, log_hash(log, app.sv), m.vars[m.s].name, app.time_element.name,
                m.name, tuple(st.name for st in m.states), store, log.cs_pin,
                log.flash_size)


def _runs_mod(dividers) -> int:
    """A multiple of every divider within 16 bits. Rates are exact decimals of
    a task rate that divides 1,000,000, so dividers have no prime factors but
    2 and 5, and their least common multiple is at most 128 x 125."""
    m = 1
    for d in dividers:
        if d:
            m = m * d // math.gcd(m, d)
    k = 65535 // m  # the largest multiple that fits 16 bits: fewer wraps
    return m * max(k, 1)


# ---- decoding -------------------------------------------------------------------------

@dataclass
class Record:
    slot: int
    kind: int
    seq: int
    flight: int
    t0: int
    period: int
    schema: int = 0  # start records
    hash: int = 0
    samples: list = field(default_factory=list)  # [(t_ms, {name: value})]


class RecordError(ValueError):
    """A record whose CRC is right but whose body does not parse: the store
    was written by another application (the log hashes differ)."""


def valid(p: Plan, raw: bytes) -> bool:
    """Whether one slot's bytes are a whole record."""
    if len(raw) != p.record or raw[0] not in (START, DATA):
        return False
    used = raw[p.record - 3]
    if not HEADER <= used <= p.record - TAIL:
        return False
    crc = crc16(raw[:used] + raw[p.record - TAIL:p.record - 2])
    return crc == int.from_bytes(raw[p.record - 2:], "little")


def decode_slot(p: Plan, slot: int, raw: bytes, samples: bool = True) -> Record | None:
    """The record in one slot, None when it is not whole; `samples=False`:
    its header only (a record of samples is parsed with `parse_samples`)."""
    if not valid(p, raw):
        return None
    used = raw[p.record - 3]
    period = int.from_bytes(raw[p.record - TAIL:p.record - 3], "little")
    seq = int.from_bytes(raw[1:3], "little")
    t0 = int.from_bytes(raw[4:8], "little")
    rec = Record(slot, raw[0], seq, raw[3], t0, period)
    if raw[0] == START:
        if used != HEADER + 8:
            raise RecordError(f"record {slot}: a start record of {used} bytes")
        rec.schema = int.from_bytes(raw[8:12], "little")
        rec.hash = int.from_bytes(raw[12:16], "little")
        return rec
    if samples:
        parse_samples(p, rec, raw)
    return rec


def parse_samples(p: Plan, rec: Record, raw: bytes) -> None:
    """A whole record of samples' samples, into `rec.samples` (RecordError
    when the body does not parse with this plan's fields)."""
    slot, t0, period = rec.slot, rec.t0, rec.period
    used = raw[p.record - 3]
    body = raw[:used]
    i = HEADER
    cur: list[bytes] = []
    for f in p.fields:
        cur.append(body[i:i + f.width])
        i += f.width
    if i > used:
        raise RecordError(f"record {slot}: shorter than its first sample")
    t = t0
    rec.samples.append((t, _values(p, cur)))
    while i < used:
        if p.escape:
            while i < used and body[i] == ESCAPE:
                k = body[i + 1] if i + 1 < used else 0xFF
                if k >= p.n_hold or i + 2 + p.fields[k].width > used:
                    raise RecordError(f"record {slot}: a bad escape at byte {i}")
                cur[k] = body[i + 2:i + 2 + p.fields[k].width]
                i += 2 + p.fields[k].width
        for k in range(p.n_hold, len(p.fields)):
            f = p.fields[k]
            if f.enc == "delta":
                if i >= used:
                    raise RecordError(f"record {slot}: a sample cut short at byte {i}")
                d = body[i] - 256 if body[i] >= 128 else body[i]
                q = int.from_bytes(cur[k], "little", signed=True) + d
                if not -2**31 <= q < 2**31:  # the firmware's counts are i32: never a record it wrote
                    raise RecordError(f"record {slot}: a delta beyond the 32-bit count at byte {i}")
                cur[k] = q.to_bytes(4, "little", signed=True)
                i += 1
            else:
                n = f.encoded()
                if i + n > used:
                    raise RecordError(f"record {slot}: a sample cut short at byte {i}")
                cur[k] = body[i:i + n]
                i += n
        if period == 0:
            raise RecordError(f"record {slot}: samples without a period")
        t += period
        rec.samples.append((t, _values(p, cur)))


def _values(p: Plan, cur: list[bytes]) -> dict:
    return {f.name: f.value(b) for f, b in zip(p.fields, cur)}


@dataclass
class Flight:
    number: int
    start: Record | None  # None: its start record was overwritten (`full newest`)
    records: list[Record]
    # the start records written again for the same flight after the firmware
    # resumed it from a reset in flight (docs/safety.md): the flight goes on
    resumed: list[Record] = field(default_factory=list)
    # another log's hash when its start record says it was recorded with
    # another `[log]` (a firmware flashed since): its samples are not decoded
    foreign: int | None = None
    # records missing from the sequence numbers (a slot whose check fails
    # between valid ones: damaged, or written while it was read): (how
    # many, the time of the last sample before them or None before the
    # flight's first record, the time of the first after or None after
    # its last), ms
    lost: list[tuple[int, int | None, int | None]] = field(default_factory=list)

    @property
    def samples(self) -> list:
        return [s for r in self.records for s in r.samples]


def decode(p: Plan, image: bytes) -> tuple[list[Flight], int]:
    """The flights in a store image (`p.slots` records from its start), oldest
    first, and how many slots held no whole record. A flight whose start
    record names another log hash is not decoded (`Flight.foreign`); a
    hole in the sequence numbers is a lost record (`Flight.lost`)."""
    records: list[Record] = []
    raws: dict[int, bytes] = {}
    empty = 0
    for s in range(p.slots):
        raw = image[s * p.record:(s + 1) * p.record]
        r = decode_slot(p, s, raw, samples=False)
        if r is None:
            empty += 1
        else:
            records.append(r)
            raws[s] = raw
    if not records:
        return [], empty
    newest = records[0]
    for r in records[1:]:
        if (r.seq - newest.seq) & 0xFFFF and ((r.seq - newest.seq) & 0xFFFF) < 0x8000:
            newest = r
    records.sort(key=lambda r: (newest.seq - r.seq) & 0xFFFF, reverse=True)  # oldest first
    flights: list[Flight] = []
    owner: list[Flight] = []  # each record's flight, in the order of `records`
    for r in records:
        last = flights[-1] if flights else None
        if r.kind == START and last is not None and last.number == r.flight and last.start is not None \
                and last.start.hash == r.hash:
            last.resumed.append(r)  # the same flight, resumed after a reset in flight
        elif r.kind == START or last is None or last.number != r.flight:
            flights.append(Flight(r.flight, r if r.kind == START else None, [],
                                  foreign=r.hash if r.kind == START and r.hash != p.hash else None))
        f = flights[-1]
        if r.kind == DATA:
            if f.foreign is None:
                parse_samples(p, r, raws[r.slot])
            f.records.append(r)
        owner.append(f)
    for k in range(1, len(records)):
        a, b = records[k - 1], records[k]
        gap = (b.seq - a.seq - 1) & 0xFFFF
        if not gap:
            continue
        t_a = a.samples[-1][0] if a.samples else a.t0
        t_b = b.samples[0][0] if b.samples else b.t0
        if owner[k - 1] is owner[k]:
            owner[k].lost.append((gap, t_a, t_b))
        elif b.kind == START:  # a flight's start follows: the records lost were the last flight's end
            owner[k - 1].lost.append((gap, t_a, None))
        else:  # this flight's first records, its start among them
            owner[k].lost.append((gap, None, t_b))
    return flights, empty
