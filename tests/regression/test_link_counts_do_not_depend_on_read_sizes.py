"""The link decoder's counts are a property of the byte stream, not of how
the port happened to hand it over: the same bytes fed 1, 7 or 4096 at a
time or all at once give the same frames and the same errors, and a run of
bytes longer than the longest frame the layout allows is counted oversized
exactly once, wherever it is (the first bytes seen, between two frames,
unterminated at the end). A stream of pure text (a board printing, the
wrong baud rate) shows in the summary as oversized, not as a clean link."""

from __future__ import annotations

import dataclasses

import pytest
from support.linkstream import TANK, PtyTarget, layout_of, stream

from fswkit.link import wire
from fswkit.link.session import Session, max_frame
from fswkit.ground.monitor import summary


@pytest.fixture(scope="module")
def layout():
    return layout_of(TANK)


def _text(n: int) -> bytes:
    line = b"T+0012.345 alt=351.4 m vel=-5.5 m/s state=Apogee\r\n"
    return (line * (n // len(line) + 1))[:n]


def _feed(layout, data: bytes, chunk: int | None) -> tuple:
    s = Session(layout)
    if chunk is None:
        s.feed(data)
    else:
        for i in range(0, len(data), chunk):
            s.feed(data[i:i + chunk])
    return dataclasses.asdict(s.deframer.stats), dataclasses.asdict(s.stats)


def _mixed(layout, long_run: int) -> tuple[bytes, int]:
    """Text first (joined a board printing), frames, runs of garbage just
    within and just beyond the bound, a long run, and text unterminated at
    the end; with how many runs are longer than any frame."""
    mx = max_frame(layout)
    frames = stream(layout, 1000, 120, hello_first=True)
    garbage = bytes(range(1, 256)) * (mx // 255 + 2)
    parts = [_text(3 * mx), b"\0", *frames[:30],
             garbage[:mx], b"\0", *frames[30:60],  # within the bound: a framing or CRC error
             garbage[:mx + 1], b"\0", *frames[60:90],  # one byte beyond it: oversized
             _text(long_run), b"\0", *frames[90:],
             _text(2 * mx)]
    return b"".join(parts), 4


@pytest.mark.parametrize("chunk", [1, 7, 4096])
def test_counts_are_the_same_whatever_the_read_sizes(layout, chunk):
    data, runs = _mixed(layout, 20_000)
    whole = _feed(layout, data, None)
    assert whole[0]["oversized"] == runs and whole[1]["frames"] == 120, whole
    assert whole[0]["framing_errors"] + whole[0]["crc_errors"] == 1 and whole[0]["leading"] == 0, whole
    assert _feed(layout, data, chunk) == whole


def test_a_megabyte_without_a_delimiter_is_oversized_in_one_read(layout):
    frames = stream(layout, 0, 40, hello_first=True)
    data = b"".join(frames[:20]) + _text(1 << 20) + b"\0" + b"".join(frames[20:])
    whole, chunked = _feed(layout, data, None), _feed(layout, data, 4096)
    assert whole == chunked
    assert whole[0]["oversized"] == 1 and whole[0]["framing_errors"] == 0 and whole[0]["crc_errors"] == 0
    assert whole[1]["frames"] == 40


def test_a_run_longer_than_a_frame_never_yields_a_frame(layout):
    """A delimiter-free run that happens to end in a valid CRC is still no
    frame when it is longer than any frame can be (no accept check here)."""
    mx = max_frame(layout)
    body = bytes((wire.HELLO, 0, 1, 2, 3, 4)) + bytes(range(1, 251)) * (mx // 250 + 2)
    data = b"\0" + wire.frame(body)
    assert len(data) - 2 > mx
    for chunk in (None, 7):
        d = wire.Deframer(max_frame=mx)
        out = d.feed(data) if chunk is None else [f for i in range(0, len(data), chunk)
                                                  for f in d.feed(data[i:i + chunk])]
        assert out == [] and d.stats.oversized == 1 and d.stats.frames == 0


def test_pure_text_shows_in_the_summary(layout):
    s = Session(layout)
    text = _text(4 << 20)
    for i in range(0, len(text), 1024):  # as the monitor reads a port
        s.feed(text[i:i + 1024])
    assert s.stats.frames == 0
    assert s.deframer.stats.oversized >= 1
    assert f"{s.deframer.stats.oversized} oversized" in summary(s)


class TextPty(PtyTarget):
    """A board on a pseudo-terminal printing text, no frame at all."""

    def __init__(self):
        super().__init__()
        self.start()

    def _run(self) -> None:
        import os
        import select

        text = _text(4096)
        while not self._stop.is_set():
            r, w, _ = select.select([self.master], [self.master], [], 0.05)
            try:
                if r:
                    os.read(self.master, 4096)  # what the ground sends is dropped
                if w:
                    os.write(self.master, text)
            except OSError:
                return
            self._stop.wait(0.005)


@pytest.mark.parametrize("command", ["monitor", "cmd"])
def test_no_hello_from_a_port_of_text_says_what_was_read(monkeypatch, command):
    from conftest import run_fsw

    from fswkit.link.client import Ground

    handshake = Ground.handshake
    monkeypatch.setattr(Ground, "handshake", lambda self, timeout=3.0, on_event=None:
                        handshake(self, timeout=0.3, on_event=on_event))
    with TextPty() as board:
        argv = (["monitor", str(TANK), "--headless"] if command == "monitor" else ["cmd", "ping", "-p", str(TANK)])
        r = run_fsw(*argv, "--port", board.port)
    assert r.code == 1 and "no hello from the target" in r.err, r.err
    assert "0 frames" in r.err and " 0 oversized" not in r.err and "oversized" in r.err, r.err
