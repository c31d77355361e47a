"""Flight-recorder stores made on the host, byte for byte as the firmware
writes them (docs/recorder.md, "The record format"), and a target that
answers `fsw dump`'s LOG_INFO and LOG_READ from one: the dump's decoding
and reporting tested without building or running firmware."""

from __future__ import annotations

import struct
from contextlib import contextmanager

from fswkit.autocode.protocol import OP_LOG_ERASE, OP_LOG_INFO, OP_LOG_READ, crc16
from fswkit.autocode.recorder import DATA, ESCAPE, START, TAIL, Plan


def seal(p: Plan, body: bytes, period: int) -> bytes:
    assert len(body) <= p.record - TAIL
    tail3 = struct.pack("<HB", period, len(body))
    pad = b"\x00" * (p.record - TAIL - len(body))
    return body + pad + tail3 + struct.pack("<H", crc16(body + tail3))


def start_record(p: Plan, seq: int, flight: int, t0: int, log_hash: int | None = None, schema: int = 0) -> bytes:
    """A flight's start record (log_hash: the plan's unless given)."""
    h = p.hash if log_hash is None else log_hash
    return seal(p, struct.pack("<BHBIII", START, seq, flight, t0, schema, h), 0)


def data_record(p: Plan, seq: int, flight: int, t0: int, period: int, samples: list[list[bytes]]) -> bytes:
    """A record of samples: each sample the fields' absolute bytes, in the
    plan's field order (a delta or quant field: its count)."""
    body = struct.pack("<BHBI", DATA, seq, flight, t0) + b"".join(samples[0])
    prev = samples[0]
    for s in samples[1:]:
        for k in range(p.n_hold):
            if s[k] != prev[k]:
                assert p.escape
                body += bytes((ESCAPE, k)) + s[k]
        for k in range(p.n_hold, len(p.fields)):
            f = p.fields[k]
            if f.enc == "delta":
                d = int.from_bytes(s[k], "little", signed=True) - int.from_bytes(prev[k], "little", signed=True)
                assert -127 <= d <= 127
                body += struct.pack("<b", d)
            else:
                body += s[k]
        prev = s
    return seal(p, body, period if len(samples) > 1 else 0)


def image(p: Plan, records: dict[int, bytes], blank: int = 0x00) -> bytes:
    """The store: `records` by slot, every other slot `blank` bytes."""
    out = bytearray(bytes((blank,)) * p.size)
    for slot, raw in records.items():
        out[slot * p.record:(slot + 1) * p.record] = raw
    return bytes(out)


class FakeGround:
    """Answers LOG_INFO from `info` and LOG_READ from `store`; `erased` is
    set by a LOG_ERASE. `on_read(slot)` may change the store as a recording
    target would."""

    def __init__(self, p: Plan, store: bytes, *, mode: int = 0, flight: int = 1, head: int = 0, seq: int = 0,
                 on_read=None):
        self.p, self.store, self.mode, self.flight, self.head, self.seq = p, bytearray(store), mode, flight, head, seq
        self.on_read = on_read
        self.erased = False
        self.infos = 0

    def command(self, op, a, tries=5, timeout=0.5):
        p = self.p
        if op == OP_LOG_INFO:
            self.infos += 1
            data = struct.pack("<BBHHHBHI", self.mode, self.flight, self.head, self.seq, p.slots, p.record, 0, p.hash)
            return {"status": 0, "data": data, "reason": ""}
        if op == OP_LOG_READ:
            slot, off, n = struct.unpack("<HBB", a)
            if self.on_read is not None and off == 0:
                self.on_read(self, slot)
            at = slot * p.record + off
            return {"status": 0, "data": struct.pack("<HBB", slot, off, n) + bytes(self.store[at:at + n]),
                    "reason": ""}
        if op == OP_LOG_ERASE:
            self.erased = True
            return {"status": 0, "data": b"", "reason": ""}
        raise AssertionError(f"op {op}")

    def close(self):
        pass


@contextmanager
def fake_target(monkeypatch, ground: FakeGround):
    """`fsw dump` talks to `ground` instead of opening its port."""
    import fswkit.cli.common as common

    def talk_on_link(args, layout, baud, say, talk, refusals):
        try:
            return talk(ground)
        except refusals as e:
            say(str(e))
            return 1

    monkeypatch.setattr(common, "talk_on_link", talk_on_link)
    yield ground
