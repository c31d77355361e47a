"""Power cuts while the flight recorder writes (docs/recorder.md): the
engine of tests/recorder/test_recorder_power.py (a few hundred cuts) and of
tools/bench_recorder.py (1,000).

The firmware is the tests/recorder/logged rig on the simulated Uno: its
pin 2 held high starts a one-second "flight" at each boot, recorded at
50 Hz in 64-byte records; each sample checks itself (the level is the time
/ 4, the count goes up by two between samples). Two kinds of cut alternate:

- a reset at a random moment: the recorder's state is read from the MCU's
  RAM just before, so the number of whole records it had written is known;
  after the reboot exactly that many must be valid (only the record being
  built may be lost);
- a cut right after the firmware's Nth EEPROM byte write (N at random), so
  records are torn at every byte: the clear, the body, the tail, the kind.

After each cut the whole store is decoded as `fsw dump` decodes it, and
checked: every record valid before is still there byte for byte (earlier
flights intact), the valid records are the first k with no hole, every
accepted record decodes and every sample checks itself (no corrupt record
accepted). When the store is nearly full it is erased, as `fsw dump --erase`
does (every record's first byte cleared), and the board restarted."""

from __future__ import annotations

import random
import struct
from dataclasses import dataclass, field

from fswkit.autocode.recorder import Plan, RecordError, decode_slot

HEAD_OFF = 6  # Recorder::head: after cfg (2 B on an AVR) and t_next (4)
W_PHASE_OFF = 21  # Recorder::w_phase


@dataclass
class CutReport:
    cuts: int = 0
    resets: int = 0  # cuts at a random moment
    write_cuts: int = 0  # cuts after the Nth EEPROM write
    records_checked: int = 0
    samples_checked: int = 0
    flights: int = 0
    erases: int = 0
    lost_in_progress: int = 0  # cuts that lost the record being written
    problems: list[str] = field(default_factory=list)


def _valid(p: Plan, img: bytes) -> dict[int, bytes]:
    out = {}
    for s in range(p.slots):
        raw = img[s * p.record:(s + 1) * p.record]
        try:
            rec = decode_slot(p, s, raw)
        except RecordError:
            rec = "corrupt"
        if rec is not None:
            out[s] = raw
    return out


def _check_samples(p: Plan, slot: int, raw: bytes, rep: CutReport) -> None:
    try:
        rec = decode_slot(p, slot, raw)
    except RecordError as e:
        rep.problems.append(f"a record whose CRC is right does not decode: {e}")
        return
    rep.records_checked += 1
    prev = None
    for t, v in rec.samples:
        rep.samples_checked += 1
        if abs(v["level"] - t / 4) > 0.125:
            rep.problems.append(f"record {slot}: level {v['level']} at {t} ms (expected {t / 4})")
        if prev is not None and v["state"] == 2 and prev[1] == 2 and v["count"] != prev[0] + 2:
            rep.problems.append(f"record {slot}: count {v['count']} after {prev[0]} at {t} ms")
        prev = (v["count"], v["state"])


def power_cuts(elf: str, p: Plan, cuts: int, seed: int = 1, *, board: str = "uno") -> CutReport:
    from fswkit.sim.board import SimBoard

    rnd = random.Random(seed)
    rep = CutReport()
    with SimBoard(elf, board, uart="none") as b:
        rec_addr, rec_size = b.symbol("fsw_gen::(anonymous namespace)::rec")

        def boot() -> None:  # a reset, then pin 2 driven high once the firmware has set its pins up
            b.reset()
            b.run_for(0.002)
            b.set_digital(2, True)

        b.eeprom_write(p.base, bytes(p.size))  # a blank store, as after an erase
        before = {}
        for i in range(cuts):
            if len(before) > p.slots - 5:  # nearly full: erase (every record's kind cleared), restart
                b.eeprom_write(p.base, bytes(p.size))
                before = {}
                rep.erases += 1
            boot()  # a new boot: a new flight
            if i % 2 == 0:
                b.run_for(rnd.uniform(0.02, 1.2))
                state = b.peek(rec_addr, rec_size)
                head = struct.unpack_from("<H", state, HEAD_OFF)[0]
                writing = state[W_PHASE_OFF] != 0
                b.reset()
                b.run_for(0.001)
                rep.resets += 1
                img = b.eeprom_read(p.base, p.size)
                now = _valid(p, img)
                expected = set(range(head)) if head <= p.slots else set(range(p.slots))
                if set(now) != expected:
                    rep.problems.append(f"cut {i}: records {sorted(now)} after a reset with {head} written")
                rep.lost_in_progress += writing
            else:
                w0, c0 = b.eeprom_count()
                b.eeprom_cut(rnd.randint(1, 160))
                for _ in range(20):
                    b.run_for(0.1)
                    if b.eeprom_count()[1] > c0:
                        break
                else:
                    rep.problems.append(f"cut {i}: the EEPROM cut never came")
                rep.write_cuts += 1
                img = b.eeprom_read(p.base, p.size)
                now = _valid(p, img)
            rep.cuts += 1
            for s, raw in before.items():
                if now.get(s) != raw:
                    rep.problems.append(f"cut {i}: record {s}, valid before, is {'changed' if s in now else 'lost'}")
            if sorted(now) != list(range(len(now))):
                rep.problems.append(f"cut {i}: a hole among the valid records {sorted(now)}")
            for s, raw in now.items():
                if s not in before:
                    _check_samples(p, s, raw, rep)
                    if raw[0] == 0xF0:
                        rep.flights += 1
            before = now
            if len(rep.problems) > 20:
                break
    return rep
