"""A channel on a pin a sensor part took in an earlier `.sns` table was
refused as `pin A4 is already used (baro.sns:1)`, pointing at a row that
names no pin (`bmp280 i2c:0x76 ...`): the part took A4 as its bus's SDA,
which the user had to know. Now the message says what the pin is there:
the I2C bus's SDA or SCL, the SPI bus's MOSI, MISO or SCK, or the part's
chip select."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES, run_fsw

TANK = EXAMPLES / "tank"


@pytest.mark.parametrize("sns,dio,what", [
    ("bmp280 i2c:0x76 pressure=baro", "i A4 flag", "the I2C bus's SDA"),
    ("bmp280 i2c:0x76 pressure=baro", "i 19 flag", "the I2C bus's SCL"),
    ("adxl345 spi:7 z=baro", "i 12 flag", "the SPI bus's MISO"),
    ("adxl345 spi:7 z=baro", "i 7 flag", "the chip select"),
])
def test_the_message_names_the_pins_role(tmp_path, sns, dio, what):
    for name in ("tank.sv", "tank.sm", "tank.app", "tank.aio", "tank.dio"):
        (tmp_path / name).write_bytes((TANK / name).read_bytes())
    (tmp_path / "tank.sv").write_text((tmp_path / "tank.sv").read_text() + "[Parts]\nF32 baro\nbool flag\n")
    (tmp_path / "parts.sns").write_text(sns + "\n")
    (tmp_path / "tank.dio").write_text((tmp_path / "tank.dio").read_text() + dio + "\n")
    app = (tmp_path / "tank.app").read_text()
    app = app.replace("io           tank.aio\n", "io           parts.sns\nio           tank.aio\n")
    (tmp_path / "tank.app").write_text(app)
    r = run_fsw("check", "tank.app", cwd=tmp_path)
    assert r.code == 1, r.err
    assert "is already used (parts.sns:1)" in r.err and what in r.err, r.err
