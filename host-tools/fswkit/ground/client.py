"""A ground command's link to its target: through the ground station when
one holds the port (`StationLink`, over the station's local socket), else
the port itself, opened exclusively (`fswkit.link.client.Ground`). Both
have the same face: `session`, `read(wait)`, `send(data)`,
`command(op, args, tries, timeout, on_event)`, `handshake(timeout,
on_event)`, `close()`; `via` says which it is."""

from __future__ import annotations

import base64
import json
import os
import select
import socket
import time

from fswkit.link import wire
from fswkit.link.client import Ground, LinkTimeout
from fswkit.link.log import RX, LogWriter
from fswkit.link.port import holder, open_port
from fswkit.link.session import Event, Session


class StationGone(OSError):
    """The station ended or dropped this client (treated as a port that went away)."""


class StationRefused(Exception):
    """The station serves the port with other configs, or speaks another protocol."""


class StationLink:
    def __init__(self, path: str, session: Session, who: str, log: LogWriter | None = None, pid: int | None = None):
        self.session = session
        self.log = log
        self.events: list[Event] = []
        self.note = ""
        self.up = True
        self._buf = b""
        self._replies: dict[int, dict] = {}
        self._id = 0
        self._leased = False
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            self.sock.connect(path)
        except OSError as e:
            self.sock.close()
            raise StationGone(f"cannot reach the ground station (pid {pid}) at {path}: {e.strerror or e}") from None
        self._put({"t": "hello", "who": f"{who} (pid {os.getpid()})"})
        welcome = self._next(10.0)
        if welcome is None or welcome.get("t") != "welcome":
            self.close()
            raise StationGone("the ground station did not answer")
        self.welcome = welcome
        self.via = f"the ground station (pid {welcome['pid']})"
        if welcome.get("schema") != session.layout.schema:
            self.close()
            raise StationRefused(
                f"the ground station (pid {welcome['pid']}) on {welcome['port']} decodes with the configs of "
                f"{welcome['project']} (schema 0x{welcome['schema']:08x}), these give 0x{session.layout.schema:08x}")
        self.note, self.up = welcome.get("note", ""), welcome.get("up", True)
        session.adopt(welcome.get("hello"), welcome.get("health"), welcome.get("numbering"))

    # ---- the socket ------------------------------------------------------------------

    def _put(self, msg: dict) -> None:
        try:
            self.sock.sendall((json.dumps(msg) + "\n").encode())
        except OSError as e:
            raise StationGone(f"the ground station went away ({e.strerror or e})") from None

    def _next(self, wait: float) -> dict | None:
        """The next message, waiting at most `wait` seconds; None when none came."""
        deadline = time.monotonic() + wait
        while b"\n" not in self._buf:
            left = deadline - time.monotonic()
            if left < 0:
                return None
            r, _, _ = select.select([self.sock], [], [], left)
            if not r:
                return None
            try:
                data = self.sock.recv(1 << 16)
            except OSError as e:
                raise StationGone(f"the ground station went away ({e.strerror or e})") from None
            if not data:
                raise StationGone("the ground station ended")
            self._buf += data
        line, _, self._buf = self._buf.partition(b"\n")
        return json.loads(line)

    def _handle(self, msg: dict) -> list[Event]:
        t = msg.get("t")
        if t == "rx":
            data = base64.b64decode(msg["d"])
            host = msg["h"]
            if self.log is not None:
                self.log.record(RX, int(host * 1e9), data)
            return self.session.feed(data, host)
        if t == "note":
            self.note, self.up = msg["text"], msg["up"]
            if msg["up"] and msg["text"].startswith("reconnected"):
                self.session.deframer.resync()
        elif t in ("ack", "leased", "released"):
            self._replies[msg.get("id")] = msg
        elif t == "error":
            self.note = msg.get("text", "")
        return []

    # ---- the link's face -----------------------------------------------------------------

    def read(self, wait: float = 0.05) -> list[Event]:
        out, self.events = self.events, []
        msg = self._next(wait)
        while msg is not None:
            out += self._handle(msg)
            msg = self._next(0)
        return out

    def _request(self, msg: dict, wait: float, on_event=None) -> dict:
        self._id += 1
        msg["id"] = ident = self._id
        self._put(msg)
        deadline = time.monotonic() + wait
        while ident not in self._replies:
            left = deadline - time.monotonic()
            if left <= 0:
                raise LinkTimeout(f"the ground station did not answer `{msg['t']}` in {wait:.0f} s")
            m = self._next(min(left, 0.1))
            if m is None:
                continue
            for ev in self._handle(m):
                if on_event is not None:
                    on_event(ev)
                else:
                    self.events.append(ev)
        return self._replies.pop(ident)

    def command(self, op: int, args: bytes = b"", tries: int = 3, timeout: float = 1.0, on_event=None,
                text: str = "") -> dict:
        """One command through the station (it numbers, sends, retries and
        waits for the acknowledgement; `text` says what it is in the
        station's history and archive); the ack's fields."""
        if self._leased:
            self._release()
        # the station may first finish another client's command
        reply = self._request({"t": "cmd", "op": op, "args": args.hex(), "tries": tries, "timeout": timeout,
                               "text": text}, tries * timeout + 30.0, on_event)
        if "error" in reply:
            raise LinkTimeout(reply["error"])
        info = dict(reply["info"])
        info["data"] = bytes.fromhex(info.get("data", ""))
        return info

    def send(self, data: bytes) -> None:
        """Raw frames (a client numbering its own commands): the uplink is
        leased first, so nobody else's command goes between them."""
        if not self._leased:
            self._request({"t": "lease"}, 60.0)
            self._leased = True
        self._put({"t": "send", "d": base64.b64encode(data).decode()})

    def _release(self) -> None:
        self._leased = False
        self._request({"t": "release"}, 10.0)

    def handshake(self, timeout: float = 3.0, on_event=None) -> dict:
        """The target's hello: the station's, when it has one (a fresh one is
        asked for when it has none)."""
        s = self.session
        if s.hello is None and s.layout.has_uplink:
            try:
                self.command(wire.OP_HELLO, tries=3, timeout=timeout / 3, on_event=on_event)
            except LinkTimeout:
                pass
        deadline = time.monotonic() + timeout
        while s.hello is None and time.monotonic() < deadline:
            for ev in self.read():
                if on_event is not None:
                    on_event(ev)
                else:
                    self.events.append(ev)
        if s.hello is None:
            raise LinkTimeout("no hello from the target (through the ground station)")
        return s.hello

    def close(self) -> None:
        try:
            self.sock.close()
        except OSError:
            pass


class PortLink(Ground):
    """The port itself, held exclusively while the command runs."""

    def __init__(self, port, session: Session, log: LogWriter | None = None):
        super().__init__(port, session, log)
        self.via = "the port"
        self.note, self.up = "", True

    def command(self, op: int, args: bytes = b"", tries: int = 3, timeout: float = 1.0, on_event=None,
                text: str = "") -> dict:
        """As Ground.command (`text` is for a station's history: a port keeps none)."""
        return super().command(op, args, tries, timeout, on_event)

    def close(self) -> None:
        try:
            self.port.close()
        except Exception:  # noqa: BLE001 - closing a port that went away
            pass


def connect(port_name: str, baud: int, session: Session, who: str, log: LogWriter | None = None):
    """The link to the target on `port_name`: through its ground station
    when one runs, else the port opened exclusively for `who` (PortBusy
    when another program holds it)."""
    rec = holder(port_name)
    if rec is not None and rec.get("socket"):
        return StationLink(rec["socket"], session, who, log, rec["pid"])
    return PortLink(open_port(port_name, baud, command=who), session, log)
