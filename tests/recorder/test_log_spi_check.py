"""`[log] store spi_nor PIN [SIZE]` (docs/recorder.md, "On an SPI NOR flash chip"): each mistake is
reported where it is written, by `fsw check` on the tests/recorder/spi rig
with one line changed."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from conftest import run_fsw
from fswkit.autocode.app import load_app
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.recorder import plan

RIG = Path(__file__).resolve().parent / "spi"
STORE = "store   spi_nor 10 1 M"


def project(tmp_path: Path, old: str, new: str) -> Path:
    for f in RIG.iterdir():
        if f.is_file():
            shutil.copy(f, tmp_path / f.name)
    app = tmp_path / "spi.app"
    text = app.read_text()
    assert old in text
    app.write_text(text.replace(old, new))
    return tmp_path


CASES = [
    # (old line, new line, line:col, words of the message)
    (STORE, "store   spi_nor 25", "26:17", "the uno has no digital pin `25` for the flash's chip select"),
    (STORE, "store   spi_nor 10x", "26:17", "malformed number"),
    (STORE, "store   spi_nor 13", "26:17", "pin 13 is the SPI bus's SCK on the uno"),
    (STORE, "store   spi_nor 11", "26:17", "pin 11 is the SPI bus's MOSI on the uno"),
    (STORE, "store   spi_nor 12", "26:17", "pin 12 is the SPI bus's MISO on the uno"),
    (STORE, "store   spi_nor 1", "26:17", "pin 1 is reserved on the uno: serial TX"),
    (STORE, "store   spi_nor 2", "26:17", "pin 2 is already the channel of `go` (spi.dio:1)"),
    (STORE, "store   spi_nor 10 3 M", "26:20", "the flash's size is a power of two from 64 K to 16 M"),
    (STORE, "store   spi_nor 10 32 M", "26:20", "found `32 M`"),
    (STORE, "store   spi_nor 10 32 K", "26:20", "found `32 K`"),
    (STORE, "store   spi_nor 10 1000000", "26:20", "found `1000000`"),
    (STORE, "store   spi_nor 10 1 G", "26:22", "`store spi_nor` takes the chip select's pin, then the chip's size"),
    (STORE, "store   spi_nor", "26:9", "`store spi_nor` takes the chip select's pin"),
    (STORE, "store   flash 10", "26:9", "`store` takes one of: eeprom, spi_nor PIN [SIZE]"),
    (STORE, "store   eeprom 10", "26:16", "`store` takes one of: eeprom, spi_nor PIN [SIZE]"),
    ("record  128", "record  100", "27:9", "`record` on spi_nor is a power of two from 32 to 128"),
    ("record  128", "record  255", "27:9", "records never straddle a 4096-byte sector"),
    ("full    stop", "full    newest", "28:9", "`full newest` is not available on spi_nor: a flash sector is erased whole"),
]


@pytest.mark.parametrize("old,new,where,words", CASES)
def test_each_mistake_is_reported_where_it_is_written(tmp_path, old, new, where, words):
    r = run_fsw("check", str(project(tmp_path, old, new)))
    assert r.code != 0
    assert f"spi.app:{where}:" in r.err, r.err
    assert words in r.err, r.err
    assert "1 error" in r.err, r.err


@pytest.mark.parametrize("store,size", [("store   spi_nor 10", 8 << 20), ("store   spi_nor 9 1 M", 1 << 20),
                                        ("store   spi_nor 10 64 K", 64 << 10), ("store   spi_nor 10 2048 K", 2 << 20),
                                        ("store   spi_nor 10 16777216", 16 << 20)])
def test_good_stores_are_planned_on_the_whole_chip(tmp_path, store, size):
    d = project(tmp_path, STORE, store)
    r = run_fsw("check", str(d))
    assert r.code == 0, r.err
    p = plan(load_app(str(d / "spi.app"), Diagnostics()))
    assert (p.store, p.flash_size, p.base, p.record) == ("spi_nor", size, 0, 128)
    assert p.cs_pin == int(store.split()[2])
    assert p.slots == min(size // 128, 65535)


def test_slots_are_capped_at_65535(tmp_path):
    d = project(tmp_path, "record  128", "record  32")
    p = plan(load_app(str(d / "spi.app"), Diagnostics()))
    assert p.slots == (1 << 20) // 32 == 32768
    d2 = tmp_path / "big"
    d2.mkdir()
    d2 = project(d2, STORE, "store   spi_nor 10 16 M")
    p = plan(load_app(str(d2 / "spi.app"), Diagnostics()))
    assert p.slots == 65535
