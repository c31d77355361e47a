"""A long session grew two things without bound. The station keeps the
bytes after the last frame delimiter (`_carry`) to hand its clients whole
frames; a port that brings no delimiter — a board flashed with another
program printing text, a baud rate that is not the board's — made it
every byte read since, copied again at every pass (at 115200 baud, 40 MB
an hour, and the copying at 50 passes a second took the station's CPU).
And a session kept every acknowledgement the target ever sent
(`Session.acks`), for the whole session. Now what is held for the clients
is never more than a run longer than any frame (the decoder drops such a
run too, counted `oversized`), the clients still get every frame whole
once delimiters come, and a session keeps its latest acknowledgements."""

from __future__ import annotations

import base64
import json

from support.linkstream import TANK, layout_of, sample, stream

from fswkit.autocode.protocol import ACK_PAYLOAD
from fswkit.ground.station import Station
from fswkit.link import wire
from fswkit.link.session import Session, max_frame


class Client:
    """A local client as the station sees it: the lines it is sent."""

    def __init__(self):
        self.lines: list[bytes] = []

    def put(self, line: bytes) -> None:
        self.lines.append(line)


def test_text_without_delimiters_is_not_held_without_bound(tmp_path, monkeypatch):
    monkeypatch.setenv("FSW_RUNTIME_DIR", str(tmp_path / "run"))
    layout = layout_of(TANK)
    st = Station(layout, "tank", "loop://", 115200, serve=False)
    client = Client()
    st._clients.add(client)
    text = b"sensor read ok, pressure 812.5 psi\r\n" * 16
    for _ in range(2000):  # 1.2 MB of a board printing text
        st._received(text)
    assert len(st._carry) <= max_frame(layout) + 1, len(st._carry)
    # delimiters come again: the client decodes every frame of them whole
    frames = stream(layout, 7000, 60, hello_first=True)
    st._received(b"\0" + b"".join(frames))
    s = Session(layout)
    for msg in map(json.loads, client.lines):
        if msg["t"] == "rx":
            s.feed(base64.b64decode(msg["d"]))
    assert s.stats.frames == 60, s.stats
    assert s.deframer.stats.oversized >= 1


def test_a_session_keeps_its_latest_acknowledgements_not_all(tmp_path):
    layout = layout_of(TANK)
    s = Session(layout)
    s.feed(stream(layout, 0, 1, hello_first=True)[0])
    for n in range(1, 20001):
        s.feed(wire.downlink(wire.ACK, n, 10 * n, ACK_PAYLOAD.pack(n & 0xFFFF, wire.OP_HELLO, 0, n & 0xFFFF)))
    assert s.stats.frames == 20001
    assert len(s.acks) <= 1024
    assert s.acks[-1]["cmd_seq"] == 20000 & 0xFFFF
    s.feed(sample(layout, 20001, 200010))
    assert s.stats.lost == 0
