"""The wire format on the host: COBS and CRC as the firmware computes them,
any chunking decodes the same, garbage resynchronises at the next frame."""

from __future__ import annotations

import random
from binascii import crc_hqx

from hypothesis import given, settings
from hypothesis import strategies as st

from fswkit.link import wire


def test_crc_is_the_firmwares():
    assert wire.crc16(b"123456789") == 0x29B1 == crc_hqx(b"123456789", 0xFFFF)
    body = b"\x81\x05\x00\x00\x00\x00abc"
    framed = wire.cobs_decode(wire.frame(body)[:-1])
    assert framed[:-2] == body and wire.crc16(framed) == 0  # high byte first: residue 0


@given(st.binary(max_size=700))
@settings(max_examples=300, deadline=None)
def test_cobs_roundtrip(data):
    enc = wire.cobs_encode(data)
    assert 0 not in enc
    assert len(enc) <= len(data) + len(data) // 254 + 1
    assert wire.cobs_decode(enc) == data


def test_cobs_rejects_bad_chains():
    assert wire.cobs_decode(b"\x05\x01\x02") is None  # a block past the end
    assert wire.cobs_decode(b"\x03\x00\x01") is None  # a zero inside
    assert wire.cobs_decode(b"") is None
    assert wire.cobs_decode(b"\xff" + b"\x01" * 254) == b"\x01" * 254  # no trailing empty block
    assert wire.cobs_decode(b"\xff" + b"\x01" * 254 + b"\x01") == b"\x01" * 254


def _stream(n: int, rnd: random.Random) -> tuple[bytes, list[bytes]]:
    frames = [wire.downlink(0x80, i, i * 10, bytes(rnd.choice((0, 1, rnd.randrange(256))) for _ in range(32)))
              for i in range(n)]
    return b"".join(frames), frames


@given(st.lists(st.integers(min_value=1, max_value=300), min_size=1, max_size=40))
@settings(max_examples=60, deadline=None)
def test_any_chunking_gives_the_same_frames(cuts):
    data, _ = _stream(600, random.Random(3))  # past the bulk threshold: both decoders run
    whole = wire.Deframer()
    expect = whole.feed(data)
    d = wire.Deframer()
    got, at, i = [], 0, 0
    while at < len(data):
        n = cuts[i % len(cuts)] * (50 if i % 7 == 0 else 1)
        got += d.feed(data[at:at + n])
        at += n
        i += 1
    assert got == expect and len(got) == 600
    assert d.stats == whole.stats


def test_garbage_then_frames_resynchronise():
    rnd = random.Random(5)
    data, frames = _stream(50, rnd)
    garbage = bytes(rnd.randrange(1, 256) for _ in range(300))  # no delimiter: the first frame merges with it
    d = wire.Deframer()
    got = d.feed(garbage + data)
    assert [f[1] for f in got] == list(range(1, 50))
    assert d.stats.leading == 1 and d.stats.crc_errors == 0 and d.stats.framing_errors == 0
    d2 = wire.Deframer()
    got2 = d2.feed(garbage + b"\0" + data)  # garbage ended by a delimiter: nothing lost
    assert [f[1] for f in got2] == list(range(50))


def test_uplink_frames_start_with_a_delimiter():
    f = wire.uplink(wire.OP_SET, 0x1234, b"\x04\x00\x01")
    assert f[0] == 0 and f[-1] == 0
    body = wire.cobs_decode(f[1:-1])
    assert body[:3] == bytes((wire.OP_SET, 0x34, 0x12)) and wire.crc16(body) == 0
