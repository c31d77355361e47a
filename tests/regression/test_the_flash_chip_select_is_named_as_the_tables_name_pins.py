"""The flight recorder's `store spi_nor PIN` took only a pin number: `store
spi_nor A0` on an Uno said "the uno has no digital pin `A0` for the
flash's chip select (digital pins: 0..19)", false (A0 is digital pin 14,
and the .dio tables and a sensor part's `spi:A0` take it by that name).
Now the chip select is named as the I/O tables name pins, `A0` or `14`,
and a name the board does not have, or an analog-only pin, is still
refused."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES, run_fsw

ROCKET = EXAMPLES / "rocket"


@pytest.fixture
def rocket(tmp_path):
    for p in ROCKET.iterdir():
        if p.is_file():
            (tmp_path / p.name).write_bytes(p.read_bytes())
    # the SPI takes 11, 12 and 13: the led goes to 4; A0..A3 are the .aio's: the flash takes A4 or A5
    dio = (tmp_path / "rocket.dio").read_text()
    assert "o      13   led" in dio
    (tmp_path / "rocket.dio").write_text(dio.replace("o      13   led", "o      4    led"))
    return tmp_path


def store(rocket, pin):
    app = (rocket / "rocket.app").read_text()
    old = next(ln for ln in app.splitlines() if ln.startswith("store"))
    app = app.replace(old, f"store   spi_nor {pin} 1 M").replace("record  64 ", "record  128")
    (rocket / "rocket.app").write_text(app)
    return run_fsw("check", "rocket.app", cwd=rocket)


@pytest.mark.parametrize("pin", ["A4", "18", "A5", "7"])
def test_a_chip_select_by_name_or_number_is_accepted(rocket, pin):
    r = store(rocket, pin)
    assert r.code == 0, r.err


def test_a_named_pin_a_channel_has_is_refused_as_a_number_is(rocket):
    r = store(rocket, "A0")
    assert r.code == 1 and "pin 14 is already the channel of `pressure` (rocket.aio:" in r.err, r.err


@pytest.mark.parametrize("pin,why", [("A7", "has no digital pin `A7`"), ("B2", "has no digital pin `B2`"),
                                     ("0", "reserved")])
def test_pins_the_board_lacks_are_refused(rocket, pin, why):
    r = store(rocket, pin)
    assert r.code == 1 and why in r.err and "internal error" not in r.err, r.err


def test_an_analog_only_pin_of_the_nano_is_refused(rocket):
    app = (rocket / "rocket.app").read_text()
    (rocket / "rocket.app").write_text(app.replace("board uno", "board nano"))
    r = store(rocket, "A6")
    assert r.code == 1 and "has no digital pin `A6`" in r.err, r.err
