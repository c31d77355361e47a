"""What the web station shows: a *source* of decoded link events and a
command path, shared by every browser that connects.

A source has a `layout`, hands each subscriber an asyncio queue of JSON-able
messages (`subscribe` / `unsubscribe`), answers `link()` with the link's
figures as of now, and serialises `command(who, kind, target, value)` into
one acknowledged uplink command at a time. `LiveSource` owns a port through
the link client (fswkit.link.client.Ground) in a reader thread."""

from __future__ import annotations

import asyncio
import threading
import time
from collections import deque

from fswkit.autocode.protocol import OP_MODE, OP_SET, STATUS
from fswkit.link.layout import Layout, LayoutError, encode_value
from fswkit.link.session import Event, Session

STALE_S = 2.0  # no frame for this long: the link is shown stale
HISTORY = 200  # commands kept for a browser that connects later
RESET_WORDS = ((0x01, "power-on"), (0x02, "external reset"), (0x04, "brown-out"), (0x08, "watchdog"))


def reset_words(cause: int | None) -> str:
    """An AVR reset cause (MCUSR bits) in words."""
    if cause is None:
        return "unknown"
    words = [w for bit, w in RESET_WORDS if cause & bit]
    return ", ".join(words) if words else f"none reported (0x{cause:02x})"


class CommandError(Exception):
    """A command the station refuses before sending it (clear reason)."""


def _message(ev: Event, layout: Layout) -> dict | None:
    """One decoded event as the browser gets it."""
    if ev.kind == "sample":
        region = layout.streams[ev.stream].region
        return {"t": "samples", "host": ev.host_time, "names": list(region.names),
                "rows": [[time] + [_json(v) for v in values] for time, values in ev.samples]}
    if ev.kind in ("hello", "health", "ack"):
        info = {k: _json(v) for k, v in ev.info.items() if not isinstance(v, (list, tuple, dict))}
        if ev.kind == "health":
            info["tasks"] = [dict(t) for t in ev.info.get("tasks", ())]
        if ev.kind == "ack":
            info["words"] = STATUS.get(ev.info.get("status"), ("?", "unknown status"))[1]
        if "reset_cause" in ev.info:
            info["reset_words"] = reset_words(ev.info["reset_cause"])
        return {"t": ev.kind, "time": ev.time, "info": info}
    return None


def _json(v):
    if isinstance(v, (bytes, bytearray)):
        return v.hex()  # an ack's data
    if isinstance(v, float) and v != v:
        return None  # JSON has no NaN
    if isinstance(v, float) and v in (float("inf"), float("-inf")):
        return str(v)
    return v


class Source:
    """Fan-out of messages to subscribers on one event loop."""

    def __init__(self, layout: Layout):
        self.layout = layout
        self.loop: asyncio.AbstractEventLoop | None = None
        self._queues: set[asyncio.Queue] = set()
        self.history: deque = deque(maxlen=HISTORY)
        self.last_frame: float | None = None  # monotonic time of the last frame
        self.frames = 0
        self.note = ""  # what the source says about its link (e.g. "port closed")

    def subscribe(self) -> asyncio.Queue:
        q: asyncio.Queue = asyncio.Queue(maxsize=10000)
        self._queues.add(q)
        return q

    def unsubscribe(self, q: asyncio.Queue) -> None:
        self._queues.discard(q)

    def publish(self, msg: dict) -> None:
        """From the loop's thread."""
        for q in list(self._queues):
            try:
                q.put_nowait(msg)
            except asyncio.QueueFull:  # a browser that does not keep up loses its oldest message
                q.get_nowait()
                q.put_nowait(msg)

    def publish_threadsafe(self, msg: dict) -> None:
        if self.loop is not None:
            self.loop.call_soon_threadsafe(self.publish, msg)

    def link(self) -> dict:
        age = None if self.last_frame is None else time.monotonic() - self.last_frame
        return {"t": "link", "frames": self.frames, "age": age, "stale": age is None or age > STALE_S,
                "note": self.note}

    async def start(self) -> None:
        self.loop = asyncio.get_running_loop()

    async def stop(self) -> None:
        pass

    async def command(self, who: str, kind: str, target: str, value: str) -> dict:
        raise CommandError("this source takes no commands (a replay)")

    def encode(self, kind: str, target: str, value: str) -> tuple[int, bytes, str]:
        """The uplink opcode and arguments of a command; CommandError with
        the reason when it cannot be sent."""
        lay = self.layout
        if kind == "set":
            if target not in lay.writable:
                raise CommandError(f"`{target}` is not writable from the ground (the application's [uplink] list: "
                                   f"{', '.join(lay.writable) or 'empty'})")
            el = lay.element(target)
            index = lay.elements.index(el)
            try:
                data = encode_value(el, value)
            except LayoutError as e:
                raise CommandError(str(e)) from None
            return OP_SET, index.to_bytes(2, "little") + data, f"set {target} = {value}"
        if kind == "mode":
            idx = lay.task_index(target)
            if idx is None:
                raise CommandError(f"no task `{target}`")
            modes = {"disabled": 0, "safed": 1, "enabled": 2}
            if value not in modes:
                raise CommandError(f"mode must be disabled, safed or enabled, not `{value}`")
            return OP_MODE, bytes([idx, modes[value]]), f"mode {target} {value}"
        raise CommandError(f"unknown command `{kind}`")


class LiveSource(Source):
    """A port owned through the link client: a thread reads it; commands go
    one at a time through a lock, each waiting for its acknowledgement.
    With the application's parameter table (`params`, `tx_cap`, `baud`),
    the firmware's parameters are listed and set through the same port
    (fswkit.param.client)."""

    def __init__(self, layout: Layout, port, log=None, ignore_schema: bool = False, *, params=(),
                 tx_cap: int = 0, baud: int = 115200):
        super().__init__(layout)
        from fswkit.link.client import Ground

        self.ground = Ground(port, Session(layout, ignore_schema), log)
        self.params, self.tx_cap, self.baud = tuple(params), tx_cap, baud
        self._lock = threading.Lock()  # one command on the wire at a time, and the port's reads
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    async def start(self) -> None:
        await super().start()
        self._thread = threading.Thread(target=self._run, name="fsw-web-reader", daemon=True)
        self._thread.start()

    async def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            await asyncio.get_running_loop().run_in_executor(None, self._thread.join, 2.0)

    def _events(self, evs) -> None:
        for ev in evs:
            self.frames += 1
            self.last_frame = time.monotonic()
            msg = _message(ev, self.layout)
            if msg is not None:
                self.publish_threadsafe(msg)

    def _run(self) -> None:
        from fswkit.link.client import LinkTimeout

        while not self._stop.is_set():
            try:
                with self._lock:
                    if self.ground.session.hello is None:  # frames decode once a hello confirmed the schema
                        try:
                            self.ground.handshake(timeout=1.0, on_event=lambda ev: self._events([ev]))
                            self.note = ""
                        except LinkTimeout:
                            self.note = "no hello from the target"
                            self.publish_threadsafe(self.link())
                    evs = self.ground.read(wait=0.02)
            except OSError as e:  # the port went away
                self.note = f"the port went away: {e}"
                self.publish_threadsafe(self.link())
                return
            self._events(evs)
            if not evs:
                time.sleep(0.005)

    def _command(self, op: int, args: bytes) -> dict:
        from fswkit.link.client import LinkTimeout

        with self._lock:
            try:
                return self.ground.command(op, args, tries=3, timeout=0.5, on_event=lambda ev: self._events([ev]))
            except LinkTimeout as e:
                return {"status": None, "words": str(e)}

    def _param_client(self):
        from fswkit.param.client import ParamClient, PortTransport

        c = ParamClient(PortTransport(self.ground), self.params, self.tx_cap, baud=self.baud, deadline=10.0)
        c.on_event = lambda ev: self._events([ev])
        return c

    def _params_now(self) -> dict:
        from fswkit.param.client import ParamError

        with self._lock:
            try:
                c = self._param_client()
                info = c.info()
                values = c.get_all()
            except ParamError as e:
                return {"ok": False, "words": str(e)}
        rows = [{"name": p.name, "machine": p.machine, "type": p.type.name, "unit": p.unit,
                 "value": _json(values[p.name]), "default": _json(p.default), "min": _json(p.min),
                 "max": _json(p.max), "when": list(p.when), "range": p.range_text()} for p in self.params]
        return {"ok": True, "info": info, "params": rows}

    async def params_now(self) -> dict:
        """The target's parameters and its store's state (PARAM_INFO)."""
        if not self.params:
            return {"ok": False, "words": "the application declares no parameters"}
        return await asyncio.get_running_loop().run_in_executor(None, self._params_now)

    def _params_set(self, values: dict) -> str | None:
        from fswkit.param.client import ParamError

        with self._lock:
            try:
                self._param_client().set(values)
            except ParamError as e:
                return str(e)
        return None

    async def params_set(self, who: str, given: dict) -> dict:
        """Live values, all or none, after the same checks as `fsw param set`."""
        from fswkit.autocode.params import check_value

        by_name = {p.name: p for p in self.params}
        values = {}
        for name, text in given.items():
            p = by_name.get(name)
            if p is None:
                raise CommandError(f"unknown parameter `{name}`")
            v, why = check_value(p, str(text))
            if why is not None:
                raise CommandError(why)
            values[name] = v
        if not values:
            raise CommandError("no value given")
        why = await asyncio.get_running_loop().run_in_executor(None, self._params_set, values)
        text = "param set " + ", ".join(f"{k} = {given[k]}" for k in values)
        entry = {"t": "command", "who": who, "text": text, "status": 0 if why is None else None,
                 "ok": why is None, "words": why or "applied", "host_time": time.time()}
        self.history.append(entry)
        self.publish(entry)
        return entry

    async def command(self, who: str, kind: str, target: str, value: str) -> dict:
        op, args, text = self.encode(kind, target, value)
        ack = await asyncio.get_running_loop().run_in_executor(None, self._command, op, args)
        status = ack.get("status")
        entry = {"t": "command", "who": who, "text": text, "status": status,
                 "ok": status == 0,
                 "words": ack.get("words") or STATUS.get(status, ("?", "unknown status"))[1],
                 "host_time": time.time()}
        self.history.append(entry)
        self.publish(entry)
        return entry

