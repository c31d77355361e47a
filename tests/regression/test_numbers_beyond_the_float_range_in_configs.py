"""Numbers that do not fit the evaluation type: `scale=1e400` in a `.aio`
was a traceback (`fsw check` too); a 401-digit literal in a machine became
infinity where the reference implementation refuses it ("number is outside
the representable range"); `1e39` on a board whose `R` is binary32 became
infinity in the firmware; a board definition took `vref = inf`. Every
number of every config must be finite once converted, or be a located
error."""

from __future__ import annotations

import tomllib

import pytest

from conftest import ROOT, run_fsw
from support.configs import edit, tank_configs

from fswkit.autocode.board import board_from_dict

BIG = "1" * 401  # about 1.1e400: beyond binary64
OUT = "number is outside the representable range"


@pytest.fixture
def tank(tmp_path):
    return tank_configs(tmp_path)


@pytest.mark.parametrize("literal", ["1e400", BIG, "1.5e309", "0." + "0" * 400 + "1e800"])
@pytest.mark.parametrize("where,old,new", [
    ("a guard", "tankPressure > 775 {", "tankPressure > {} {{"),
    ("an assignment", "    counter = 0\n.step", "    counter = {}\n.step"),
    ("a local's initial value", "U64 counter             = 0", "U64 counter             = {}"),
    ("a window size", "    counter = 0\n.step", "    counter = roll_avg(counter, {})\n.step"),
])
def test_a_machine_literal_beyond_binary64_is_refused(tank, literal, where, old, new):
    edit(tank / "tank.sm", old, new.format(literal))
    r = run_fsw("check", "tank.sm", cwd=tank)
    assert r.code == 1, where
    assert "state machine config error @ tank.sm:" in r.err and f"^ {OUT}\n" in r.err, r.err


def test_a_script_literal_beyond_binary64_is_refused(tank):
    edit(tank / "tank.ss", "G == 1000:", f"G == {BIG}:")
    for argv in (("check", "tank.ss"), ("test", "tank.ss")):
        r = run_fsw(*argv, cwd=tank)
        assert r.code in (1, 2) and "state script error @ tank.ss:" in r.err and OUT in r.err, r.err


def test_the_largest_binary64_literal_is_accepted(tank):
    edit(tank / "tank.sm", "tankPressure > 775 {", "tankPressure > 1.7976931348623157e308 {")
    assert run_fsw("check", "tank.sm", cwd=tank).code == 0


@pytest.mark.parametrize("option", ["scale=1e400", "offset=-1e400", f"scale={BIG}", "scale=1e39",
                                    "scale=3.4028236e38"])
def test_an_analog_calibration_beyond_the_boards_numbers_is_refused(tank, option):
    edit(tank / "tank.aio", "scale=250", option)
    r = run_fsw("check", "tank.app", cwd=tank)
    assert r.code == 1 and "internal error" not in r.err, r.err
    assert "I/O config error @ tank.aio:4:" in r.err and "is outside the representable range" in r.err


def test_calibration_boundaries(tank):
    # binary32's largest is a number the board has, but volts x scale must be too (5 V at full scale:
    # test_an_analog_calibration_gives_a_finite_varying_element.py)
    edit(tank / "tank.aio", "scale=250", "scale=6.8e37")
    assert run_fsw("check", "tank.app", cwd=tank).code == 0
    edit(tank / "tank.aio", "scale=6.8e37", "scale=1e39")
    edit(tank / "tank.app", "board uno", "board native")  # R is binary64 there
    r = run_fsw("check", "tank.app", cwd=tank)
    assert r.code == 0, r.err


def test_a_machine_literal_beyond_binary32_is_refused_where_r_is_binary32(tank):
    edit(tank / "tank.sm", "tankPressure > 775 {", "tankPressure > 1e39 {")
    assert run_fsw("check", "tank.sm", cwd=tank).code == 0  # the machine alone: binary64 holds it
    assert run_fsw("test", "tank.ss", cwd=tank).code == 0
    r = run_fsw("check", "tank.app", cwd=tank)  # the Uno computes in binary32
    assert r.code == 1
    assert "state machine config error @ tank.sm:17:23:" in r.err
    assert f"{OUT} of binary32, the uno's evaluation type R" in r.err
    for flags in (("--real", "f32"), ("--board", "uno")):
        r = run_fsw("test", *flags, "tank.ss", cwd=tank)
        assert r.code == 2 and "tank.sm:17:23:" in r.err and f"{OUT} of binary32" in r.err, r.err


def test_an_app_number_beyond_binary64_is_a_located_error(tank):
    edit(tank / "tank.app", "rate  100", "rate  1e400")
    r = run_fsw("check", "tank.app", cwd=tank)
    assert r.code == 1 and "internal error" not in r.err
    assert "tank.app:6:7:" in r.err and "no greater than 1,000,000,000" in r.err


@pytest.mark.parametrize("rate", ["0." + "9" * 5000, "1e-5000"])
def test_an_app_number_of_too_many_digits_or_too_small_says_so(tank, rate):
    # Such a rate is positive: "must be a positive number" was not the reason.
    edit(tank / "tank.app", "sense    inputs        rate=100", f"sense    inputs        rate={rate}")
    r = run_fsw("check", "tank.app", cwd=tank)
    assert r.code == 1 and "internal error" not in r.err
    assert "tank.app:20:29:" in r.err and "`rate` is beyond the numbers the tools take (at most 4,000 " \
        "significant digits, from 1e-4000 to 1e4000)" in r.err, r.err


@pytest.mark.parametrize("old,new,field", [
    ("vref = 5.0", "vref = inf", "adc.vref"),
    ("vref = 5.0", "vref = nan", "adc.vref"),
    ("vref = 5.0", "vref = 1e400", "adc.vref"),
    ("vref = 5.0", "vref = -5.0", "adc.vref"),
    ("f_cpu = 16000000", "f_cpu = 1.6e7", "board.f_cpu"),
    ("f_cpu = 16000000", "f_cpu = 100000000000000000000", "board.f_cpu"),
    ("ram = 2048", "ram = -1", "memory.ram"),
    ("bits = 10", "bits = true", "adc.bits"),
    ("bits = 10", "bits = 64", "adc.bits"),
    ('R = "f32"', 'R = "f16"', "eval.R"),
])
def test_a_board_number_out_of_range_is_refused(old, new, field):
    text = (ROOT / "boards" / "uno.toml").read_text()
    assert old in text
    d = tomllib.loads(text.replace(old, new, 1))
    with pytest.raises(ValueError, match=f"`{field}`"):
        board_from_dict("uno", d)


def test_a_pin_number_of_5000_digits_is_a_located_error(tank):
    """int() of a pin of over 4,300 digits raised ValueError (exit 3)."""
    edit(tank / "tank.aio", "A0", "9" * 5000)
    r = run_fsw("check", "tank.app", cwd=tank)
    assert r.code == 1 and "internal error" not in r.err
    assert "I/O config error @ tank.aio:4:8:" in r.err and "has no pin" in r.err


@pytest.mark.parametrize("argv", [("check", "tank.app"), ("gen", "."), ("build", "."), ("sim", ".", "--board", "uno"),
                                  ("monitor", "--port", "/dev/null", "."), ("flash", ".")])
def test_every_command_that_reads_the_tables_refuses_the_calibration(tank, argv):
    edit(tank / "tank.aio", "scale=250", "scale=1e400")
    r = run_fsw(*argv, cwd=tank)
    assert r.code in (1, 2) and "internal error" not in r.err, r.err
    assert "tank.aio:4:34:" in r.err and "`scale` is outside the representable range" in r.err
    assert not (tank / "build").exists()


def test_a_script_literal_beyond_binary32_in_an_empty_block_is_refused(tank):
    # A guard whose block is empty is never evaluated, but it is checked like
    # every guard: a literal is an error wherever it stands.
    edit(tank / "tank.ss", "G == 1000: @stop", "G == 1000: @stop\nG > 1e39 { }")
    assert run_fsw("test", "tank.ss", cwd=tank).code == 0  # binary64 holds it
    r = run_fsw("test", "--real", "f32", "tank.ss", cwd=tank)
    assert r.code == 2 and "state script error @ tank.ss:13:5:" in r.err, r.err
    assert f"{OUT} of binary32" in r.err
