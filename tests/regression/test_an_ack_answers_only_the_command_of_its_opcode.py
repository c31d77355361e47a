"""A command's acknowledgement was matched by its number alone. A late
acknowledgement of another command of the same number (the station's
`hello`, given up under load, then answered; a command of an earlier
numbering) was taken for the answer of the command waiting: the
parameters' page read a `hello` acknowledgement as the parameter table's
("the target's parameter table (hash 0x00004001, 128 parameters) is not
the one of ...", seen in a fresh-clone CI run). The target echoes each
command's opcode in its acknowledgement: an acknowledgement now answers
only the command of its number *and* its opcode, in the link's client, the
ground station and the parameters' pipeline."""

from __future__ import annotations

import threading
import time

from fswkit.link import wire
from fswkit.link.client import Ground
from fswkit.link.session import ACK_PAYLOAD, Session
from support.linkstream import TANK, hello, layout_of


def ack(seq: int, op: int, cmd_seq: int, data: bytes = b"") -> bytes:
    return wire.downlink(wire.ACK, seq, 1000 + seq, ACK_PAYLOAD.pack(cmd_seq, op, 0, cmd_seq) + data)


def command_seq(frame: bytes) -> tuple[int, int]:
    body = wire.cobs_decode(frame.strip(b"\0"))
    return body[0], body[1] | body[2] << 8


class Answering:
    """A port whose target answers each command twice: first as if it were a
    command of another opcode with the same number (a late acknowledgement),
    then as itself."""

    def __init__(self, layout, on_bytes=None):
        self.inbox = bytearray(hello(layout, 1, 1000))
        self.n = 2
        self.on_bytes = on_bytes  # the station reads by itself: its bytes are handed to it

    def _give(self, data: bytes):
        if self.on_bytes is not None:
            self.on_bytes(data)
        else:
            self.inbox += data

    def write(self, data: bytes):
        op, seq = command_seq(data)
        other = wire.OP_HELLO if op != wire.OP_HELLO else wire.OP_SET
        stale, right = ack(self.n, other, seq, b"\x01\x40\x00\x00\x80"), ack(self.n + 1, op, seq)
        self.n += 2
        self._give(stale + right)
        return len(data)

    def flush(self):
        pass

    @property
    def in_waiting(self):
        return len(self.inbox)

    def read(self, n=1):
        out = bytes(self.inbox[:n])
        del self.inbox[:n]
        return out


def test_the_links_client_takes_only_its_opcodes_acknowledgement():
    layout = layout_of(TANK)
    g = Ground(Answering(layout), Session(layout))
    a = g.command(wire.OP_SET, b"\x00\x01", tries=1, timeout=1.0)
    assert a["op"] == wire.OP_SET, a


def test_the_station_takes_only_its_opcodes_acknowledgement():
    from fswkit.ground.station import Station

    layout = layout_of(TANK)
    st = Station(layout, str(TANK), "/nonexistent/port", 115200, serve=False)
    st.port = Answering(layout, on_bytes=lambda data: threading.Thread(target=st._received, args=(data,)).start())
    st._received(hello(layout, 1, 1000))
    a = st.command("test", wire.OP_SET, b"\x00\x01", tries=1, timeout=1.0)
    assert a["op"] == wire.OP_SET, a
    time.sleep(0.05)


def test_the_parameters_pipeline_takes_only_its_opcodes_acknowledgement():
    from fswkit.param.client import OP_PARAM_INFO, ParamClient

    layout = layout_of(TANK)
    port = Answering(layout)

    class Transport:
        session = Session(layout)

        def now(self):
            return time.monotonic()

        def send(self, data):
            port.write(data)

        def events(self, wait):
            return self.session.feed(port.read(port.in_waiting), time.time()) if port.in_waiting else []

    c = ParamClient(Transport(), (), tx_cap=32, timeout=0.5, deadline=3.0)
    a = c.run([(OP_PARAM_INFO, b"")])[0]
    assert a["op"] == OP_PARAM_INFO, a
