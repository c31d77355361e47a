"""`fsw param load` takes a NO_LOAD answer to its COMMIT as the sign that an
earlier copy of the COMMIT was applied and its acknowledgement lost. When
the COMMIT went once and was answered NO_LOAD, no copy was applied: the
load was closed before it came (the target restarted during the load, its
brown-out at the igniter's relay, say), and the client went on to "verify"
and said the live CRC was not the file's, in numbers. Now it says the
target lost the load before its COMMIT, that nothing was loaded, and to
run the load again."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest

from fswkit.autocode.protocol import OP_PARAM_COMMIT, OP_PARAM_GET, OP_PARAM_INFO, PARAM_INFO
from fswkit.link import wire
from fswkit.link.session import Event

RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"


class Restarted:
    """A target that acknowledges everything, but has lost the open load by
    the COMMIT (it restarted): NO_LOAD, and its defaults live."""

    def __init__(self, params):
        from fswkit.autocode.params import default_block, param_hash
        from fswkit.autocode.protocol import crc16

        self.session = SimpleNamespace(hello=None, health=None)
        self.t = 0.0
        self.acks: list[Event] = []
        self.block = default_block(params)
        self.info = PARAM_INFO.pack(1, 0, crc16(self.block), len(params), param_hash(params))

    def now(self) -> float:
        return self.t

    def send(self, data: bytes) -> None:
        body = wire.cobs_decode(data[1:-1])
        op, seq, args = body[0], body[1] | body[2] << 8, body[3:-2]
        status, out = 0, b""
        if op == OP_PARAM_COMMIT:
            status = 12
        elif op == OP_PARAM_INFO:
            out = self.info
        elif op == OP_PARAM_GET:
            out = bytes(args[:2]) + self.block
        self.acks.append(Event("ack", 0, 0, self.t, info={
            "cmd_seq": seq, "op": op, "status": status, "status_name": {0: "OK", 12: "NO_LOAD"}[status], "reason": "",
            "data": out}))

    def events(self, wait: float):
        self.t += max(wait, 0.001)
        out, self.acks = self.acks, []
        return out


def test_a_commit_answered_no_load_at_once_says_the_load_was_lost():
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.params import app_parameters
    from fswkit.param.client import ParamClient, ParamError
    from fswkit.target.build import load

    params = app_parameters(load(str(RIG), Diagnostics()))
    client = ParamClient(Restarted(params), params, 64, deadline=5.0)
    with pytest.raises(ParamError) as e:
        client.load({"OPEN_AT": 650.0})
    words = str(e.value)
    assert "the target lost the load before its COMMIT" in words and "nothing was loaded" in words, words
    assert "did not verify" not in words, words
