"""The parameter client tries a command the target answers BUSY again a
little later, until its deadline; when the target answered BUSY every
time, the client said "no answer from the target after 30 s", which sent
the team looking at the cable and the radio of a target that answered
every command. Now it says the target answered BUSY, and what that means."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest

from fswkit.link import wire
from fswkit.link.session import Event

RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"


class AlwaysBusy:
    """A target whose every acknowledgement is BUSY (simulated clock)."""

    def __init__(self):
        self.session = SimpleNamespace(hello=None, health=None)
        self.t = 0.0
        self.acks: list[Event] = []
        self.sent = 0

    def now(self) -> float:
        return self.t

    def send(self, data: bytes) -> None:
        body = wire.cobs_decode(data[1:-1])
        self.sent += 1
        self.acks.append(Event("ack", 0, 0, self.t, info={
            "cmd_seq": body[1] | body[2] << 8, "op": body[0], "status": 11, "status_name": "BUSY", "reason": "busy", "data": b""}))

    def events(self, wait: float):
        self.t += max(wait, 0.001)
        out, self.acks = self.acks, []
        return out


@pytest.mark.parametrize("what", ["set", "save"])
def test_a_target_answering_busy_is_said_to_be_busy(what):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.params import app_parameters
    from fswkit.param.client import ParamClient, ParamError
    from fswkit.target.build import load

    params = app_parameters(load(str(RIG), Diagnostics()))
    t = AlwaysBusy()
    client = ParamClient(t, params, 64, deadline=3.0)
    with pytest.raises(ParamError) as e:
        client.set({"OPEN_AT": 700.0}) if what == "set" else client.run([(0x08, b"")])
    words = str(e.value)
    assert t.sent > 10  # it did try again, and every try was answered
    assert "no answer" not in words, words
    assert "answered BUSY" in words and "3 s" in words and "writing" in words, words
