"""The ground's parameter client (docs/parameters.md): lists, sets, saves
and loads a target's parameters over the link.

Commands are pipelined: several are in flight at once (as many bytes as
the target's UART receive buffer holds), each acknowledged on its own;
one whose acknowledgement does not come in time is sent again with a new
sequence number, so a lossy radio slows a transfer down but never stalls
it. A load is staged, committed with the CRC of the whole value block it
makes, and verified by reading the live CRC back.

The client talks through a transport: a serial port (PortTransport, wall
clock) or the simulated board's UART (SimTransport, simulated clock, with
frames dropped at random in each direction for tests and benches)."""

from __future__ import annotations

import random
import struct
import time
from collections import deque
from dataclasses import dataclass

from fswkit.autocode.params import AppParam
from fswkit.autocode.protocol import crc16
from fswkit.autocode.protocol import (OP_MACHINE_INFO, OP_PARAM_BEGIN, OP_PARAM_COMMIT, OP_PARAM_GET, OP_PARAM_INFO,
                                      OP_PARAM_SAVE, OP_PARAM_SET, OP_PARAM_STAGE, PARAM_INFO, PARAM_SOURCES,
                                      PARAM_WRITING)
from fswkit.link import wire
from fswkit.link.client import Numbers
from fswkit.link.session import Session

RX_CAP = 24  # the target's uplink frame buffer (FSW_LINK_RX_CAP): encoded bytes, delimiter excluded
# uplink bytes in flight at most: the target's UART receive buffer holds 64,
# and it takes a command off it about every 20 ms (faster than 9,600 baud
# brings one), so a window a little over the buffer keeps the pipe full
# without ever overflowing it
RX_WINDOW = 90
REPLAY, UNKNOWN_OP, BUSY, NO_LOAD = 1, 2, 11, 12


class ParamError(Exception):
    """A refusal or a failure, said in words."""


def not_read(params, names, machine: str | None, slot: int, project: str) -> str | None:
    """Why a change of `names` would not reach the machine that runs: the
    first of them declared by `machine` (the project's [reload] machine)
    while the image uploaded in `slot` runs in its place (docs/reload.md:
    an uploaded machine reads its own defaults); None when none is."""
    if not slot or machine is None:
        return None
    for p in params:
        if p.name in names and p.machine == machine:
            return (f"`{p.name}` is a parameter of machine `{machine}`, which runs the image uploaded in slot {slot}: "
                    "an uploaded machine reads its own defaults, never these values (docs/reload.md), so the change "
                    f"would not reach it; `fsw machine {project} revert` runs the generated machine again, which "
                    "reads them")
    return None


def uploaded_note(params, machine: str | None, slot: int, project: str) -> str | None:
    """What to say beside the values while the image uploaded in `slot`
    runs in place of `machine`, when it declares parameters; else None."""
    if not slot or machine is None or not any(p.machine == machine for p in params):
        return None
    return (f"machine `{machine}` runs the image uploaded in slot {slot}, which reads its own defaults: the values of "
            f"its parameters here reach the generated machine only (`fsw machine {project} revert`)")


@dataclass
class Stats:
    sent: int = 0
    resent: int = 0
    acks: int = 0
    busy: int = 0


# ---- transports -------------------------------------------------------------------------

class PortTransport:
    """A serial port through the link client (wall clock)."""

    def __init__(self, ground):
        self.ground = ground
        self.session = ground.session

    def now(self) -> float:
        return time.monotonic()

    def send(self, data: bytes) -> None:
        self.ground.send(data)

    def events(self, wait: float):
        return self.ground.read(wait)


class Lossy:
    """Drops whole frames (the bytes up to a delimiter) with probability
    `p`, as a radio loses packets; the delimiter stays, so the next frame
    is intact."""

    def __init__(self, p: float, rnd: random.Random):
        self.p, self.rnd = p, rnd
        self.partial = bytearray()
        self.frames = self.dropped = 0

    def __call__(self, data: bytes) -> bytes:
        out = bytearray()
        self.partial += data
        while True:
            i = self.partial.find(0)
            if i < 0:
                break
            frame = bytes(self.partial[:i + 1])
            del self.partial[:i + 1]
            if i == 0:  # a bare delimiter
                out += frame
                continue
            self.frames += 1
            if self.rnd.random() < self.p:
                self.dropped += 1
                out += b"\0"
            else:
                out += frame
        return bytes(out)


class SimTransport:
    """The simulated board's UART (its `control` mode): time is the board's
    simulated time; frames may be dropped in each direction."""

    def __init__(self, board, session: Session, up: Lossy | None = None, down: Lossy | None = None):
        self.board, self.session = board, session
        self.up, self.down = up, down
        self.uplink_bytes = 0

    def now(self) -> float:
        return self.board.time

    def send(self, data: bytes) -> None:
        if self.up is not None:
            data = self.up(data)
        self.uplink_bytes += len(data)
        if data:
            self.board.uart_write(data)

    def events(self, wait: float):
        self.board.run_for(max(wait, 0.001))
        data = self.board.uart_read()
        if self.down is not None:
            data = self.down(data)
        return self.session.feed(data, self.board.time) if data else []


# ---- the client -------------------------------------------------------------------------

def _encoded(args: bytes) -> int:
    return wire.encoded_size(3 + len(args))


class ParamClient:
    def __init__(self, transport, params: tuple[AppParam, ...], tx_cap: int, timeout: float = 0.5,
                 deadline: float = 30.0, baud: int = 115200):
        self.t = transport
        self.params = params
        self.tx_cap = tx_cap
        self.byte_s = 10.0 / baud  # a byte's time on the wire
        self.timeout = timeout  # the longest wait for an acknowledgement
        self.deadline = deadline
        self.rtt: float | None = None  # smoothed round trip of acknowledged commands
        self.stats = Stats()
        self.numbers = Numbers(transport.session)
        self.on_event = None  # every decoded event is passed here (a monitor may show them)
        # what a target that answers BUSY till the deadline is doing (a client of other commands says its own)
        self.busy_words = ("it is still writing a parameter bank (`fsw param list` says `writing` while it does); "
                           "try again once it is done, or reset the target if it never is")

    def run(self, cmds: list[tuple[int, bytes]], busy_retry: bool = True) -> list[dict]:
        """Each command sent (several in flight), until each has its
        acknowledgement; the acks in the commands' order. A REPLAY answer
        resynchronises the sequence numbers; BUSY is tried again a little
        later (when busy_retry); a command unanswered in time goes again with
        a new number, and an acknowledgement of any of its copies counts.
        ParamError past the deadline: the target answered BUSY (busy_words),
        or nothing came."""
        t = self.t
        results: list[dict | None] = [None] * len(cmds)
        queue = deque(range(len(cmds)))
        inflight: dict[int, tuple[int, float, int]] = {}  # seq -> (command, sent at, bytes): its latest copy
        copies: dict[int, int] = {}  # every sequence number sent -> its command
        not_before = 0.0
        start = t.now()
        resent: set[int] = set()  # commands sent more than once: their round trips are ambiguous
        busy: set[int] = set()  # commands whose latest answer was BUSY

        def service(i: int) -> float:
            """How long command i keeps the link busy: its frame up, its ack
            down (a GET's carries values), a cycle of the target's, and room
            for the telemetry that shares the downlink."""
            op, args = cmds[i]
            down = (self.tx_cap if op == OP_PARAM_GET else 24) + 2
            return 1.5 * (_encoded(args) + 1 + down) * self.byte_s + 0.02

        while any(r is None for r in results):
            now = t.now()
            if now - start > self.deadline:
                if busy:  # it answers: not the link's fault
                    raise ParamError(f"the target answered BUSY for {self.deadline:g} s: {self.busy_words}")
                raise ParamError(f"no answer from the target after {self.deadline:g} s "
                                 f"({self.stats.resent} commands sent again)")
            busy_bytes = sum(b for _, _, b in inflight.values())
            while queue and now >= not_before:
                i = queue[0]
                if results[i] is not None:  # answered meanwhile (an earlier copy's ack)
                    queue.popleft()
                    continue
                op, args = cmds[i]
                size = _encoded(args) + 1
                if inflight and busy_bytes + size > RX_WINDOW:
                    break
                queue.popleft()
                seq = self.numbers.take()
                t.send(wire.uplink(op, seq, args))
                self.stats.sent += 1
                inflight[seq] = (i, now, size)
                copies[seq] = i
                busy_bytes += size
            for ev in t.events(0.01):
                if self.on_event is not None:
                    self.on_event(ev)
                if ev.kind != "ack" or ev.info["cmd_seq"] not in copies:
                    continue
                if ev.info["op"] != cmds[copies[ev.info["cmd_seq"]]][0]:  # another command's, of the same number
                    continue
                seq = ev.info["cmd_seq"]
                i = copies.pop(seq)
                sent = inflight.pop(seq, None)
                if results[i] is not None:
                    continue  # another copy was answered already
                self.stats.acks += 1
                if sent is not None and i not in resent:  # Karn: only unambiguous samples
                    rtt = t.now() - sent[1]
                    self.rtt = rtt if self.rtt is None else 0.8 * self.rtt + 0.2 * rtt
                st = ev.info["status"]
                if st == REPLAY:
                    self.numbers.resync(ev.info["last_seq"])
                    self._drop_copies(inflight, copies, i)
                    queue.appendleft(i)
                elif st == BUSY and busy_retry:
                    self.stats.busy += 1
                    busy.add(i)
                    self._drop_copies(inflight, copies, i)
                    queue.appendleft(i)
                    not_before = t.now() + 0.02
                else:
                    results[i] = ev.info
                    busy.discard(i)
                    self._drop_copies(inflight, copies, i)
            # a command waits behind those sent before it: its ack is due after
            # theirs, plus a margin (a quarter of the round trips measured)
            now = t.now()
            margin = 0.06 if self.rtt is None else min(self.timeout, 0.04 + 0.25 * self.rtt)
            ahead = 0.0
            for seq, (i, sent, _) in sorted(inflight.items(), key=lambda kv: kv[1][1]):
                ahead += service(i)
                if now - sent > ahead + margin:
                    del inflight[seq]  # its ack still counts if it comes (copies)
                    queue.appendleft(i)
                    resent.add(i)
                    self.stats.resent += 1
        return results  # type: ignore[return-value]

    @staticmethod
    def _drop_copies(inflight, copies, i) -> None:
        for seq in [s for s, c in copies.items() if c == i]:
            del copies[seq]
            inflight.pop(seq, None)

    # ---- the operations --------------------------------------------------------------

    def info(self) -> dict:
        ack = self.run([(OP_PARAM_INFO, b"")])[0]
        if ack["status"] == UNKNOWN_OP:  # a firmware without parameters links none of their commands
            raise ParamError("the target's firmware has no parameters (it does not know PARAM_INFO): it was built "
                             "from other configs; build and flash it again")
        if ack["status"] != 0:
            raise ParamError(f"the target refused PARAM_INFO: {ack['status_name']}: {ack['reason']}")
        if len(ack["data"]) < PARAM_INFO.size:
            raise ParamError("the target's firmware has no parameters (PARAM_INFO carried no state)")
        source, seq, crc, count, h = PARAM_INFO.unpack_from(ack["data"])
        return {"source": source & 3, "source_name": PARAM_SOURCES[source & 3], "dirty": bool(source & 0x40),
                "writing": bool(source & PARAM_WRITING), "seq": seq, "crc": crc, "count": count, "hash": h}

    def table_info(self, project: str) -> dict:
        """PARAM_INFO, once the target's parameter table is this client's
        (the table hash and count): the link's schema does not cover the
        parameters, so a board flashed with other ones says hello as this
        project's would, and its values read or set by this table would be
        other parameters'. ParamError, saying so, when it is not."""
        from fswkit.autocode.params import param_hash

        inf = self.info()
        mine = param_hash(self.params)
        if inf["hash"] != mine or inf["count"] != len(self.params):
            raise ParamError(f"the target's parameter table (hash 0x{inf['hash']:08x}, {inf['count']} parameters) is "
                             f"not the one of {project} (0x{mine:08x}, {len(self.params)}): its firmware was built "
                             "from other configs; build and flash it again")
        return inf

    def uploaded_slot(self, machine: str | None) -> int:
        """The slot (1, 2) whose uploaded image runs in place of `machine`
        (the project's [reload] machine), 0 when its generated code runs;
        asked (MACHINE_INFO) only when `machine` declares parameters."""
        if machine is None or not any(p.machine == machine for p in self.params):
            return 0
        ack = self.run([(OP_MACHINE_INFO, b"")])[0]
        data = ack.get("data") or b""
        return data[0] if ack["status"] == 0 and data and data[0] in (1, 2) else 0

    def get_all(self) -> dict[str, object]:
        """Every parameter's live value, by name."""
        room = self.tx_cap - 24 - self.tx_cap // 254
        chunks = []
        i = 0
        while i < len(self.params):
            first, used = i, 0
            while i < len(self.params) and used + self.params[i].type.size <= room and i - first < 255:
                used += self.params[i].type.size
                i += 1
            if i == first:
                raise ParamError("the target's transmit buffer holds no parameter value")
            chunks.append((first, i - first))
        values: dict[str, object] = {}
        todo = chunks
        while todo:
            acks = self.run([(OP_PARAM_GET, bytes(c)) for c in todo])
            nxt = []
            for (first, count), ack in zip(todo, acks):
                if ack["status"] != 0:
                    raise ParamError(f"the target refused PARAM_GET {first}: {ack['status_name']}: {ack['reason']}")
                data = ack["data"]
                if len(data) < 2 or data[0] != first:
                    raise ParamError("the target's PARAM_GET answer does not match the request")
                n, at = data[1], 2
                for p in self.params[first:first + n]:
                    values[p.name] = p.unpack(data[at:at + p.type.size])
                    at += p.type.size
                if n < count:
                    nxt.append((first + n, count - n))
            todo = nxt
        return values

    def _entries(self, values: dict[str, object]) -> list[bytes]:
        by_name = {p.name: p for p in self.params}
        return [bytes((by_name[k].id,)) + by_name[k].pack(v) for k, v in values.items()]

    def _refusal(self, ack: dict, what: str) -> ParamError:
        why = f"{ack['status_name']}: {ack['reason']}"
        data = ack.get("data", b"")
        if data and data[0] < len(self.params):
            p = self.params[data[0]]
            if ack["status"] == 10:
                why = (f"`{p.name}` may change only while machine `{p.machine}` is in "
                       f"{' or '.join(p.when)} (WRONG_STATE)")
            elif ack["status"] == 9:
                why = f"`{p.name}` must be within {p.range_text()} (OUT_OF_RANGE)"
            else:
                why = f"`{p.name}`: {why}"
        return ParamError(f"{what} refused: {why}")

    def set(self, values: dict[str, object]) -> None:
        """Live values, all or none (not saved)."""
        args = b"".join(self._entries(values))
        if _encoded(args) > RX_CAP:
            raise ParamError(f"{len(values)} values do not fit one command ({_encoded(args)} bytes encoded, the "
                             f"target takes {RX_CAP}): set fewer at a time, or use `fsw param load FILE.toml`")
        ack = self.run([(OP_PARAM_SET, args)])[0]
        if ack["status"] != 0:
            raise self._refusal(ack, "set")

    def _wait_written(self, budget: float) -> dict:
        start = self.t.now()
        while True:
            inf = self.info()
            if not inf["writing"]:
                return inf
            if self.t.now() - start > budget:
                raise ParamError(f"the target was still writing its parameter bank after {budget:g} s")
            self.t.events(0.05)

    def _write_budget(self) -> float:
        return 5.0 + 2 * (9 + sum(p.type.size for p in self.params)) * 0.0034

    def save(self) -> dict:
        """The live values into the other EEPROM bank; its state once written."""
        before = self.info()
        ack = self.run([(OP_PARAM_SAVE, b"")])[0]
        if ack["status"] != 0:
            raise self._refusal(ack, "save")
        after = self._wait_written(self._write_budget())
        if after["seq"] == before["seq"] or after["source"] not in (2, 3):
            raise ParamError("the save did not complete: the target still reports "
                             f"{after['source_name']} (sequence {after['seq']})")
        return after

    def load(self, values: dict[str, object], current: dict[str, object] | None = None) -> dict:
        """A whole set, all or nothing: staged, committed with the CRC of the
        block it makes, then verified by the live CRC read back."""
        if current is None:
            current = self.get_all()
        block = b"".join(p.pack(values.get(p.name, current[p.name])) for p in self.params)
        crc = crc16(block)
        ack = self.run([(OP_PARAM_BEGIN, b"")])[0]
        if ack["status"] != 0:
            raise self._refusal(ack, "load")
        # entries into frames that fit the target's receive buffer
        frames, cur = [], b""
        for e in self._entries(values):
            if cur and _encoded(cur + e) > RX_CAP:
                frames.append(cur)
                cur = b""
            cur += e
        if cur:
            frames.append(cur)
        for ack in self.run([(OP_PARAM_STAGE, f) for f in frames]):
            if ack["status"] != 0:
                raise self._refusal(ack, "load")
        resent = self.stats.resent
        ack = self.run([(OP_PARAM_COMMIT, struct.pack("<H", crc))])[0]
        if ack["status"] == NO_LOAD and self.stats.resent == resent:  # no copy of it was applied
            raise ParamError("the target lost the load before its COMMIT (it restarted during the load?): nothing "
                             "was loaded; run the load again")
        if ack["status"] == NO_LOAD:  # an earlier copy of the commit was applied, its ack lost
            pass
        elif ack["status"] != 0:
            raise self._refusal(ack, "load")
        after = self._wait_written(self._write_budget())
        if after["crc"] != crc:
            raise ParamError(f"the load did not verify: the target's live CRC is 0x{after['crc']:04x}, "
                             f"the file's 0x{crc:04x}")
        if after["dirty"] or after["source"] not in (2, 3):
            raise ParamError("the load did not reach the EEPROM: the target reports "
                             f"{after['source_name']}{' with unsaved changes' if after['dirty'] else ''}")
        return after
