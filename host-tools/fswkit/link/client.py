"""The ground end of a live link: reads the port into a Session (and a log),
sends commands with fresh sequence numbers and waits for their
acknowledgements."""

from __future__ import annotations

import time

from . import wire
from .log import RX, TX, LogWriter
from .port import drain
from .session import Event, Session


class LinkTimeout(Exception):
    pass


class Numbers:
    """The uplink's command numbers: the next after the target's last
    accepted one (from its hello or health), then counting up, never 0;
    `forget()` starts again from the target's; `resync(last)` after a
    REPLAY answer."""

    def __init__(self, session: Session):
        self.session = session
        self._next: int | None = None

    def take(self) -> int:
        s = self.session
        if self._next is None:
            known = [x["last_seq"] for x in (s.hello, s.health) if x is not None]
            self._next = (max(known) + 1) & 0xFFFF if known else 1
        if self._next == 0:
            self._next = 1
        seq = self._next
        self._next = (seq + 1) & 0xFFFF
        return seq

    def forget(self) -> None:
        self._next = None

    def resync(self, last: int) -> None:
        self._next = (last + 1) & 0xFFFF


def exchange(numbers: Numbers, op: int, args: bytes, tries: int, send_and_wait) -> dict:
    """One command until acknowledged: `send_and_wait(seq, frame)` sends the
    numbered frame and returns its acknowledgement's fields, or None when
    none came in time. A REPLAY answer carries the target's last accepted
    number: the command goes again after it (twice at most). LinkTimeout
    after `tries` unanswered sends."""
    replays = attempt = 0
    while attempt < tries:
        seq = numbers.take()
        ack = send_and_wait(seq, wire.uplink(op, seq, args))
        if ack is not None:
            if ack["status"] == 1 and replays < 2:  # REPLAY: resynchronise on its last number
                numbers.resync(ack["last_seq"])
                replays += 1
                continue
            return ack
        attempt += 1
    raise LinkTimeout(f"no acknowledgement of `{wire.OP_NAMES.get(op, op)}` after {tries} tries")


class Ground:
    def __init__(self, port, session: Session, log: LogWriter | None = None):
        self.port = port
        self.session = session
        self.log = log
        self.events: list[Event] = []  # decoded, not yet taken by the caller
        self.numbers = Numbers(session)

    def read(self, wait: float = 0.05) -> list[Event]:
        """Bytes waiting on the port (at most `wait` seconds for the first)."""
        port = self.port
        n = port.in_waiting
        data = port.read(n if n else 1) if wait else port.read(n)
        if n == 0 and data:
            more = port.in_waiting
            if more:
                data += port.read(more)
        if data:
            now = time.time_ns()
            if self.log is not None:
                self.log.record(RX, now, data)
            self.events += self.session.feed(data, now / 1e9)
        out, self.events = self.events, []
        return out

    def send(self, data: bytes) -> None:
        if self.log is not None:
            self.log.record(TX, time.time_ns(), data)
        self.port.write(data)
        drain(self.port)

    def command(self, op: int, args: bytes = b"", tries: int = 3, timeout: float = 1.0,
                on_event=None) -> dict:
        """Sends a command until it is acknowledged (fswkit.link.client.exchange);
        returns the ack's fields (status 0: applied). Every event read
        meanwhile goes to `on_event`, or stays for the next `read()`."""
        def send_and_wait(seq: int, frame: bytes) -> dict | None:
            self.send(frame)
            deadline = time.monotonic() + timeout
            ack = None
            while ack is None and time.monotonic() < deadline:
                for ev in self.read():  # every event is passed on, the ack's too
                    if on_event is not None:
                        on_event(ev)
                    else:
                        self.events.append(ev)
                    if ev.kind == "ack" and ev.info["cmd_seq"] == seq and ev.info["op"] == op and ack is None:
                        ack = ev.info
            return ack

        return exchange(self.numbers, op, args, tries, send_and_wait)

    def handshake(self, timeout: float = 3.0, on_event=None) -> dict:
        """Asks for a hello (when the application has an uplink) and waits for
        one; returns its fields."""
        if self.session.layout.has_uplink:
            self.send(b"\0")  # ends whatever partial frame the target holds
            try:
                self.command(wire.OP_HELLO, tries=3, timeout=timeout / 3, on_event=on_event)
            except LinkTimeout:
                pass
        deadline = time.monotonic() + timeout
        while self.session.hello is None and time.monotonic() < deadline:
            for ev in self.read():
                if on_event is not None:
                    on_event(ev)
                else:
                    self.events.append(ev)
        if self.session.hello is None:
            raise LinkTimeout("no hello from the target")
        return self.session.hello
