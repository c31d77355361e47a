"""The flight recorder on an SPI NOR flash chip (docs/recorder.md, "On an SPI NOR flash chip"): the
tests/recorder/spi rig (the logged rig with `store spi_nor 10 1 M`, `record
128`) on the simulated Uno with a W25Q-class chip on D10 (PB2), and its
native build with the chip's model in a file, dumped over the link.

A flight is recorded on the chip and decodes with every sample checking
itself; a reset keeps it and the next flight is appended; the boot scan
reads a few records, not the chip; power cuts at random moments and right
after random page programs and sector erases lose nothing but the record in
progress and never leave a corrupt record valid."""

from __future__ import annotations

import os
import shutil
import time
from pathlib import Path

import pytest

from conftest import run_fsw
from fswkit.autocode.app import load_app
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.recorder import RECORDER_SIZE, decode, plan
from fswkit.testing.recorder_cuts import CutReport, _check_samples, power_cuts_nor, store_image, valid_records
from support.linkfw import PtyTarget
from support.simfw import OUT, kept_native, kept_sim

pytestmark = pytest.mark.costly(9, waits=True)

RIG = Path(__file__).resolve().parent / "spi"
LOGGED = Path(__file__).resolve().parent / "logged"
needs_sim = pytest.mark.skipif(shutil.which("avr-g++") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                               reason="gcc-avr and libsimavr-dev are needed (make setup)")
CHIP = "B2:1048576"  # the Uno's D10


@pytest.fixture(scope="module")
def built():
    elf, _board = kept_sim(RIG)
    return Path(elf), plan(load_app(str(RIG / "spi.app"), Diagnostics()))


def flight(b, seconds: float = 1.5) -> None:
    """A boot, then pin 2 high: a one-second flight."""
    b.reset()
    b.run_for(0.3)  # the boot's scan of the chip, at simavr's 100 us an SPI byte
    b.set_digital(2, True)
    b.run_for(seconds)
    b.set_digital(2, False)
    b.run_for(0.2)


def checked(p, img: bytes) -> CutReport:
    rep = CutReport()
    for s, raw in valid_records(p, img).items():
        _check_samples(p, s, raw, rep)
    assert rep.problems == []
    return rep


@needs_sim
def test_the_plan_and_the_ram_are_the_eeprom_recorders(built):
    from fswkit.sim.board import SimBoard

    elf, p = built
    assert (p.store, p.cs_pin, p.flash_size, p.base, p.slots, p.record) == ("spi_nor", 10, 1 << 20, 0, 8192, 128)
    with SimBoard(str(elf), "uno", uart="none", spi_flash=CHIP) as b:
        assert b.symbol("fsw_gen::(anonymous namespace)::rec")[1] == RECORDER_SIZE


@needs_sim
def test_a_flight_is_recorded_on_the_chip_and_the_next_one_appended_after_a_reset(built):
    from fswkit.sim.board import SimBoard

    elf, p = built
    with SimBoard(str(elf), "uno", uart="none", spi_flash=CHIP) as b:
        flight(b)
        img = store_image(b, p)
        assert len(img) == 4096  # one sector written
        flights, _ = decode(p, img)
        assert [f.number for f in flights] == [1] and flights[0].start is not None
        s = flights[0].samples
        assert len(s) >= 50 and {v["state"] for _, v in s} >= {1, 2}
        rep = checked(p, img)
        assert rep.samples_checked == len(s)
        first = valid_records(p, img)
        info = b.flash_info()
        assert info["erases"] == 1  # sector 0, before its first record
        flight(b)  # a reset: flight 1 stays, flight 2 follows it
        img2 = store_image(b, p)
        flights2, _ = decode(p, img2)
        assert [f.number for f in flights2] == [1, 2]
        assert flights2[0].samples == s
        now = valid_records(p, img2)
        assert all(now[k] == v for k, v in first.items())
        assert min(set(now) - set(first)) == max(first) + 1  # appended right after
        checked(p, img2)
        assert b.flash_info()["erases"] == 1  # the same sector: no erase


@needs_sim
def test_records_cross_sectors_each_erased_before_its_first_record(built):
    from fswkit.sim.board import SimBoard

    elf, p = built
    with SimBoard(str(elf), "uno", uart="none", spi_flash=CHIP) as b:
        # records up to the end of sector 0 as fixtures: copies of a real flight's records
        flight(b)
        recs = valid_records(p, store_image(b, p))
        n = len(recs)
        raw = b.flash_read(0, n * p.record)
        per = 4096 // p.record
        b.flash_erase()
        copies = raw * (per // n + 1)
        b.flash_write(0, copies[:(per - 1) * p.record])  # slots 0..per-2 hold records (seq numbers repeat)
        e0 = b.flash_info()["erases"]
        flight(b)
        img = store_image(b, p)
        now = valid_records(p, img)
        new = sorted(s for s in now if s >= per - 1)
        assert new and new[0] == per - 1 and new[-1] >= per  # the flight went on into sector 1
        assert b.flash_info()["erases"] == e0 + 1
        checked(p, img)


@needs_sim
def test_the_boot_scan_reads_a_few_records_not_the_chip(built):
    """The boot's binary search on a 1 MiB chip (8,192 slots): the SPI
    traffic from reset until the chip goes quiet, with two flights on it."""
    from fswkit.sim.board import SimBoard

    elf, p = built
    with SimBoard(str(elf), "uno", uart="none", spi_flash=CHIP) as b:
        flight(b)
        flight(b)
        b.watch(10)
        b.edges()
        b.reset()
        b.run_for(1.0)
        cs = [e for e in b.edges() if e.pin == 10]
        falls = [e for e in cs if not e.level]
        assert 10 <= len(falls) <= 40, len(falls)  # 13 probes, a record validated: not 8,192 reads
        cycles = cs[-1].cycle - falls[0].cycle
        seconds = cycles / 16e6
        print(f"boot scan: {len(falls)} transactions, {cycles} cycles ({seconds * 1000:.1f} ms simulated)")
        assert seconds < 0.25


@needs_sim
def test_power_cuts_lose_only_the_record_being_written(built):
    elf, p = built
    rep = power_cuts_nor(str(elf), p, 100, seed=11, spi_flash=CHIP)
    assert rep.problems == []
    assert rep.cuts == 100 and rep.resets == 50 and rep.write_cuts == 50
    assert rep.flights >= 60 and rep.records_checked >= 100 and rep.samples_checked >= 1000
    assert rep.lost_in_progress >= 20


# ---- the native build: the chip in a file, dumped over the link ---------------------

@pytest.fixture(scope="module")
def exe():
    """The rig on a 64 KiB chip (512 slots: `fsw dump` reads every slot)."""
    if shutil.which("g++") is None:
        pytest.skip("no host C++ compiler")
    # a copy of the rig kept in build/sim-tests/ with its build (support.simfw.kept_native): a file is
    # written only when its text changed, so a warm run's build finds everything up to date
    src = OUT / "spi-64k"
    src.mkdir(parents=True, exist_ok=True)
    texts = {f.name: f.read_text() for f in RIG.iterdir() if f.is_file()}
    texts["spi.app"] = texts["spi.app"].replace("store   spi_nor 10 1 M", "store   spi_nor 10 64 K")
    assert "spi_nor 10 64 K" in texts["spi.app"]
    for f in src.iterdir():
        if f.is_file() and f.name not in texts:
            f.unlink()
    for name, text in texts.items():
        if not (src / name).is_file() or (src / name).read_text() != text:
            (src / name).write_text(text)
    return src, kept_native(src) / "spi"


def test_the_native_build_keeps_the_chip_in_a_file_and_dumps_it(exe, tmp_path):
    from test_recorder_link import check_flight, rows

    src, exe = exe
    chip = tmp_path / "flash.bin"
    with PtyTarget(exe, "--flash", str(chip), "d2=1") as t:
        time.sleep(1.6)
        r = run_fsw("dump", str(src), "--port", t.port, "-o", str(tmp_path / "d1"))
        assert r.code == 0, r.err
        assert "1 flight(s)" in r.out
    assert chip.stat().st_size == 64 << 10
    image = chip.read_bytes()
    p = plan(load_app(str(src / "spi.app"), Diagnostics()))
    assert image[4096:] == b"\xff" * (len(image) - 4096)  # only sector 0 written
    flights, _ = decode(p, image)
    assert [f.number for f in flights] == [1]
    samples = rows(tmp_path / "d1" / "flight-1.log")
    check_flight(samples)
    with PtyTarget(exe, "--flash", str(chip), "d2=1") as t:  # a restart: flight 2 is appended
        time.sleep(1.6)
        r = run_fsw("dump", str(src), "--port", t.port, "-o", str(tmp_path / "d2"), "--all")
        assert r.code == 0, r.err
        assert "2 flight(s)" in r.out
    assert rows(tmp_path / "d2" / "flight-1.log") == samples
    check_flight(rows(tmp_path / "d2" / "flight-2.log"))


def test_erase_over_the_link_erases_the_sectors_in_use(exe, tmp_path):
    src, exe = exe
    chip = tmp_path / "flash.bin"
    with PtyTarget(exe, "--flash", str(chip), "d2=1") as t:
        time.sleep(1.6)
        r = run_fsw("dump", str(src), "--port", t.port, "-o", str(tmp_path / "d"), "--erase", "--yes", "--force")
        assert r.code == 0 and "erasing" in r.out, r.err
        time.sleep(0.5)  # 45 ms a sector on the model's clock
        r = run_fsw("dump", str(src), "--port", t.port, "-o", str(tmp_path / "again"))
        assert r.code == 0 and "0 flight(s)" in r.out, r.out + r.err
    assert chip.read_bytes() == b"\xff" * (64 << 10)


@needs_sim
def test_closed_loop_flights_carry_the_chip_on_the_cs_pin():
    from fswkit.plant.cosim import _nor

    app = load_app(str(RIG / "spi.app"), Diagnostics())
    p, chip = _nor(app, "uno")
    assert chip == CHIP and p.store == "spi_nor"
    assert _nor(load_app(str(LOGGED / "logged.app"), Diagnostics()), "uno") is None
