"""What the web station shows: a *source* of decoded link events and a
command path, shared by every browser that connects.

A source has a `layout`, hands each subscriber an asyncio queue of JSON-able
messages (`subscribe` / `unsubscribe`), answers `link()` with the link's
figures as of now, and serialises `command(who, kind, target, value)` into
one acknowledged uplink command at a time. `LiveSource` owns a port through
the link client (fswkit.link.client.Ground) in a reader thread."""

from __future__ import annotations

import asyncio
import json
import time
from collections import deque

from fswkit.autocode.protocol import OP_MODE, OP_SET, STATUS
from fswkit.link.layout import Layout, LayoutError, encode_value
from fswkit.link.session import Event, reset_words

STALE_S = 2.0  # no frame for this long: the link is shown stale
HISTORY = 200  # commands kept for a browser that connects later


class CommandError(Exception):
    """A command the station refuses before sending it (clear reason)."""


def _message(ev: Event, layout: Layout) -> dict | None:
    """One decoded event as the browser gets it."""
    if ev.kind == "sample":
        region = layout.streams[ev.stream].region
        return {"t": "samples", "seq": ev.seq, "host": ev.host_time, "names": list(region.names),
                "rows": [[time] + [_json(v) for v in values] for time, values in ev.samples]}
    if ev.kind in ("hello", "health", "ack"):
        info = {k: _json(v) for k, v in ev.info.items() if not isinstance(v, (list, tuple, dict))}
        if ev.kind == "health":
            info["tasks"] = [dict(t) for t in ev.info.get("tasks", ())]
            info["pyro"] = [dict(p) for p in ev.info.get("pyro", ())]  # each charge's status (docs/safety.md)
            info["sensors"] = [dict(s) for s in ev.info.get("sensors", ())]  # each part's health (docs/sensor-table.md)
        if ev.kind == "ack":
            info["words"] = STATUS.get(ev.info.get("status"), ("?", "unknown status"))[1]
        if "reset_cause" in ev.info:
            info["reset_words"] = reset_words(ev.info["reset_cause"])
        return {"t": ev.kind, "time": ev.time, "info": info}
    return None


_STRICT = json.JSONEncoder(allow_nan=False).encode


def _text(ev: Event, layout: Layout) -> str | None:
    """One decoded event as the browser gets it, as JSON text: encoded once,
    in the station's reader, for every browser. A sample frame whose values
    are all finite (the common case, at the link's rate) is encoded as it
    is; anything else goes through `_message`, which names what JSON
    cannot hold."""
    if ev.kind == "sample":
        try:
            return _STRICT({"t": "samples", "seq": ev.seq, "host": ev.host_time,
                            "names": layout.streams[ev.stream].region.names,
                            "rows": [[time, *values] for time, values in ev.samples]})
        except (ValueError, TypeError):  # a NaN or an infinity
            pass
    msg = _message(ev, layout)
    return None if msg is None else json.dumps(msg)


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
        """A queue of messages as JSON text (each encoded once for every
        subscriber; an item may be several, joined by commas: the items
        joined by commas in brackets are a JSON array of messages)."""
        q: asyncio.Queue = asyncio.Queue(maxsize=10000)
        self._queues.add(q)
        return q

    def unsubscribe(self, q: asyncio.Queue) -> None:
        self._queues.discard(q)

    def publish(self, msg: dict) -> None:
        """From the loop's thread."""
        self.publish_all([json.dumps(msg)])

    def publish_threadsafe(self, msg: dict) -> None:
        self.soon(self.publish, msg)

    def soon(self, fn, *args) -> None:
        """`fn(*args)` on the loop, from another thread (the station's). A
        call that races the loop's closing (the page's server stopped) is
        dropped: there is no page left to tell."""
        if self.loop is None:
            return
        try:
            self.loop.call_soon_threadsafe(fn, *args)
        except RuntimeError:  # the loop is closed
            pass

    def publish_all(self, texts: list) -> None:
        """Messages already encoded (JSON text; several joined by commas go as
        one), from the loop's thread."""
        for q in list(self._queues):
            for text in texts:
                try:
                    q.put_nowait(text)
                except asyncio.QueueFull:  # a browser that does not keep up loses its oldest message
                    q.get_nowait()
                    q.put_nowait(text)

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
    """The page's view of a ground station (fswkit.ground.station): its
    decoded events and notes are published to every browser, commands go
    through its one uplink (each waiting for its acknowledgement). With the
    application's parameter table (`params`, `tx_cap`, `baud`), the
    firmware's parameters are listed and set through the same station
    (fswkit.param.client), on a lease of its uplink."""

    def __init__(self, station, *, params=(), tx_cap: int = 0, baud: int = 115200, reload_machine: str | None = None):
        super().__init__(station.layout)
        self.station = station
        self.params, self.tx_cap, self.baud = tuple(params), tx_cap, baud
        self.reload_machine = reload_machine  # the [reload] machine, whose uploaded images read their own defaults

    async def start(self) -> None:
        await super().start()
        self.note = "" if self.station.up else self.station.note
        self.station.listen(self._events)
        self.station.notes(self._note)
        self.station.commands(self._commanded)

    def _commanded(self, entry: dict) -> None:
        """Every client's command (a browser's, `fsw cmd`'s, a script's) in the shared history."""
        def add():
            self.history.append(entry)
            self.publish(entry)
        self.soon(add)

    async def stop(self) -> None:
        self.station.unlisten(self._events)
        self.station.unnotes(self._note)
        self.station.uncommands(self._commanded)

    def _note(self, text: str, up: bool) -> None:
        self.note = text
        self.publish_threadsafe({"t": "note", "text": text, "up": up})
        self.publish_threadsafe(self.link())

    def _events(self, evs) -> None:
        if not evs:
            return
        self.frames += len(evs)
        self.last_frame = time.monotonic()
        if self.loop is None or not self._queues:  # no browser: nothing to encode, nothing to wake
            return
        texts = [m for m in (_text(ev, self.layout) for ev in evs) if m is not None]
        if texts:  # one wake-up of the loop and one message of each queue for the chunk's frames
            self.soon(self.publish_all, [",".join(texts)])

    def _command(self, who: str, op: int, args: bytes, text: str) -> dict:
        from fswkit.link.client import LinkTimeout

        try:
            return self.station.command(who, op, args, tries=3, timeout=0.5, text=text)
        except (LinkTimeout, OSError) as e:
            return {"status": None, "words": str(e)}

    def _param_client(self, transport):
        from fswkit.param.client import ParamClient

        return ParamClient(transport, self.params, self.tx_cap, baud=self.baud, deadline=10.0)

    def _params_now(self) -> dict:
        from fswkit.param.client import ParamError, uploaded_note

        with _StationTransport(self.station) as transport:
            try:
                c = self._param_client(transport)
                info = c.table_info(self.station.project)
                values = c.get_all()
                note = uploaded_note(self.params, self.reload_machine, c.uploaded_slot(self.reload_machine),
                                     self.station.project)
            except ParamError as e:
                return {"ok": False, "words": str(e)}
        rows = [{"name": p.name, "machine": p.machine, "type": p.type.name, "unit": p.unit,
                 "value": _json(values[p.name]), "default": _json(p.default), "min": _json(p.min),
                 "max": _json(p.max), "when": list(p.when), "range": p.range_text()} for p in self.params]
        return {"ok": True, "info": info, "params": rows, "note": note or ""}

    async def params_now(self) -> dict:
        """The target's parameters and its store's state (PARAM_INFO)."""
        if not self.params:
            return {"ok": False, "words": "the application declares no parameters"}
        return await asyncio.get_running_loop().run_in_executor(None, self._params_now)

    def _params_set(self, values: dict) -> str | None:
        from fswkit.param.client import ParamError, not_read

        with _StationTransport(self.station) as transport:
            try:
                c = self._param_client(transport)
                c.table_info(self.station.project)  # the ids are the board's
                why = not_read(self.params, values, self.reload_machine, c.uploaded_slot(self.reload_machine),
                               self.station.project)
                if why is not None:
                    return f"set refused: {why}"
                c.set(values)
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
        ack = await asyncio.get_running_loop().run_in_executor(None, self._command, who, op, args, text)
        status = ack.get("status")
        # the history has it already, through the station's command listeners
        return {"t": "command", "who": who, "text": text, "status": status, "ok": status == 0,
                "words": ack.get("words") or STATUS.get(status, ("?", "unknown status"))[1],
                "host_time": time.time()}



class _StationTransport:
    """The parameter client's transport on a station: the uplink leased
    (nobody else's command goes between its numbered commands), the
    decoded events of the station's reader handed over through a queue."""

    def __init__(self, station):
        import queue

        self.station = station
        self.session = station.session
        self._q: queue.Queue = queue.Queue()
        self._lease = station.lease()

    def __enter__(self):
        self.station.listen(self._q.put)
        self._lease.__enter__()
        return self

    def __exit__(self, *exc):
        self._lease.__exit__(*exc)
        self.station.unlisten(self._q.put)

    def now(self) -> float:
        return time.monotonic()

    def send(self, data: bytes) -> None:
        self.station.write(data)

    def events(self, wait: float):
        import queue

        out = []
        try:
            out += self._q.get(timeout=wait) if wait else self._q.get_nowait()
            while True:
                out += self._q.get_nowait()
        except queue.Empty:
            pass
        return out
