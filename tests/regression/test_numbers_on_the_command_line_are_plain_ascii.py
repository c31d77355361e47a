"""Numbers given on the command line were read with Python's int() and
float(), which take more than a number as a user writes one: `1_000`
(an underscore between digits), digits of other scripts (`١٢`, Arabic-Indic
12; `１０`, full-width 10), and, for float(), `nan` and `infinity`. So
`fsw sim examples/tank --duration 1_0` flew 10 s, `--analog ١٤=2.5` set
A0 (pin 14 on an Uno), `--fault baro-nack@１５` failed the part at 15 s and
`--pad-alt ５０` was 50 m. Now every number an option takes is plain ASCII
(digits, one sign, a decimal point, an exponent; an integer's digits only;
a part's address also 0x with hex digits), and anything else is refused
with the option and the text it got, before any build."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES, run_fsw

TANK = EXAMPLES / "tank"
DIGITAL = EXAMPLES / "hpr_digital"
NOT_NUMBERS = ["1_0", "١٢", "１０", "1 0", "0x10", "nan", "infinity", "", "+-1", "1e", "."]


def _refused(r, *words):
    assert r.code == 2, (r.code, r.out, r.err)
    assert "Traceback" not in r.err and "built" not in r.err and "fsw build" not in r.err, r.err
    for w in words:
        assert w in r.err, r.err


@pytest.mark.parametrize("text", NOT_NUMBERS)
def test_a_duration_that_is_not_a_plain_number_is_refused(tmp_path, text):
    r = run_fsw("sim", str(TANK), "--duration", text, "--out", str(tmp_path / "out"))
    _refused(r, "--duration")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("option, text", [("--seed", "1_0"), ("--seed", "١"), ("--runs", "٢"), ("--jobs", "２"),
                                          ("--perturb", "1_000"), ("--run", "+1_0")])
def test_whole_numbers_are_ascii_digits(tmp_path, option, text):
    r = run_fsw("sim", str(TANK), option, text, "--out", str(tmp_path / "out"))
    _refused(r, option)


@pytest.mark.parametrize("argv", [
    ("tape", "import", "altos", "x.csv", "--pad-alt", "５０", "-o", "y.csv"),
    ("monitor", str(TANK), "--duration", "1_5"),
    ("monitor", str(TANK), "--baud", "9_600"),
    ("replay", "x.csv", "--speed", "٢"),
])
def test_every_numeric_option_reads_ascii_only(argv):
    r = run_fsw(*argv)
    _refused(r)
    assert "expected" in r.err, r.err


@pytest.mark.parametrize("item", ["١٤=2.5", "A0=2_5", "A0=٢", "A0=nan"])
def test_an_analog_setting_is_ascii(tmp_path, item):
    r = run_fsw("sim", str(TANK), "--analog", item, "--duration", "0.1", "--out", str(tmp_path / "out"))
    assert r.code == 2 and "--analog" in r.err and "Traceback" not in r.err, r.err


@pytest.mark.parametrize("fault", ["baro-nack@１５", "baro-nack@1_5", "baro-nack@nan"])
def test_a_fault_time_is_ascii(tmp_path, fault):
    r = run_fsw("sim", str(DIGITAL), "--plant", "rocket", "--fault", fault, "--out", str(tmp_path / "out"))
    assert r.code == 2 and "--fault" in r.err and "Traceback" not in r.err, r.err
    assert not (tmp_path / "out").exists()


def test_plain_numbers_still_work():
    from fswkit.autocode.numtext import decimal, integer

    assert [decimal(t) for t in ("10", "-1.5", "+2.", ".5", "1e3", "2.5E-2")] == [10.0, -1.5, 2.0, 0.5, 1000.0, 0.025]
    assert [integer(t) for t in ("0", "42", "-7", "+3")] == [0, 42, -7, 3]
    assert integer("0x76", hex_ok=True) == 0x76 and integer("0x76") is None
    assert all(decimal(t) is None for t in NOT_NUMBERS)
    assert all(integer(t) is None for t in NOT_NUMBERS + ["1.0", "1e3"])
    from fswkit.autocode.numtext import non_finite

    assert [str(non_finite(t)) for t in ("nan", " -Inf", "+infinity")] == ["nan", "-inf", "inf"]
    assert all(non_finite(t) is None for t in ("1", "1e999", "nanx", "١٢", ""))


@pytest.mark.parametrize("setting, words", [("HOLD_MS=1_000", "`HOLD_MS` is U16: `1_000` is not a whole number"),
                                            ("HOLD_MS=٧٠٠", "`HOLD_MS` is U16: `٧٠٠` is not a whole number"),
                                            ("OPEN_AT=６５０", "`OPEN_AT` is F32: `６５０` is not a number"),
                                            ("OPEN_AT=6_50.5", "`OPEN_AT` is F32: `6_50.5` is not a number"),
                                            ("OPEN_AT=nan", "NaN is not a value a parameter may take")])
def test_a_parameters_value_is_ascii(tmp_path, setting, words):
    """`fsw param set` (and `fsw test --param`, the page: autocode.params.check_value) read a value
    with int(text, 0) and float(): `HOLD_MS=1_000` set 1000, `٧٠٠` 700."""
    from support.param_page import RIG

    r = run_fsw("param", str(RIG), "set", setting, "--port", str(tmp_path / "none"))
    assert r.code == 2 and words in r.err and "Traceback" not in r.err, r.err


def test_a_parameters_value_in_hex_or_with_an_exponent_still_works():
    from fswkit.autocode.params import AppParam, check_value
    from fswkit.autocode.types import TYPES

    def param(type_name: str) -> AppParam:
        return AppParam(id=0, name="N", machine="m", type=TYPES[type_name], default=0, min=0, max=5000, unit="",
                        when=(), when_ids=(), off=0, state_element="S", var=0, line=1, path="m.sm")

    assert check_value(param("U16"), "0x10") == (16, None)
    assert check_value(param("U16"), " 1e3 ") == (1000, None)
    assert check_value(param("U16"), "3000.0") == (3000, None)
    assert check_value(param("F32"), "2.5") == (2.5, None)
    assert check_value(param("F32"), "-0") == (0.0, None)
    assert check_value(param("U16"), "0b101")[1] is not None
