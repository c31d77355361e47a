"""A local client of `fsw ground` (its socket serves the kit's tools)
whose line is JSON but not an object (`[1]`), nests deeper than the JSON
reader recurses, or asks for a command numbered `1e400`, ended the client's
thread with a traceback on the station's console (AttributeError,
RecursionError, OverflowError). Each is answered with an error, and the
client goes on being served."""

from __future__ import annotations

import json
import socket

from conftest import EXAMPLES
from support.linkfw import tank_layout

from fswkit.ground.station import Station, _Client


class Recorded(_Client):
    """A client whose answers are kept in a list, in the order sent (the
    welcome goes to its queue)."""

    def __init__(self, *a):
        super().__init__(*a)
        self.sent: list[dict] = []

    def put(self, line: bytes) -> None:
        self.sent.append(json.loads(line))


def served(lines: list[bytes]) -> list[dict]:
    """What the station answers a client that sends `lines` and hangs up."""
    st = Station(tank_layout(), str(EXAMPLES / "tank"), "/dev/null", 115200, serve=False)
    ours, theirs = socket.socketpair()
    client = Recorded(st, ours)
    theirs.sendall(b"".join(lines))
    theirs.shutdown(socket.SHUT_WR)
    try:
        client._reader()  # in this thread: an exception fails the test
    finally:
        theirs.close()
    return client.sent


def test_lines_that_are_not_requests_are_answered():
    deep = b"[" * 100_000 + b"]" * 100_000 + b"\n"
    answers = served([b'{"who": "a test"}\n', b"[1]\n", b'"text"\n', deep, b'{"t": "cmd", "op": 1e400}\n',
                      b'{"t": "release", "id": 7}\n'])
    assert [a.get("text") for a in answers[:3]] == ["not a JSON object on one line"] * 3
    assert answers[3]["t"] == "ack" and "malformed command" in answers[3]["error"]
    assert answers[4] == {"t": "released", "id": 7}  # still served


def test_a_first_line_that_is_no_object():
    answers = served([b"[1]\n", b'{"t": "release", "id": 1}\n'])
    assert answers == [{"t": "released", "id": 1}]
