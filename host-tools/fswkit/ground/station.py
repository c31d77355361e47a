"""The ground station (`fsw ground`): one process owns a target's serial
port and serves it to every client at once.

- The port is held exclusively (fswkit.link.port): a second opener is told
  "busy: held by fsw ground, pid N".
- One reader thread reads the port in passes of whole frames (at most one
  every PASS_S, the frames that came meanwhile together: each pass costs
  every part of the station a wake-up), decodes it (its own Session),
  archives the bytes, frames and notes (fswkit.ground.archive), and hands
  every chunk to every client: the in-process ones (the web page's source) get
  the decoded events, the local ones (the terminal monitor, `fsw cmd`,
  `fsw param`, `fsw dump`, scripts) the raw bytes over a Unix socket,
  cut at frame delimiters so a client that attaches mid-stream starts on
  a whole frame and decodes with its own session (its losses counted from
  the first frame it saw).
- Commands from any client go one at a time through `command()`: the
  station numbers them, sends, and waits for the acknowledgement the
  reader thread sees; each is archived with who sent it. A client that
  pipelines its own commands (`fsw param`) takes a *lease* on the uplink
  first and sends raw frames while it holds it.
- When the port goes away (a cable pulled, a board re-enumerating) the
  station says so and opens it again as soon as it comes back, asks for a
  hello, and says why the target restarted when it did (its reset cause).

The local protocol is JSON lines (docs/ground.md): the client says
`{"t": "hello", "who": ...}`, the station answers `{"t": "welcome", ...}`
with the target's last hello and health, then sends `{"t": "rx", "h":
HOST_TIME, "d": BASE64}` for every chunk, `{"t": "note", ...}` when the
link changes, and `{"t": "ack", "id": N, ...}` for each of the client's
commands."""

from __future__ import annotations

import base64
import json
import os
import queue
import socket
import threading
import time
from contextlib import contextmanager

from fswkit.link import wire
from fswkit.link.client import LinkTimeout, Numbers, exchange
from fswkit.link.layout import Layout
from fswkit.link.port import (PortError, drain, open_port, port_errors, port_identity, port_key, port_returned,
                              runtime_dir)
from fswkit.link.session import Event, Session, max_frame, reset_words

from .archive import ArchiveError

PROTOCOL = 1
REOPEN_S = 0.25  # how often a port that went away is tried again
CLIENT_BACKLOG = 200_000  # messages queued for a client that does not read before it is dropped
COMMAND_WHO = "fsw ground"
FRAME_WAIT_S = 0.02  # the longest a frame's first bytes wait for its end before they are handed on
PASS_S = 0.02  # the least time between two passes of frames to the decoder, the archive and the clients
FRAME_POLL_S = 0.002  # the margin over a frame's remaining time on the wire, and the least wait


def socket_path(port_name: str) -> str:
    return os.path.join(runtime_dir(), port_key(port_name) + ".sock")


def jsonable(info: dict) -> dict:
    out = {}
    for k, v in info.items():
        if isinstance(v, (bytes, bytearray)):
            v = bytes(v).hex()
        elif isinstance(v, list):
            v = [dict(x) if isinstance(x, dict) else x for x in v]
        out[k] = v
    return out


class Station:
    """The port's owner. `listen(fn)` adds an in-process listener called
    from the reader thread with each batch of decoded events; `notes(fn)`
    one called with each note (text, up: whether the link is up)."""

    def __init__(self, layout: Layout, project: str, port_name: str, baud: int, *, archive=None,
                 ignore_schema: bool = False, serve: bool = True):
        self.layout, self.project, self.port_name, self.baud = layout, project, port_name, baud
        self.archive = archive
        self.session = Session(layout, ignore_schema)
        self.ignore_schema = ignore_schema
        self.socket_path = socket_path(port_name) if serve else None
        self.port = None
        self.note = "opening the port"
        self.up = False
        self.last_frame: float | None = None  # monotonic
        self.reconnects = 0
        self._listeners: list = []
        self._note_listeners: list = []
        self._command_listeners: list = []
        self._clients: set[_Client] = set()
        self._clients_lock = threading.RLock()  # a client dropped while a chunk goes out takes it again
        self._uplink = threading.Lock()  # one command, or one lease, on the wire at a time
        self._write_lock = threading.Lock()
        self._waiting: dict[int, dict] = {}  # command number -> {"event", "ack"}
        self.numbers = Numbers(self.session)
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []
        self._server: socket.socket | None = None
        self._carry = b""  # bytes after the last delimiter, sent to clients with the next chunk
        # ... at most a run longer than any frame: a port that brings no delimiter (a board printing
        # text, a baud rate not the board's) is not held for the clients byte by byte
        self._carry_max = max_frame(layout) + 1
        self._restarts = 0
        self._identity: tuple | None = None  # link.port.port_identity of the port opened

    # ---- life ------------------------------------------------------------------------

    def start(self) -> None:
        """Opens the port (PortBusy / PortError when it cannot) and starts
        serving."""
        self.port = open_port(self.port_name, self.baud, command="fsw ground", socket=self.socket_path)
        self._identity = port_identity(self.port_name)  # what the port must be to be opened again
        if self.archive is not None:
            try:
                self.archive.begin(layout=self.layout, project=self.project, port=self.port_name, baud=self.baud,
                                   started=time.time())
            except ArchiveError:  # refused as an archive is, the port given up
                self.port.close()
                self.port = None
                raise
        self.up = True
        self._say("port open")
        if self.socket_path is not None:
            self._listen_socket()
        self._spawn(self._read_loop, "fsw-ground-reader")
        self._spawn(self._hello, "fsw-ground-hello")

    def stop(self) -> None:
        self._stop.set()
        for t in self._threads:
            if t is not threading.current_thread():
                t.join(2.0)
        with self._clients_lock:
            clients = list(self._clients)
        for c in clients:
            c.close()
        if self._server is not None:
            try:
                self._server.close()
            except OSError:
                pass
            try:
                os.unlink(self.socket_path)
            except OSError:
                pass
        if self.port is not None:
            self.port.close()
            self.port = None
        self._archive("close")

    def __enter__(self):
        self.start()
        return self

    def __exit__(self, *exc):
        self.stop()

    def _spawn(self, fn, name: str) -> None:
        t = threading.Thread(target=fn, name=name, daemon=True)
        self._threads.append(t)
        t.start()

    def listen(self, fn) -> None:
        self._listeners.append(fn)

    def unlisten(self, fn) -> None:
        if fn in self._listeners:
            self._listeners.remove(fn)

    def notes(self, fn) -> None:
        self._note_listeners.append(fn)

    def unnotes(self, fn) -> None:
        if fn in self._note_listeners:
            self._note_listeners.remove(fn)

    def commands(self, fn) -> None:
        """`fn(entry)` after every command of every client: who, text,
        status, ok, words, host_time."""
        self._command_listeners.append(fn)

    def uncommands(self, fn) -> None:
        if fn in self._command_listeners:
            self._command_listeners.remove(fn)

    def _archive(self, what: str, *args, **kw) -> None:
        """The archive's `what` (rx, event, tick, ...). An archive that cannot
        be written (a lock another program holds longer than SQLite waits, a
        full disk) stops archiving, said once: the link goes on without it,
        the archive keeps what was committed."""
        archive = self.archive
        if archive is None:
            return
        try:
            getattr(archive, what)(*args, **kw)
            while archive.notices:  # what it did of itself (its file deleted and written again)
                self._say(archive.notices.pop(0))
        except ArchiveError as e:
            if self.archive is not archive:  # another thread said it
                return
            self.archive = None
            archive.abandon()
            self._say(f"archiving stopped: {e}; the link goes on without it (the archive keeps what was "
                      "committed before)")

    def _say(self, text: str) -> None:
        self.note = text
        self._archive("note", time.time(), text)
        for fn in list(self._note_listeners):
            fn(text, self.up)
        self._broadcast({"t": "note", "text": text, "up": self.up})

    # ---- the port ----------------------------------------------------------------------

    def _read_loop(self) -> None:
        """Reads the port in passes of whole frames. A pass costs the decoder,
        the archive, every client and the page's event loop their work and
        a wake-up each, which is most of the station's CPU time at a full
        link's rate; so the thread sleeps while a frame is still on the wire
        (about its remaining bytes' time at the baud rate, judged by the
        last whole frame's length) instead of reading it as it trickles in,
        hands frames on at most once every PASS_S (those that came meanwhile
        together), and blocks on the port only between frames. A frame
        waits PASS_S for its pass at the most, and a quiet link's frame goes
        on as soon as its last byte is read; bytes with no delimiter after
        them (a frame longer than the last, or no frame) go on after
        FRAME_WAIT_S as they are."""
        errors = port_errors()
        byte_s = 10.0 / max(1, self.baud)  # a byte's time on the wire: start, 8 data and stop bits
        held = b""  # read, not handed on yet: no delimiter among them
        held_since = 0.0  # monotonic time the oldest held byte was read
        last_read = 0.0  # ... and the newest
        part = 0  # bytes handed on of the frame in progress (after the last delimiter)
        frame_len = 0  # the last whole frame's bytes, its delimiter included
        next_pass = 0.0  # monotonic time before which no frame is handed on
        while not self._stop.is_set():
            port = self.port
            if port is None:
                held, part = b"", 0
                self._reopen()
                continue
            try:
                if not held and not part:  # between frames: the next byte wakes the thread
                    data = port.read(port.in_waiting or 1)
                    more = port.in_waiting if data else 0  # the rest of what came with it (a whole frame, often)
                    if more:
                        data += port.read(more)
                else:  # a frame in progress: its rest gathers meanwhile (and the frames after it)
                    left = (frame_len - part - len(held)) * byte_s + FRAME_POLL_S
                    time.sleep(min(FRAME_WAIT_S, max(FRAME_POLL_S, left, next_pass - time.monotonic())))
                    n = port.in_waiting
                    data = port.read(n) if n else b""
            except errors as e:
                self._lost(e)
                held, part = b"", 0
                continue
            except (TypeError, AttributeError):
                # pyserial reading a port closed under it (its descriptor is
                # None): stop() closes the port once its wait for this thread
                # has run out. Stopping, that is the end; otherwise a defect.
                if self._stop.is_set():
                    break
                raise
            now = time.monotonic()
            if data:
                last_read = now
                if not held:
                    held_since = now
                held += data
            if held:
                end = held.rfind(b"\0")
                if (end >= 0 and now >= next_pass) or now - held_since >= FRAME_WAIT_S:
                    if end >= 0:  # whole frames, handed on with the start of the next one
                        before = held.rfind(b"\0", 0, end)
                        frame_len = end - before if before >= 0 else part + end + 1
                        part = len(held) - end - 1
                    else:  # a frame longer than the last, or no frame: what came, as it is
                        part += len(held)
                    data, held = held, b""
                    next_pass = now + PASS_S
                    self._received(data)
                    continue
            if not data:
                if part and not held and now - last_read >= FRAME_WAIT_S:
                    part = 0  # the rest is not coming: wait on the port again
                self._archive("tick")

    def _lost(self, e: Exception) -> None:
        port, self.port = self.port, None
        if port is not None:
            port.close()
        self.up = False
        self._carry = b""
        never = self._identity is not None and self._identity[0] == "pty"
        self._say(f"the port went away ({e}); "
                  + (port_returned(self.port_name, self._identity) if never else "waiting for it to come back"))

    def _reopen(self) -> None:
        self._archive("tick")  # the note that the port went away, and the last bytes, committed
        if self._stop.wait(REOPEN_S):
            return
        if port_returned(self.port_name, self._identity) is not None:
            return  # not there yet, or another program's pseudo-terminal now
        try:
            self.port = open_port(self.port_name, self.baud, command="fsw ground", socket=self.socket_path)
        except PortError:
            return
        self._identity = port_identity(self.port_name)
        self.up = True
        self.reconnects += 1
        self.session.deframer.resync()  # a frame cut by the pull is not one
        self._say("reconnected: the port is back; asking the target for a hello")
        self._spawn(self._hello, "fsw-ground-hello")

    def _hello(self) -> None:
        """Asks for a hello (the schema, the reset cause); without an uplink
        the target sends one by itself."""
        if not self.layout.has_uplink:
            return
        try:
            self.write(b"\0")
            self.command(COMMAND_WHO, wire.OP_HELLO, b"", tries=3, timeout=0.5)
        except (LinkTimeout, OSError):
            pass

    def _received(self, data: bytes) -> None:
        t_ns = time.time_ns()
        host = t_ns / 1e9
        # clients get whole frames: the chunk up to its last delimiter; decoded
        # and sent under the clients' lock, so a client's welcome (the station's
        # numbering as of then) is never ahead of the first chunk it gets
        buf = self._carry + data
        cut = buf.rfind(b"\0") + 1
        self._carry = buf[cut:] if len(buf) - cut <= self._carry_max else buf[-self._carry_max:]
        with self._clients_lock:
            evs = self.session.feed(data, host)
            if cut and self._clients:  # encoded once for every client, and not at all for none
                line = (json.dumps({"t": "rx", "h": host, "d": base64.b64encode(buf[:cut]).decode()}) + "\n").encode()
                for c in list(self._clients):
                    c.put(line)
        if evs:
            self.last_frame = time.monotonic()
        for ev in evs:
            if ev.kind == "ack":
                w = self._waiting.get(ev.info["cmd_seq"])  # the command of its number and its opcode only
                if w is not None and w["ack"] is None and w["op"] == ev.info["op"]:
                    w["ack"] = ev.info
                    w["event"].set()
            elif ev.kind == "hello":
                self._on_hello(ev)
        for fn in list(self._listeners):
            fn(evs)
        self._archive("received", t_ns, data, evs)  # the bytes, their frames and a tick: one call

    def _on_hello(self, ev: Event) -> None:
        i = ev.info
        restarted = self.session.stats.restarts > self._restarts
        self._restarts = self.session.stats.restarts
        cause = reset_words(i.get("reset_cause"))
        schema = "" if i["schema_ok"] else " (its schema does not match the configs)"
        if restarted:
            self._say(f"the target restarted: reset cause {cause}{schema}")
        else:
            self._say(f"target up, last reset: {cause}{schema}")

    def write(self, data: bytes) -> None:
        port = self.port
        if port is None:
            raise OSError("the port is not open (it went away)")
        with self._write_lock:
            self._archive("tx", time.time_ns(), data)
            try:
                port.write(data)
                drain(port)
            except (TypeError, AttributeError):
                # pyserial writing a port the reader closed under it (it went away): its descriptor is None
                if port.is_open:
                    raise
                raise OSError("the port is not open (it went away)") from None

    # ---- commands ------------------------------------------------------------------------

    def command(self, who: str, op: int, args: bytes = b"", tries: int = 3, timeout: float = 0.5,
                text: str = "") -> dict:
        """One command, acknowledged: the ack's fields (status 0: applied).
        A REPLAY answer resynchronises the numbers and sends it again.
        LinkTimeout when none came (lost, or applied and its acknowledgement
        lost: the words say so); OSError when it could not be written, its
        words `not sent: ...` when nothing of it went on the wire. Either way
        it is archived and told to the command listeners with those words,
        who sent it and what it is (`text`, else the opcode's name and the
        arguments in hex)."""
        sent = time.time()
        ack = None
        written = []  # the frames of it that went on the wire
        words = "no acknowledgement"
        try:
            with self._uplink:
                ack = self._exchange(op, args, tries, timeout, written)
            words = ack["reason"]
            return ack
        except LinkTimeout as e:
            words = f"{e}: lost, or applied and its acknowledgement lost"
            raise LinkTimeout(words) from None
        except OSError as e:
            words = (f"sent, then no acknowledgement: {e} (lost, or applied and its acknowledgement lost)"
                     if written else f"not sent: {e}")
            raise OSError(words) from None
        finally:
            text = text or f"{wire.OP_NAMES.get(op, f'op_{op}')} {args.hex()}".strip()
            entry = {"t": "command", "who": who, "text": text, "status": None if ack is None else ack["status"],
                     "ok": ack is not None and ack["status"] == 0, "words": words, "host_time": time.time()}
            self._archive("command", who=who, text=text, op=op, args=args, sent=sent,
                          cmd_seq=None if ack is None else ack["cmd_seq"], status=entry["status"],
                          words=words, acked=None if ack is None else entry["host_time"])
            for fn in list(self._command_listeners):
                fn(entry)

    def _exchange(self, op: int, args: bytes, tries: int, timeout: float, written: list) -> dict:
        def send_and_wait(seq: int, frame: bytes) -> dict | None:
            slot = {"event": threading.Event(), "ack": None, "op": op}
            self._waiting[seq] = slot  # before it goes: the reader thread fills it
            try:
                self.write(frame)
                written.append(seq)
                slot["event"].wait(timeout)
            finally:
                del self._waiting[seq]
            return slot["ack"]

        return exchange(self.numbers, op, args, tries, send_and_wait)

    @contextmanager
    def lease(self):
        """The uplink for one client's own numbered commands (`fsw param`):
        nobody else's command is sent meanwhile; the station numbers afresh
        after it."""
        with self._uplink:
            try:
                yield self
            finally:
                self.numbers.forget()

    # ---- local clients -------------------------------------------------------------------

    def _listen_socket(self) -> None:
        path = self.socket_path
        try:
            os.unlink(path)  # we hold the port: a socket left there is a dead station's
        except OSError:
            pass
        srv = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        srv.bind(path)
        os.chmod(path, 0o600)
        srv.listen(16)
        srv.settimeout(0.2)
        self._server = srv
        self._spawn(self._accept_loop, "fsw-ground-accept")

    def _accept_loop(self) -> None:
        while not self._stop.is_set():
            try:
                conn, _ = self._server.accept()
            except socket.timeout:
                continue
            except OSError:
                return
            conn.settimeout(None)
            _Client(self, conn).start()

    def _broadcast(self, msg: dict) -> None:
        line = (json.dumps(msg) + "\n").encode()
        with self._clients_lock:
            clients = list(self._clients)
        for c in clients:
            c.put(line)

    def welcome(self) -> dict:
        s = self.session
        return {"t": "welcome", "protocol": PROTOCOL, "pid": os.getpid(), "project": self.project,
                "port": self.port_name, "baud": self.baud, "schema": self.layout.schema,
                "hello": None if s.hello is None else jsonable(s.hello),
                "health": None if s.health is None else jsonable(s.health),
                "numbering": s.numbering(), "note": self.note, "up": self.up}

    def clients(self) -> list[str]:
        with self._clients_lock:
            return [c.who for c in self._clients]


def _message(raw: bytes) -> dict | None:
    """A client's line as the JSON object it must be, or None (not JSON,
    another JSON value, or nested too deeply to read)."""
    try:
        msg = json.loads(raw)
    except (ValueError, RecursionError):
        return None
    return msg if isinstance(msg, dict) else None


class _Client:
    """One local client: a thread reading its requests, one writing its
    messages in order."""

    def __init__(self, station: Station, conn: socket.socket):
        self.st, self.conn = station, conn
        self.who = "a local client"
        self.q: queue.Queue = queue.Queue()
        self.lease = None
        self.closed = False

    def start(self) -> None:
        threading.Thread(target=self._reader, name="fsw-ground-client", daemon=True).start()

    def put(self, line: bytes) -> None:
        if self.q.qsize() > CLIENT_BACKLOG:
            self.close()
            return
        self.q.put(line)

    def close(self) -> None:
        if self.closed:
            return
        self.closed = True
        with self.st._clients_lock:
            self.st._clients.discard(self)
        self.q.put(None)
        self._release()
        try:
            self.conn.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass

    def _writer(self) -> None:
        while True:
            line = self.q.get()
            if line is None:
                break
            try:
                self.conn.sendall(line)
            except OSError:
                break
        self.close()
        try:
            self.conn.close()
        except OSError:
            pass

    def _send(self, msg: dict) -> None:
        self.put((json.dumps(msg) + "\n").encode())

    def _release(self) -> None:
        if self.lease is not None:
            lease, self.lease = self.lease, None
            lease.__exit__(None, None, None)

    def _reader(self) -> None:
        f = self.conn.makefile("rb")
        try:
            first = _message(f.readline() or b"{}") or {}
            self.who = str(first.get("who") or self.who)[:120]
            # registered and welcomed under the clients' lock: no chunk can come
            # before the welcome, nor be missed after it
            with self.st._clients_lock:
                self.q.put((json.dumps(self.st.welcome()) + "\n").encode())
                self.st._clients.add(self)
            threading.Thread(target=self._writer, name="fsw-ground-client-out", daemon=True).start()
            for raw in f:
                msg = _message(raw)
                if msg is None:
                    self._send({"t": "error", "text": "not a JSON object on one line"})
                    continue
                self._request(msg)
        except (OSError, ValueError):
            pass
        finally:
            self.close()

    def _request(self, msg: dict) -> None:
        kind = msg.get("t")
        ident = msg.get("id")
        if kind == "cmd":
            try:
                op, args = int(msg["op"]), bytes.fromhex(msg.get("args", ""))
                if self.lease is not None:
                    raise ValueError("a client holding the uplink sends its own frames")
                ack = self.st.command(self.who, op, args, int(msg.get("tries", 3)), float(msg.get("timeout", 0.5)),
                                      str(msg.get("text", ""))[:200])
                self._send({"t": "ack", "id": ident, "info": jsonable(ack)})
            except (KeyError, ValueError, TypeError, OverflowError) as e:  # OverflowError: int() of an infinity
                self._send({"t": "ack", "id": ident, "error": f"malformed command: {e}"})
            except (LinkTimeout, OSError) as e:
                self._send({"t": "ack", "id": ident, "error": str(e)})
        elif kind == "lease":
            if self.lease is None:
                lease = self.st.lease()
                lease.__enter__()
                self.lease = lease
            self._send({"t": "leased", "id": ident})
        elif kind == "send":
            if self.lease is None:
                self._send({"t": "error", "text": "send without the uplink (ask for a lease first)"})
                return
            try:
                self.st.write(base64.b64decode(msg["d"]))
            except OSError as e:
                self._send({"t": "error", "text": str(e)})
        elif kind == "release":
            self._release()
            self._send({"t": "released", "id": ident})
        else:
            self._send({"t": "error", "text": f"unknown request `{kind}`"})
