"""plant.toml names a pin as the project's I/O tables may: by its name
(`"A0"`) or by the board's pin number (`14`, `"14"`: A0 on an Uno), for
analog channels and digital pins alike; a pin the board does not have is an
error that names the forms it takes, and the plant drives the same ADC
channel whichever form names it."""

from __future__ import annotations

import re

import pytest
from conftest import EXAMPLES

from fswkit.plant.run import SetupError, prepare

ROCKET, TANK = EXAMPLES / "rocket", EXAMPLES / "tank"


def _params(tmp_path, base, table_re, new):
    text = (base / "plant.toml").read_text()
    changed, n = re.subn(table_re, new, text, count=1, flags=re.S)
    assert n == 1
    p = tmp_path / "plant.toml"
    p.write_text(changed)
    return str(p)


BARO = r'(\[barometer\][^\n]*\nchannel\s*=\s*)"A0"'


@pytest.mark.parametrize("form", ['14', '"14"', '"A0"'])
def test_analog_channel_by_name_or_number(tmp_path, form):
    p = _params(tmp_path, ROCKET, BARO, rf"\g<1>{form}")
    _app, _layout, sc = prepare(str(ROCKET), "rocket", params=p)
    assert sc.channels[0] == "A0" and sc.baro_element == "pressure"


def test_tank_transducer_by_number(tmp_path):
    p = _params(tmp_path, TANK, r'(\[transducer\][^\n]*\nchannel\s*=\s*)"A0"', r"\g<1>14")
    _app, _layout, sc = prepare(str(TANK), "tank", params=p)
    assert sc.channel == "A0"


@pytest.mark.parametrize("form,says", [
    ("99", "board `uno` has no pin 99"),
    ('"A7"', "board `uno` has no pin A7"),
    ("15", "the barometer and the accelerometer"),
])
def test_pins_the_board_or_project_lacks(tmp_path, form, says):
    p = _params(tmp_path, ROCKET, BARO, rf"\g<1>{form}")
    with pytest.raises(SetupError) as e:
        prepare(str(ROCKET), "rocket", params=p)
    text = str(e.value)
    assert says in text and f"{p}:" in text, text
    if form in ("99", '"A7"'):
        assert '"A0"' in text and "14" in text  # the forms it takes
