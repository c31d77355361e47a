"""A flight recorder on an SPI NOR flash (`[log] store spi_nor PIN`) took
the SPI bus without claiming its pins: examples/hpr with its arming key
moved to pin 12 (MISO) and its log on a flash at pin 10 passed `fsw check`
and built, and the arming input then read the flash's data; its status LED
on pin 13 (SCK) was accepted too and showed the SPI clock. And with the SPI
in use, by the flash or by an SPI sensor part, a channel on the SPI's SS
pin (10 on an Uno, 53 on a Mega 2560) was accepted, although the firmware
makes SS an output and drives it high at boot (psl_arduino.cpp
`spi_bus_begin`, from `log_begin`, before the channels are set up): an
input there read the MCU's own output, an arming key that always reads
armed, and a pyro channel there (the drogue on pin 10) went high at boot
for as long as the flash's boot scan took. Each is now refused where it is
written; a chip select on SS is still fine."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from conftest import EXAMPLES

SPI_LOG = ("store   eeprom", "store   spi_nor {cs} 1 M"), ("record  64", "record  128")


def hpr(tmp_path: Path, name: str = "hpr", dio: dict[str, str] | None = None, app: tuple = (),
        board: str = "uno") -> Path:
    """examples/hpr (or hpr_digital, with hpr's tables copied beside it) with
    lines of its .dio and .app replaced."""
    shutil.copytree(EXAMPLES / "hpr", tmp_path / "hpr")
    if name == "hpr_digital":
        shutil.copytree(EXAMPLES / "hpr_digital", tmp_path / "hpr_digital")
    d = tmp_path / "hpr"
    text = (d / "hpr.dio").read_text()
    for old, new in (dio or {}).items():
        assert old in text
        text = text.replace(old, new)
    (d / "hpr.dio").write_text(text)
    a = tmp_path / name / f"{name}.app"
    text = a.read_text().replace("board uno", f"board {board}")
    for old, new in app:
        assert old in text, old
        text = text.replace(old, new)
    a.write_text(text)
    return a


def spi_log(cs: int) -> tuple:
    return tuple((old, new.format(cs=cs)) for old, new in SPI_LOG)


LED_OFF_SCK = {"o      13   led": "o      7    led"}


def test_an_input_on_miso_with_a_flash_log_is_refused_at_the_store(fsw, tmp_path):
    app = hpr(tmp_path, dio={"i      2    armSwitch": "i      12   armSwitch", **LED_OFF_SCK}, app=spi_log(10))
    r = fsw("check", str(app))
    assert r.code == 1, r.out
    assert "hpr.app:39:9:" in r.err
    assert "pin 12 is the SPI bus's MISO" in r.err and "`armSwitch` (hpr.dio:3)" in r.err
    assert "Traceback" not in r.err


def test_an_output_on_sck_with_a_flash_log_is_refused(fsw, tmp_path):
    app = hpr(tmp_path, app=spi_log(10))  # the LED stays on 13
    r = fsw("check", str(app))
    assert r.code == 1, r.out
    assert "pin 13 is the SPI bus's SCK" in r.err and "output channel of `led` (hpr.dio:7)" in r.err


def test_a_flash_log_with_its_bus_pins_free_is_accepted(fsw, tmp_path):
    app = hpr(tmp_path, dio=LED_OFF_SCK, app=spi_log(10))
    r = fsw("check", str(app))
    assert r.code == 0, r.err


def test_an_input_on_ss_with_a_flash_log_is_refused(fsw, tmp_path):
    app = hpr(tmp_path, dio={"i      2    armSwitch": "i      10   armSwitch", **LED_OFF_SCK}, app=spi_log(4))
    r = fsw("check", str(app))
    assert r.code == 1, r.out
    assert "hpr.app:39:9:" in r.err
    assert "pin 10 is the SPI's SS" in r.err and "input channel of `armSwitch`" in r.err


def test_an_input_on_the_megas_ss_with_a_flash_log_is_refused(fsw, tmp_path):
    app = hpr(tmp_path, board="mega2560", dio={"i      2    armSwitch": "i      53   armSwitch", **LED_OFF_SCK},
              app=spi_log(4))
    r = fsw("check", str(app))
    assert r.code == 1, r.out
    assert "pin 53 is the SPI's SS" in r.err
    # pin 10 is no SS on the Mega: an input there is fine
    app = hpr(tmp_path / "b", board="mega2560", dio={"i      2    armSwitch": "i      10   armSwitch"},
              app=spi_log(4))
    r = fsw("check", str(app))
    assert r.code == 0, r.err


def test_a_pyro_output_on_ss_with_a_flash_log_is_refused(fsw, tmp_path):
    app = hpr(tmp_path, dio={"o      5    drogue": "o      10   drogue", **LED_OFF_SCK}, app=spi_log(4))
    r = fsw("check", str(app))
    assert r.code == 1, r.out
    assert "pin 10 is the SPI's SS, which the firmware drives high at boot" in r.err
    assert "output channel of `drogue` (hpr.dio:4)" in r.err


def test_the_flash_chip_select_on_ss_is_accepted(fsw, tmp_path):
    app = hpr(tmp_path, dio=LED_OFF_SCK, app=spi_log(10))
    r = fsw("check", str(app))
    assert r.code == 0, r.err


ADXL_SPI = ("adxl345   i2c:0x53   range=16 rate=400 stuck=50   z=accel fault=accelFault",
            "adxl345   spi:4      range=16 rate=400 stuck=50   z=accel fault=accelFault")


@pytest.mark.parametrize("dio_first", [True, False])
def test_an_input_on_ss_with_an_spi_part_is_refused_in_either_order(fsw, tmp_path, dio_first):
    app = hpr(tmp_path, "hpr_digital", dio={"i      2    armSwitch": "i      10   armSwitch", **LED_OFF_SCK})
    sns = app.parent / "hpr_digital.sns"
    sns.write_text(sns.read_text().replace(*ADXL_SPI))
    if dio_first:
        text = app.read_text()
        app.write_text(text.replace("io           hpr_digital.sns\nio           ../hpr/hpr.dio\n",
                                    "io           ../hpr/hpr.dio\nio           hpr_digital.sns\n"))
    r = fsw("check", str(app))
    assert r.code == 1, r.out
    assert "Traceback" not in r.err
    if dio_first:  # at the part's bus, naming the channel
        assert "hpr_digital.sns:" in r.err and "pin 10 is the SPI's SS" in r.err
    else:  # at the channel's pin, naming the part
        assert "hpr.dio:3:8:" in r.err and "pin `10` cannot be a channel's: it is the SPI's SS" in r.err
        assert "the SPI part at hpr_digital.sns:" in r.err


def test_an_spi_part_with_an_output_on_ss_after_it_is_refused(fsw, tmp_path):
    app = hpr(tmp_path, "hpr_digital", dio={"o      8    buzzer": "o      10   buzzer", **LED_OFF_SCK})
    sns = app.parent / "hpr_digital.sns"
    sns.write_text(sns.read_text().replace(*ADXL_SPI))
    r = fsw("check", str(app))
    assert r.code == 1, r.out
    assert "hpr.dio:6:8:" in r.err and "pin `10` cannot be a channel's" in r.err


def test_an_spi_part_with_its_chip_select_on_ss_is_accepted(fsw, tmp_path):
    app = hpr(tmp_path, "hpr_digital", dio=LED_OFF_SCK)
    sns = app.parent / "hpr_digital.sns"
    sns.write_text(sns.read_text().replace(ADXL_SPI[0], ADXL_SPI[1].replace("spi:4 ", "spi:10")))
    r = fsw("check", str(app))
    assert r.code == 0, r.err
