"""Records on an SPI NOR chip are numbered in 16 bits: at most 65,535 of
them, so `store spi_nor 10 16 M` with `record 32` uses 2 MiB of the 16 MiB
chip, and `store spi_nor 10` (8 MiB by default) with the default 64-byte
records 4 MiB of 8. docs/recorder.md says so, and the checker defined the
limit but never used it: `fsw check` said "0 warnings" and the user
believed in hours of recording the firmware never has room for. It is now
a warning at the size (or at `spi_nor` when the size is the default),
saying how much of the chip is used and how to use more."""

from __future__ import annotations

import shutil

from conftest import ROOT, run_fsw

RIG = ROOT / "tests" / "recorder" / "spi"


def _check(tmp_path, store: str, record: str):
    proj = tmp_path / "p"
    shutil.copytree(RIG, proj)
    app = (proj / "spi.app").read_text()
    assert "store   spi_nor 10 1 M" in app and "record  128" in app
    (proj / "spi.app").write_text(app.replace("store   spi_nor 10 1 M", store).replace("record  128", record))
    return run_fsw("check", str(proj / "spi.app"))


def test_a_chip_past_65535_records_is_a_warning_at_its_size(tmp_path):
    r = _check(tmp_path, "store   spi_nor 10 16 M", "record  32")
    text = r.out + r.err
    assert r.code == 0 and "1 warning" in text, text
    assert "spi.app:26:20" in text and "2,097,120 B of the 16,777,216 B chip" in text and "65,535" in text, text


def test_the_default_size_is_warned_at_spi_nor(tmp_path):
    r = _check(tmp_path, "store   spi_nor 10", "record  64")
    text = r.out + r.err
    assert r.code == 0 and "spi.app:26:9" in text and "of the 8,388,608 B chip" in text, text


def test_a_chip_the_records_fill_is_quiet(tmp_path):
    r = _check(tmp_path, "store   spi_nor 10 8 M", "record  128")
    assert r.code == 0 and "0 warnings" in r.out + r.err, r.out + r.err
