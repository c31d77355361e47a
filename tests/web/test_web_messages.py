"""What the page gets for each frame is encoded once, in the station's
reader, for every browser (fswkit.web.source._text): the same message as
`_message` builds, as JSON the browser's parser takes — a sample frame of
finite values straight, one with a NaN or an infinity through `_message`
(null, "inf", "-inf"), and the other frames as `_message` has them."""

from __future__ import annotations

import json
import math

from fswkit.link.session import Event, Session
from fswkit.web.source import _message, _text
from support.linkstream import TANK, layout_of, stream


def strict(text: str):
    """JSON as a browser parses it: no NaN, no Infinity."""
    def refuse(name):
        raise ValueError(f"not JSON: {name}")
    return json.loads(text, parse_constant=refuse)


def test_each_frame_is_the_message_the_page_always_got():
    layout = layout_of(TANK)
    s = Session(layout)
    evs = []
    for f in stream(layout, 0, 120, hello_first=True):
        evs += s.feed(f, 1_700_000_000.25)
    assert {ev.kind for ev in evs} >= {"hello", "health", "sample"}
    for ev in evs:
        assert strict(_text(ev, layout)) == _message(ev, layout)


def test_values_json_cannot_hold_go_as_they_always_went():
    layout = layout_of(TANK)
    names = layout.streams[0].region.names
    odd = [math.nan, math.inf, -math.inf, 1.5, 7] + [0.0] * (len(names) - 5)
    ev = Event("sample", 12, 340, 1_700_000_000.5, 0, [(330, tuple(odd[:len(names)])), (340, (2.5,) * len(names))])
    got = strict(_text(ev, layout))
    assert got == _message(ev, layout)
    assert got["rows"][0][1:4] == [None, "inf", "-inf"][:len(names)]
    assert got["names"] == list(names) and got["seq"] == 12 and got["host"] == 1_700_000_000.5


def test_an_acks_bytes_go_as_hex():
    layout = layout_of(TANK)
    ev = Event("ack", 3, 40, 1.0, info={"cmd_seq": 2, "op": 1, "status": 0, "data": b"\x01\xab"})
    assert strict(_text(ev, layout))["info"]["data"] == "01ab"
