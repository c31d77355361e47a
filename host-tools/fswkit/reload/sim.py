"""Machines uploaded to the simulated board (docs/reload.md): the ground's
machine client on the other end of its UART, frames dropped at random in
each direction, or the power cut at an EEPROM write. Used by the tests
(tests/reload) and `make bench` (tools/bench_reload.py); every time here is
simulated time."""

from __future__ import annotations

import random
from dataclasses import dataclass, field


class _Cut(Exception):
    """The board lost power (the harness reset it at an EEPROM write)."""


@dataclass
class Upload:
    seconds: float  # simulated, from BEGIN to the slot committed and verified
    activate_s: float  # from ACTIVATE to the target running the image
    sent: int
    resent: int
    busy: int
    up_frames: int
    up_dropped: int
    down_frames: int
    down_dropped: int
    slot: int
    longest_command: int = 0  # cycles of the longest uplink command the board handled (0: not measured)
    longest_slice: int = 0  # cycles of the longest slice of a check (the CRC's or the verifier's)
    slices: int = 0  # slices the checks took (the commit's and the activation's)
    copy: int = 0  # cycles of the switch's copy: the image from the EEPROM into RAM, and its reset
    late: int = -1  # cycles the executor counted late from BEGIN to the switch (-1: no health frame)
    worst_us: dict = field(default_factory=dict)  # task -> its longest step since boot (health frame)
    overruns: dict = field(default_factory=dict)  # task -> its overruns from BEGIN to the switch


def _session(app, b, loss: float, seed: int):
    from fswkit.autocode.schema import link_plan
    from fswkit.link.layout import from_app
    from fswkit.link.session import Session
    from fswkit.param.client import Lossy, SimTransport

    from .client import MachineClient

    rnd = random.Random(seed)
    up, down = (Lossy(loss, rnd), Lossy(loss, rnd)) if loss else (None, None)
    session = Session(from_app(app))
    t = SimTransport(b, session, up, down)
    while session.hello is None and b.time < 30:  # the boot hello (or a later one)
        t.events(0.05)
    return MachineClient(t, link_plan(app).tx_cap, baud=app.baud, timeout=0.3, deadline=600), t, up, down


# What timed_upload times on the board (when the build has them out of
# line): each reload command the link hands the store, each slice of a
# check, the switch's copy of the image into RAM.
_TIMED = ("fsw::link_reload_apply(", "fsw::(anonymous namespace)::check_slice(",
          "fsw::(anonymous namespace)::run_slot(")


def timed_upload(elf: str, board: str, app, image: bytes, mask: bytes, loss: float = 0.0, seed: int = 1,
                 baud: int | None = None, analog: dict | None = None) -> Upload:
    """Boots the firmware and uploads `image` (and activates it), through a
    link that drops `loss` of the frames each way; the board's profiler
    times each reload command it handles, each slice of the checks and the
    switch's copy (_TIMED), and the health frames before and after give the late
    cycles, the overruns and each task's longest step."""
    from fswkit.sim.board import SimBoard
    from fswkit.target.build import elf_symbols

    syms = [(addr, name) for addr, _size, kind, name in elf_symbols(elf) if kind in "tT"]
    timed = [next((a for a, n in syms if n.startswith(prefix)), None) for prefix in _TIMED]
    with SimBoard(elf, board, uart="control", sim_limit=1e6, analog=analog) as b:
        if any(a is not None for a in timed):
            b.profile([a for a in timed if a is not None])
        c, t, up, down = _session(app, b, loss, seed)
        h0 = _health(t)
        t0 = t.now()
        slot, _ = c.upload(image, mask)
        t1 = t.now()
        c.activate(slot, wait=30)
        t2 = t.now()
        fns = {f.entry: f for f in b.profile_read().functions} if any(a is not None for a in timed) else {}
        command, check, copy = (fns.get(a) for a in timed)
        h1 = _health(t)
        late, worst, over = -1, {}, {}
        if h0 is not None and h1 is not None:
            late = h1["late"] - h0["late"]
            worst = {x["name"]: x["worst_us"] for x in h1["tasks"]}
            over = {x["name"]: x["overruns"] - y["overruns"] for x, y in zip(h1["tasks"], h0["tasks"])}
        return Upload(t1 - t0, t2 - t1, c.stats.sent, c.stats.resent, c.stats.busy,
                      up.frames if up else 0, up.dropped if up else 0, down.frames if down else 0,
                      down.dropped if down else 0, slot, longest_command=command.worst if command else 0,
                      longest_slice=check.worst if check else 0, slices=check.calls if check else 0,
                      copy=copy.worst if copy else 0, late=late, worst_us=worst, overruns=over)


def _health(t, budget: float = 3.0) -> dict | None:
    """The next health frame the board sends (sent after this call), or None
    if none came within `budget` simulated seconds (a lossy link may drop
    them)."""
    last = t.session.health
    seen = last["cycles"] if last is not None else -1
    end = t.now() + budget
    while t.now() < end:
        t.events(0.05)
        h = t.session.health
        if h is not None and h["cycles"] > seen:
            return dict(h)
    return None


@dataclass
class CutRun:
    writes: int  # EEPROM byte writes an upload and activation take
    cases: int = 0  # cut points tried
    old: int = 0  # reboots that came up running the machine that ran before
    new: int = 0  # ... running the uploaded one
    bad: list = field(default_factory=list)  # (cut point, what was wrong)


def power_cuts(elf: str, board: str, app, image: bytes, mask: bytes, stride: int = 1,
               analog: dict | None = None) -> CutRun:
    # `analog`: the inputs (volts by pin) set again after every reset, so that
    # the machine sits in a state that lets another take over
    """The generated machine runs; the ground uploads `image` and activates
    it; the power is cut after the 1st, 1+stride-th, ... EEPROM byte write
    (and after each of the last few). After each reboot the board must run
    the generated machine or the image, whole: its slot committed with the
    image's bytes when it runs it, and never a slot marked to boot that it
    does not run."""
    from fswkit.autocode.reloadcheck import eeprom_bytes
    from fswkit.sim.board import SimBoard

    from .client import MachineError
    from fswkit.param.client import ParamError

    size = app.reload.size
    erased = b"\xff" * eeprom_bytes(size)
    with SimBoard(elf, board, uart="control", sim_limit=1e9, analog=analog) as b:
        def inputs():
            for pin, v in (analog or {}).items():
                b.set_analog(pin, v)

        def boot():
            b.eeprom_write(0, erased)
            b.reset("power")
            inputs()
            c, t, _, _ = _session(app, b, 0.0, 1)
            cuts0 = b.eeprom_count()[1]
            inner = t.events

            def events(wait):
                out = inner(wait)
                if b.eeprom_count()[1] != cuts0:
                    raise _Cut()
                return out

            t.events = events
            return c

        def change(c):
            slot, _ = c.upload(image, mask)
            c.activate(slot, wait=10)

        c = boot()
        w0 = b.eeprom_count()[0]
        change(c)
        res = CutRun(b.eeprom_count()[0] - w0)
        last = res.writes
        points = sorted(set(range(1, last + 1, stride)) | set(range(max(1, last - 8), last + 1)))
        for k in points:
            c = boot()
            b.eeprom_cut(k)
            try:
                change(c)
            except (_Cut, MachineError, ParamError):
                pass
            res.cases += 1
            inputs()
            c2, _t, _, _ = _session(app, b, 0.0, 1)  # the board after the cut, booted again
            inf = c2.info()
            s1 = inf.slots[0]
            if inf.active == 0:
                res.old += 1
                if s1.status == 2:
                    res.bad.append((k, "slot 1 is marked to boot but the generated machine runs"))
            elif inf.active == 1:
                res.new += 1
                if s1.status != 2 or s1.length != len(image) or s1.nmask != len(mask):
                    res.bad.append((k, f"runs slot 1, whose header says {s1}"))
                data = b.eeprom_read(9, len(image) + len(mask))
                if data != bytes(image) + bytes(mask):
                    res.bad.append((k, "runs slot 1, whose bytes are not the image's"))
            else:
                res.bad.append((k, f"runs {inf.active}"))
        return res
