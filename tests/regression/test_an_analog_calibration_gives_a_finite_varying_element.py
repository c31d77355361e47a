"""An analog input's calibration was checked number by number: `scale` and
`offset` each had to be finite in the board's evaluation type, and that
was all. So `fsw check` accepted calibrations the firmware cannot follow:
`scale=0` (or `scale=1e-50`, which is 0 in binary32) made the element the
offset whatever the pin read (the tank example then aborted at once in
`fsw sim --plant tank`, reading -125 psi); `scale=3.4028235e38` on an Uno
(binary32) passed though the full-scale count gives infinity
(1023 x 3.4e38 x 5 / 1023); `scale=1e39` into an `F32` element on the
native board (binary64) passed though the element stores infinity.

Now the element's value at both ends of the converter, count 0 and
2^bits - 1, computed as the firmware computes it and stored in the
element's type, must be finite, and the span per count must not be 0: else
a located error at the calibration. An inverted span (a negative scale) is
still a calibration."""

from __future__ import annotations

import pytest

from conftest import run_fsw
from support.configs import edit, tank_configs


@pytest.fixture
def tank(tmp_path):
    return tank_configs(tmp_path)


def column(tank, key):
    """The column of the number after `key=` (after its `-`) on tank.aio's line 4."""
    line = (tank / "tank.aio").read_text().splitlines()[3]
    at = line.index(key + "=") + len(key) + 1
    return at + 1 + (line[at] == "-")


def check(tank):
    return run_fsw("check", "tank.app", cwd=tank)


@pytest.mark.parametrize("cal", ["scale=0", "scale=-0.0", "scale=0e5", "scale=1e-50"])
def test_a_calibration_with_no_span_is_refused(tank, cal):
    edit(tank / "tank.aio", "scale=250", cal)
    r = check(tank)
    assert r.code == 1 and "internal error" not in r.err, r.err
    assert f"I/O config error @ tank.aio:4:{column(tank, 'scale')}:" in r.err, r.err
    assert "whatever the pin reads" in r.err, r.err


@pytest.mark.parametrize("cal", ["scale=3.4028235e38", "scale=1e38", "scale=1e33 offset=3.4028235e38", "scale=-1e38"])
def test_a_calibration_whose_full_scale_overflows_the_board_is_refused(tank, cal):
    edit(tank / "tank.aio", "scale=250 offset=-125", cal)
    r = check(tank)
    assert r.code == 1 and "internal error" not in r.err, r.err
    assert f"I/O config error @ tank.aio:4:{column(tank, 'scale')}:" in r.err, r.err
    assert "at the pin's full scale" in r.err and "binary32" in r.err, r.err


def test_an_f32_element_on_a_binary64_board_must_hold_the_value(tank):
    edit(tank / "tank.app", "board uno", "board native")
    (tank / "tank.sv").write_text((tank / "tank.sv").read_text() + "[Volts]\nF32 volts\nF64 volts64\n")
    (tank / "tank.aio").write_text((tank / "tank.aio").read_text() + "i      A1   volts          scale=1e39\n")
    r = check(tank)
    assert r.code == 1 and "I/O config error @ tank.aio:5:" in r.err, r.err
    assert "F32" in r.err and "at the pin's full scale" in r.err, r.err
    edit(tank / "tank.aio", "A1   volts ", "A1   volts64")  # binary64 holds it
    assert check(tank).code == 0, check(tank).err


def test_an_offset_beyond_an_f32_element_is_refused_at_the_offset(tank):
    edit(tank / "tank.app", "board uno", "board native")
    (tank / "tank.sv").write_text((tank / "tank.sv").read_text() + "[Volts]\nF32 volts\n")
    (tank / "tank.aio").write_text((tank / "tank.aio").read_text() + "i A1 volts offset=1e39\n")
    r = check(tank)
    assert r.code == 1 and "I/O config error @ tank.aio:5:19:" in r.err, r.err
    assert "F32 element" in r.err and "at 0 V (count 0)" in r.err, r.err


@pytest.mark.parametrize("cal", ["scale=-250 offset=1125", "scale=6e37", "scale=1e-30", "offset=3e38",
                                 "scale=-6e37 offset=0"])
def test_finite_varying_calibrations_are_accepted(tank, cal):
    edit(tank / "tank.aio", "scale=250 offset=-125", cal)
    r = check(tank)
    assert r.code == 0, r.err
