"""The link's wire format (docs/telemetry.md): COBS framing with a 0x00
delimiter, CRC-16/CCITT-FALSE (binascii.crc_hqx, init 0xFFFF) sent high byte
first, frame types, uplink opcodes and acknowledgement codes. No schema
here: this layer turns bytes into verified frames and counts what it threw
away."""

from __future__ import annotations

import struct
from binascii import crc_hqx
from dataclasses import dataclass

# The numbers of the protocol are written once, in autocode (the generator
# sizes the firmware's buffers from them); the ground tools read them here.
from fswkit.autocode.protocol import (ACK, CRC, CRC_INIT, HEADER, HEALTH, HELLO, OP_HELLO, OP_MODE, OP_NAMES,
                                      OP_PING, OP_SET, OP_SNAPSHOT, PROTOCOL, SAMPLE, SNAPSHOT, STATUS, crc16,
                                      encoded_max)

__all__ = ["ACK", "CRC", "CRC_INIT", "HEADER", "HEALTH", "HELLO", "OP_HELLO", "OP_MODE", "OP_NAMES", "OP_PING",
           "OP_SET", "OP_SNAPSHOT", "PROTOCOL", "SAMPLE", "SNAPSHOT", "STATUS",
           "BULK", "Deframer", "WireStats", "cobs_decode", "cobs_encode", "crc16", "downlink", "encoded_size",
           "frame", "uplink"]

_U32 = struct.Struct("<I")


def cobs_encode(data: bytes) -> bytes:
    """COBS encoding of `data` (no delimiter), exactly as the firmware's
    encoder: a full block of 254 bytes is always followed by a new block."""
    out = bytearray()
    block = bytearray()
    for b in data:
        if b == 0:
            out.append(len(block) + 1)
            out += block
            block.clear()
        else:
            block.append(b)
            if len(block) == 254:
                out.append(0xFF)
                out += block
                block.clear()
    out.append(len(block) + 1)
    out += block
    return bytes(out)


def cobs_decode(enc: bytes) -> bytes | None:
    """The bytes a COBS block chain (no zero bytes) stands for, or None when
    a block runs past the end or a zero byte appears."""
    n = len(enc)
    if n == 0 or 0 in enc:
        return None
    # Each code byte after the first stands where a zero was (unless the block
    # before it was a full one of 254 bytes): walk the chain, patch zeros in.
    i = enc[0]
    if i == n:  # one block: the frame had no zero byte
        return enc[1:] if i != 0xFF else enc[1:]
    out = bytearray(enc)
    full = i == 0xFF
    cut = []
    while i < n:
        c = enc[i]
        if full:
            cut.append(i)
        else:
            out[i] = 0
        full = c == 0xFF
        i += c
    if i != n:
        return None
    if cut:
        for p in reversed(cut):
            del out[p]
    del out[0]
    return bytes(out)


def frame(body: bytes) -> bytes:
    """A complete wire frame: body + CRC (high byte first), COBS, delimiter."""
    crc = crc16(body)
    return cobs_encode(body + bytes((crc >> 8, crc & 0xFF))) + b"\0"


def downlink(ftype: int, seq: int, time32: int, payload: bytes) -> bytes:
    """A target frame (for tests and simulations of the firmware)."""
    return frame(bytes((ftype, seq & 0xFF)) + _U32.pack(time32 & 0xFFFFFFFF) + payload)


def uplink(op: int, seq: int, args: bytes = b"") -> bytes:
    """A command frame, with a leading delimiter that ends any garbage the
    target may hold."""
    return b"\0" + frame(bytes((op, seq & 0xFF, (seq >> 8) & 0xFF)) + args)


@dataclass
class WireStats:
    bytes: int = 0
    frames: int = 0  # verified frames
    crc_errors: int = 0  # decoded, CRC mismatch
    framing_errors: int = 0  # not a COBS block chain, or shorter than a header + CRC
    leading: int = 0  # bytes before the first delimiter that were not a frame (joined mid-frame)
    invalid: int = 0  # verified, but of a type or length the schema does not allow
    oversized: int = 0  # runs of bytes without a delimiter longer than any frame: dropped unread, once each


def encoded_size(body: int) -> int:
    """The most bytes a frame body of `body` bytes takes on the wire, CRC
    and COBS included, without its delimiter."""
    return encoded_max(body + CRC) - 1  # no delimiter


class Deframer:
    """Bytes in (any chunking), verified frame bodies out: (type, seq, time32,
    payload). A corrupted frame costs only itself: decoding resumes at the
    next delimiter. The bytes held between two delimiters are bounded by
    `max_frame` (the longest encoded frame): a longer run is no frame, and
    is dropped up to the next delimiter and counted (`oversized`) once,
    wherever it is (the first bytes seen too), so the work stays
    proportional to the bytes fed, whatever they are. Every count depends
    on the bytes alone, not on how they were split into calls."""

    def __init__(self, accept=None, max_frame: int = 1 << 16):
        self.stats = WireStats()
        self._accept = accept  # (type, body) -> bool: a verified frame the schema allows
        self._max = max_frame
        self._tail = b""
        self._synced = False  # bytes before the first delimiter are a partial frame
        self._skipping = False  # inside an oversized run: drop up to the next delimiter

    def resync(self) -> None:
        """Forgets a partial frame (the link was cut): the bytes up to the
        next delimiter are again the tail of a frame never seen whole."""
        self._tail = b""
        self._synced = False
        self._skipping = False

    def feed(self, data: bytes) -> list[tuple[int, int, int, bytes]]:
        self.stats.bytes += len(data)
        if self._skipping:
            z = data.find(b"\0")
            if z < 0:
                return []
            self._skipping = False
            self._synced = True  # the next byte starts a frame
            data = data[z + 1:]
        buf = self._tail + data if self._tail else data
        end = buf.rfind(b"\0")
        if end < 0:
            self._tail = buf
            self._bound()
            return []
        self._tail = buf[end + 1:]
        first = not self._synced
        self._synced = True
        self._bound()
        mx = self._max
        if end >= BULK:
            encs, bodies = _bulk_decode(buf, end, mx)
        else:
            encs = buf[:end].split(b"\0")
            if end > mx:  # a run longer than any frame may lie between two delimiters: not decoded
                bodies = [None if len(e) > mx else cobs_decode(e) if e else b"" for e in encs]
            else:
                bodies = [cobs_decode(e) if e else b"" for e in encs]
        return self._verify(encs, bodies, first)

    def _bound(self) -> None:
        # a run too long for a frame, even as the first bytes seen (joined
        # in the middle of text or noise): counted once, dropped to its end
        if len(self._tail) > self._max:
            self.stats.oversized += 1
            self._tail = b""
            self._skipping = True

    def _verify(self, encs, bodies, first: bool) -> list[tuple[int, int, int, bytes]]:
        st = self.stats
        out = []
        append = out.append
        unpack = _U32.unpack_from
        accept = self._accept
        for enc, body in zip(encs, bodies):
            if not enc:
                first = False
                continue
            if body is None or len(body) < HEADER + 2 or crc_hqx(body, CRC_INIT) != 0:
                if body is None and len(enc) > self._max:  # as _bound counts it when read in pieces
                    st.oversized += 1
                elif first:  # the stream may begin mid-frame: not an error
                    st.leading += 1
                elif body is None or len(body) < HEADER + 2:
                    st.framing_errors += 1
                else:
                    st.crc_errors += 1
                first = False
                continue
            first = False
            if accept is not None and not accept(body[0], body):
                st.invalid += 1
                continue
            append((body[0], body[1], unpack(body, 2)[0], body[HEADER:-2]))
        st.frames += len(out)
        return out


BULK = 8192  # bytes from which a feed decodes its frames with numpy


def _bulk_decode(buf: bytes, end: int, limit: int):
    """The frames of buf[:end] (end: a delimiter) and their COBS decodings,
    all frames at once: the block chains are walked in parallel, one numpy
    step per block; frames with a full 254-byte block, or longer chains,
    take the plain path; runs longer than `limit` are not decoded (None)."""
    import numpy as np

    arr = np.frombuffer(buf, dtype=np.uint8, count=end + 1)
    z = np.flatnonzero(arr == 0)
    starts = np.empty(len(z), dtype=np.int64)
    starts[0] = 0
    starts[1:] = z[:-1] + 1
    ends = z.astype(np.int64)
    pos = starts.copy()
    slow = np.zeros(len(z), dtype=bool)
    zeros = []
    act = np.flatnonzero(ends > starts)
    rounds = 0
    while act.size:
        p = pos[act]
        c = arr[p].astype(np.int64)
        if rounds:
            zeros.append(p)
        slow[act[c == 0xFF]] = True
        p = p + c
        pos[act] = p
        act = act[p < ends[act]]
        rounds += 1
        if rounds == 256:
            slow[act] = True
            break
    bad = (pos != ends) & (ends > starts)  # a block ran past the delimiter
    out = arr.copy()
    if zeros:
        out[np.concatenate(zeros)] = 0
    outb = out.tobytes()
    s_l, e_l, slow_l, bad_l = starts.tolist(), ends.tolist(), slow.tolist(), bad.tolist()
    encs, bodies = [], []
    for i in range(len(s_l)):
        a, b = s_l[i], e_l[i]
        enc = buf[a:b]
        encs.append(enc)
        if a == b:
            bodies.append(b"")
        elif b - a > limit:
            bodies.append(None)
        elif slow_l[i]:
            bodies.append(cobs_decode(enc))
        elif bad_l[i]:
            bodies.append(None)
        else:
            bodies.append(outb[a + 1:b])
    return encs, bodies
