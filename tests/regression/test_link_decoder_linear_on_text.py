"""The link decoder's time grows with its input, not with its square, on
bytes that hold no frame delimiter (a board printing text, noise on an
idle line): a run of bytes longer than the longest frame the layout allows
is dropped and counted, never kept growing — in the session the live
monitor feeds chunk by chunk, and in the log tools."""

from __future__ import annotations

import time

import pytest
from support.linkstream import TANK, layout_of, stream

from fswkit.link.session import Session

CHUNK = 1024  # what a serial port's read hands over at a time


@pytest.fixture(scope="module")
def layout():
    return layout_of(TANK)


def _text(n: int) -> bytes:
    line = b"T+0012.345 alt=351.4 m vel=-5.5 m/s state=Apogee  # a board printing text\r\n"
    return (line * (n // len(line) + 1))[:n]


def _decode_seconds(layout, data: bytes) -> tuple[float, Session]:
    s = Session(layout)
    t0 = time.process_time()
    for i in range(0, len(data), CHUNK):
        s.feed(data[i:i + CHUNK])
    return time.process_time() - t0, s


def test_text_without_delimiters_decodes_in_linear_time(layout):
    small = min(_decode_seconds(layout, _text(1 << 20))[0] for _ in range(2))
    large, s = _decode_seconds(layout, _text(4 << 20))
    # linear: about 4 times as long; quadratic: about 16 times
    assert large <= 8 * max(small, 0.005), (small, large)
    big, s = _decode_seconds(layout, _text(16 << 20))
    assert big < 10.0, big
    st = s.deframer.stats
    assert st.bytes == 16 << 20 and s.stats.frames == 0
    assert st.oversized + st.leading == 1  # dropped as one run too long for a frame, and counted


def test_frames_after_text_still_decode(layout):
    frames = stream(layout, 1000, 60, hello_first=True)
    data = b"".join(frames[:30]) + _text(300_000) + b"\0" + b"".join(frames[30:])
    s = Session(layout)
    for i in range(0, len(data), CHUNK):
        s.feed(data[i:i + CHUNK])
    assert s.stats.frames == 60 and s.stats.lost == 0
    assert s.deframer.stats.oversized == 1 and s.deframer.stats.crc_errors == 0


def test_longest_frame_is_not_oversized(layout):
    # a snapshot, hello or health frame, or a full batch: each passes the bound
    frames = stream(layout, 0, 300, hello_first=True)
    s = Session(layout)
    for f in frames:
        for b in range(0, len(f), 3):
            s.feed(f[b:b + 3])
    assert s.stats.frames == 300 and s.deframer.stats.oversized == 0
