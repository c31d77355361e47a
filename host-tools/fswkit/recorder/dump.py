"""Dumped flights as link logs, and the reading of a target's records.

A flight's log has the layout of one region, `Record`, holding the logged
fields in their element types, streamed as stream 0 at the log's rate: each
recorded sample is one sample frame at its recorded time. Held and
delta-encoded values are decoded (a delta or quant field carries its
quantised value: the documented precision, docs/recorder.md)."""

from __future__ import annotations

import struct

from fswkit.autocode.protocol import HELLO, HELLO_PAYLOAD, OP_LOG_INFO, OP_LOG_READ, PROTOCOL, SAMPLE
from fswkit.autocode.recorder import Flight, Plan
from fswkit.link import wire
from fswkit.link.layout import from_dict
from fswkit.link.log import RX, LogWriter

MODES = {0: "idle (waiting for the trigger)", 1: "recording a flight", 2: "full", 3: "erasing"}
_INFO = struct.Struct("<BBHHHBHI")


def record_layout(app, p: Plan):
    """The layout a dumped flight's log is decoded with."""
    elements, off = [], 0
    for f in p.fields:
        elements.append({"name": f.name, "type": f.type.name, "offset": off, "region": "Record"})
        off += f.type.size
    rate = max(app.log.rates)
    states = {p.state_element: {str(i + 1): n for i, n in enumerate(p.states)}}
    return from_dict({
        "schema": p.hash, "name": f"{app.name} (flight record)", "sv_size": off, "time_unit": "ms",
        "rate": app.rate, "elements": elements, "regions": [{"name": "Record", "offset": 0, "size": off}],
        "streams": [{"region": "Record", "rate": str(rate), "batch": 1, "period": str(1000 / rate)}],
        "tasks": [], "writable": [], "states": states, "analog": {}, "health_payload": 34,
    })


def sample_payload(p: Plan, values: dict) -> bytes:
    out = b""
    for f in p.fields:
        v = values[f.name]
        out += struct.pack("<" + f.type.fmt, v if not f.type.is_int else int(v))
    return out


def write_flight(path: str, app, p: Plan, flight: Flight, *, force: bool = False) -> int:
    """Writes one flight as a link log; the samples written."""
    layout = record_layout(app, p)
    log = LogWriter(path, layout, force=force, source="fsw dump", clock="recorded", flight=flight.number)
    n = 0
    try:
        samples = flight.samples
        t_first = samples[0][0] if samples else 0
        # a hello first, as a live link begins: it names the layout (the log hash) the samples decode with
        hello = HELLO_PAYLOAD.pack(PROTOCOL, p.hash, t_first >> 32, 0, 0, 0, 0, 0, 0, 0)
        log.record(RX, t_first * 1_000_000, wire.downlink(HELLO, 0, t_first & 0xFFFFFFFF, hello))
        for t, values in samples:
            frame = wire.downlink(SAMPLE, (n + 1) & 0xFF, t & 0xFFFFFFFF, sample_payload(p, values))
            log.record(RX, t * 1_000_000, frame)
            n += 1
    except BaseException:
        log.close(keep=False)
        raise
    log.close()
    return n


def info(ack: dict) -> dict:
    """LOG_INFO's fields; DumpError when the answer is shorter than they are."""
    if len(ack["data"]) < _INFO.size:
        raise DumpError(f"a malformed answer to LOG_INFO ({len(ack['data'])} bytes, not {_INFO.size}): is the "
                        "firmware built by this kit's version from this project?")
    mode, flight, head, seq, slots, record, dropped, h = _INFO.unpack_from(ack["data"])
    return {"mode": mode, "mode_name": MODES.get(mode, f"mode {mode}"), "flight": flight, "head": head, "seq": seq,
            "slots": slots, "record": record, "dropped": dropped, "hash": h}


def slots_read(p: Plan, head: int | None) -> int:
    """How many record slots `read_image` reads: on an SPI NOR chip those
    before `head` (LOG_INFO's next record) and the one at it, else all."""
    return p.slots if head is None or p.store != "spi_nor" else min(p.slots, head + 1)


def read_image(command, p: Plan, tx_cap: int, progress=None, head: int | None = None) -> bytes:
    """The records' bytes, read over the link: `command(op, args)` sends a
    command and returns its ack's fields (fswkit.link.client.Ground.command).
    On an SPI NOR chip the records are the slots before `head` (LOG_INFO's
    next record) and the one at it: only those are read, and the rest of the
    image is blank (0xFF); an EEPROM is read whole."""
    room = tx_cap - 24 - tx_cap // 254
    chunk = max(1, min(p.record, room - 4))
    image = bytearray()
    last = slots_read(p, head)
    for slot in range(last):
        off = 0
        while off < p.record:
            n = min(chunk, p.record - off)
            ack = command(OP_LOG_READ, struct.pack("<HBB", slot, off, n))
            if ack["status"] != 0:
                raise DumpError(f"the target refused to read record {slot}: {ack['reason']}")
            data = ack["data"]
            got_slot, got_off, got_n = struct.unpack_from("<HBB", data) if len(data) >= 4 else (None, None, 0)
            if (got_slot, got_off) != (slot, off) or not 0 < got_n <= n or len(data) != 4 + got_n:
                raise DumpError(f"a malformed answer to reading record {slot} at byte {off}")
            image += data[4:]
            off += got_n
        if progress is not None:
            progress(slot + 1)
    return bytes(image) + b"\xff" * ((p.slots - last) * p.record)


class DumpError(Exception):
    """A dump that cannot go on, said in words."""


def query_info(command) -> dict:
    ack = command(OP_LOG_INFO, b"")
    if ack["status"] != 0:
        raise DumpError(f"the target has no flight recorder ({ack['reason']}): is it built from this project?")
    return info(ack)
