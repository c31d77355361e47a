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


def _compare(p: Plan, i: int, before: dict[int, bytes], now: dict[int, bytes], rep: CutReport) -> None:
    """After cut `i`: every record valid before is there byte for byte; the
    new ones decode and every sample checks itself."""
    for s, raw in before.items():
        if now.get(s) != raw:
            rep.problems.append(f"cut {i}: record {s}, valid before, is {'changed' if s in now else 'lost'}")
    for s, raw in now.items():
        if s not in before:
            _check_samples(p, s, raw, rep)
            if raw[0] == 0xF0:
                rep.flights += 1


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
                now = valid_records(p, img)
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
                now = valid_records(p, img)
            rep.cuts += 1
            if sorted(now) != list(range(len(now))):
                rep.problems.append(f"cut {i}: a hole among the valid records {sorted(now)}")
            _compare(p, i, before, now, rep)
            before = now
            if len(rep.problems) > 20:
                break
    return rep


# ---- any store: the EEPROM or an SPI NOR flash (docs/recorder.md, "On an SPI NOR flash chip") ------------------

NOR_SECTOR = 4096


def store_image(b, p: Plan) -> bytes:
    """The recorder's store on the simulated board `b` as `decode` takes it:
    the EEPROM's `p.size` bytes from `p.base`, or the SPI flash's written part
    (whole 4 KiB sectors from 0 up to the first blank one)."""
    if p.store != "spi_nor":
        return b.eeprom_read(p.base, p.size)
    out = bytearray()
    end = min(p.slots * p.record, p.flash_size)
    while len(out) < end:
        sector = b.flash_read(len(out), NOR_SECTOR)
        if sector == b"\xff" * NOR_SECTOR:
            break
        out += sector
    return bytes(out)


def valid_records(p: Plan, img: bytes) -> dict[int, bytes]:
    """Slot -> bytes of every whole record in a store image (any store;
    a short image: the slots past its end are blank)."""
    out = {}
    for s in range(min(p.slots, len(img) // p.record)):
        raw = img[s * p.record:(s + 1) * p.record]
        try:
            rec = decode_slot(p, s, raw)
        except RecordError:
            rec = "corrupt"
        if rec is not None:
            out[s] = raw
    return out


def power_cuts_nor(elf: str, p: Plan, cuts: int, seed: int = 1, *, board: str = "uno",
                   spi_flash: str = "B2:1048576", boot_s: float = 0.3) -> CutReport:
    """Power cuts on the SPI NOR store, on the tests/recorder/spi rig (the
    logged rig's firmware on a flash chip): resets at random moments, and
    cuts right after a random page program or sector erase starts (left half
    done, as the chip model does). After each: every record valid before is
    still there byte for byte; every valid record decodes and its samples
    check themselves (no corrupt record accepted); after a reset, every
    record the Recorder had finished (its head, read from RAM just before)
    since the boot is valid (only the one in progress is lost); new records
    only ever follow the old ones (a torn slot is skipped, never
    reprogrammed). `erases` counts the times the test blanked the chip
    (nearly full); `boot_s` is waited after a reset for the boot's scan."""
    from fswkit.sim.board import SimBoard

    rnd = random.Random(seed)
    rep = CutReport()
    with SimBoard(elf, board, uart="none", spi_flash=spi_flash) as b:
        rec_addr, rec_size = b.symbol("fsw_gen::(anonymous namespace)::rec")

        def head() -> tuple[int, bool]:
            state = b.peek(rec_addr, rec_size)
            return struct.unpack_from("<H", state, HEAD_OFF)[0], state[W_PHASE_OFF] != 0

        before: dict[int, bytes] = {}
        for i in range(cuts):
            if max(before, default=0) > p.slots - 8:
                b.flash_erase()
                before = {}
                rep.erases += 1
            b.reset()  # a new boot: pin 2 high once the scan is over starts a flight
            b.run_for(boot_s)
            head0 = head()[0]
            if before and head0 <= max(before):
                rep.problems.append(f"cut {i}: the boot goes on at slot {head0}, not after record {max(before)}")
            b.set_digital(2, True)
            if i % 2 == 0:
                b.run_for(rnd.uniform(0.02, 1.2))
                h, writing = head()
                b.reset()
                b.set_digital(2, False)
                b.run_for(0.001)
                rep.resets += 1
                rep.lost_in_progress += writing
                now = valid_records(p, store_image(b, p))
                lost = sorted(set(range(head0, h)) - set(now))
                if lost:
                    rep.problems.append(f"cut {i}: records {lost}, finished before the reset, are not valid")
            else:
                c0 = b.flash_info()["cuts"]
                b.flash_cut(rnd.randint(1, 40))
                for _ in range(40):
                    b.run_for(0.1)
                    if b.flash_info()["cuts"] > c0:
                        break
                else:
                    rep.problems.append(f"cut {i}: the flash cut never came")
                b.set_digital(2, False)
                rep.write_cuts += 1
                now = valid_records(p, store_image(b, p))
            rep.cuts += 1
            for s in now:
                if s not in before and before and s < max(before):
                    rep.problems.append(f"cut {i}: a new record {s} among the old ones (last {max(before)})")
            _compare(p, i, before, now, rep)
            before = now
            if len(rep.problems) > 20:
                break
    return rep
