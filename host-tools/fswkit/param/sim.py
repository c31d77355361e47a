"""Parameters over a simulated radio: the firmware on the simulated board,
the ground's client on the other end of its UART, frames dropped at random
in each direction. Used by the lossy-link test and `make bench`
(tools/bench_params.py); every time here is simulated time."""

from __future__ import annotations

import random
from dataclasses import dataclass

from fswkit.autocode.protocol import crc16


@dataclass
class LossyRun:
    list_s: float  # simulated seconds to read every value
    load_s: float  # ... to stage, commit, and verify a whole file (the bank written)
    verified: bool  # the target's live CRC is the file's, and its bank advanced
    sent: int
    resent: int
    busy: int
    up_frames: int
    up_dropped: int
    down_frames: int
    down_dropped: int
    values_ok: bool  # the values read back after the load are the file's


def lossy_list_and_load(elf: str, board: str, app, loss: float, seed: int) -> LossyRun:
    """Boots the firmware, then lists every parameter and loads a file that
    changes each of them, through a link that drops `loss` of the frames in
    each direction."""
    from fswkit.autocode.params import app_parameters
    from fswkit.autocode.schema import link_plan
    from fswkit.link.layout import from_app
    from fswkit.link.session import Session
    from fswkit.sim.board import SimBoard

    from .client import Lossy, ParamClient, SimTransport

    params = app_parameters(app)
    rnd = random.Random(seed)
    with SimBoard(elf, board, uart="control", sim_limit=120) as b:
        session = Session(from_app(app))
        up, down = Lossy(loss, rnd), Lossy(loss, rnd)
        t = SimTransport(b, session, up, down)
        while session.hello is None and b.time < 10:  # the boot hello (or a later one) confirms the schema
            t.events(0.05)
        client = ParamClient(t, params, link_plan(app).tx_cap, timeout=0.3, deadline=60, baud=app.baud)
        t0 = t.now()
        values = client.get_all()
        list_s = t.now() - t0
        new = {}
        for p in params:  # every value changed, within its range
            v = values[p.name]
            if p.type.is_bool:
                new[p.name] = not v
            elif p.type.is_float:
                new[p.name] = p.min + (p.max - p.min) * rnd.random()
                new[p.name] = p.unpack(p.pack(new[p.name]))
            else:
                new[p.name] = rnd.randint(p.min, p.max)
        t1 = t.now()
        inf = client.load(new, current=values)
        load_s = t.now() - t1
        block = b"".join(p.pack(new[p.name]) for p in params)
        back = client.get_all()
        ok = all(p.pack(back[p.name]) == p.pack(new[p.name]) for p in params)
        return LossyRun(list_s, load_s, inf["crc"] == crc16(block), client.stats.sent, client.stats.resent,
                        client.stats.busy, up.frames, up.dropped, down.frames, down.dropped, ok)


class _Cut(Exception):
    """The board lost power (the harness reset it at an EEPROM write)."""


@dataclass
class CutRun:
    writes: int  # EEPROM byte writes the change takes
    cases: int  # cut points tried
    old: int  # reboots that came up with the old set
    new: int  # ... with the new set
    bad: list  # (cut point, what was wrong): a mix, no valid bank, live values not the bank's


def power_cuts(elf: str, board: str, app, stride: int = 1, seed: int = 1, op: str = "load") -> CutRun:
    """A change of every parameter (op "load": a whole file; "save": a SET
    of the first values, then SAVE) interrupted by a power cut after the
    1st, 1+stride-th, ... EEPROM byte write. After each reboot the live
    values must be the old set or the new one, and equal the newest valid
    bank."""
    from fswkit.autocode.params import HEADER, app_parameters, bank_image, block_size, valid_banks
    from fswkit.autocode.schema import link_plan
    from fswkit.link.layout import from_app
    from fswkit.link.session import Session
    from fswkit.sim.board import SimBoard

    from .client import ParamClient, ParamError, SimTransport

    params = app_parameters(app)
    size = block_size(params)
    rnd = random.Random(seed)
    old = {p.name: p.default for p in params}
    new = {}
    for p in params:
        if p.type.is_bool:
            new[p.name] = not p.default
        elif p.type.is_float:
            new[p.name] = p.unpack(p.pack(p.min + (p.max - p.min) * rnd.random()))
        else:
            new[p.name] = rnd.randint(p.min, p.max)
    if op == "save":  # the values one SET carries; the others stay
        first = params[:3]
        new = {p.name: (new[p.name] if p in first else old[p.name]) for p in params}
    old_block = b"".join(p.pack(old[p.name]) for p in params)
    new_block = b"".join(p.pack(new[p.name]) for p in params)
    machines = [m for m in app.machines if any(v.param is not None for v in m.vars)]
    layout = from_app(app)
    tx_cap = link_plan(app).tx_cap
    with SimBoard(elf, board, uart="control", sim_limit=1e9) as b:
        blocks = [b.symbol(f"fsw_gen::{m.name}::prm") for m in machines]

        def live() -> bytes:
            return b"".join(b.peek(a, n) for a, n in blocks)

        def boot():
            b.eeprom_write(0, bank_image(params, old, seq=1) + b"\xff" * (HEADER + size))
            b.reset()
            session = Session(layout)
            cuts0 = b.eeprom_count()[1]

            class Watch(SimTransport):
                def events(self, wait):
                    out = super().events(wait)
                    if b.eeprom_count()[1] != cuts0:
                        raise _Cut()
                    return out

            t = Watch(b, session)
            while session.hello is None:
                t.events(0.05)
            return ParamClient(t, params, tx_cap, timeout=0.3, deadline=20, baud=app.baud)

        def change(c):
            if op == "load":
                c.load(new, current=old)
            else:
                c.set({p.name: new[p.name] for p in params[:3]})
                c.save()

        c = boot()
        w0 = b.eeprom_count()[0]
        change(c)
        writes = b.eeprom_count()[0] - w0
        if live() != new_block:
            raise AssertionError("the change without a cut did not take")
        res = CutRun(writes, 0, 0, 0, [])
        points = sorted(set(range(1, writes + 1, stride)) | {writes - 1, writes})  # the last two: magic
        for k in points:
            c = boot()
            b.eeprom_cut(k)
            try:
                change(c)
            except (_Cut, ParamError):
                pass
            b.run_for(0.1)  # the reboot after the cut
            res.cases += 1
            now = live()
            banks = valid_banks(params, b.eeprom_read(0, 2 * (HEADER + size)))
            if now == old_block:
                res.old += 1
            elif now == new_block:
                res.new += 1
            else:
                res.bad.append((k, "a mix of the old and the new set"))
                continue
            if not banks:
                res.bad.append((k, "no valid bank"))
            elif banks[0][2] != now:
                res.bad.append((k, "the live values are not the newest valid bank's"))
        return res
