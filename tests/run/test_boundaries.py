"""Boundary pairs of the languages (spec §4.4, §4.5, §5): each limit shown
on both sides, through real machines and scripts run with `fsw test` in
binary64 and in binary32, reading the final state vector of the report."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from conftest import run_fsw

REALS = ("f64", "f32")

# Two elements of every type, `a` and `b`, for the two sides of a pair.
TYPES = ("U8", "I8", "U16", "I16", "U32", "I32", "U64", "I64", "F32", "F64", "bool")
ELEMENTS = [(t, f"{t.lower()}{side}") for t in TYPES for side in "ab"]


def write_project(folder: Path, step: list[str], script: list[str] | None = None,
                  options: str = "delta_t 1", local: list[str] = ()) -> Path:
    """A state vector with every element, a machine whose one state runs
    `step` in `.step`, and a script (`script` lines in [all_states], by
    default stopping after the first step). Returns the script's path."""
    sv = ["[Time]", "U64 time", "U32 state", "[Data]"] + [f"{t} {n}" for t, n in ELEMENTS]
    sm = (["[state_vector]", "U64 time @alias G", "U32 state @alias S"]
          + [f"{t} {n}" for t, n in ELEMENTS]
          + ["", "[local]", *local, "", "[Run]", ".step"] + [f"    {s}" for s in step])
    ss = ["[options]", *options.splitlines(), "", "[all_states]", *(script or ["G == 0: @stop"])]
    (folder / "b.sv").write_text("\n".join(sv) + "\n")
    (folder / "b.sm").write_text("\n".join(sm) + "\n")
    (folder / "b.ss").write_text("\n".join(ss) + "\n")
    return folder / "b.ss"


def final_values(out: str) -> dict[str, str]:
    tail = out.split("final state vector:\n", 1)[1]
    return dict(re.findall(r"^  (\S+) = (.*)$", tail, re.M))


def run(tmp_path: Path, real: str, step: list[str], **kw) -> dict[str, str]:
    ss = write_project(tmp_path, step, **kw)
    r = run_fsw("test", str(ss), "--real", real)
    assert r.err == "" and r.code == 0, r.err + r.out
    return final_values(r.out)


def check_errors(tmp_path: Path, name: str) -> str:
    r = run_fsw("check", name, cwd=tmp_path)
    return r.err


# ---- window sizes: 1 to 100000 ----------------------------------------------------

@pytest.mark.parametrize("real", REALS)
def test_window_100000_accepted(tmp_path, real):
    v = run(tmp_path, real, ["u64a = roll_max(G, 100000)", "u64b = roll_min(G, 100000)",
                             "u32a = roll_avg(G, n)"],
            local=["U32 n = 100000"], script=["G == 4: @stop"])
    assert (v["u64a"], v["u64b"], v["u32a"]) == ("4", "0", "2")


def test_window_100001_refused(tmp_path):
    write_project(tmp_path, ["u64a = roll_max(G, 100001)", "u64b = roll_avg(G, n)"], local=["U32 n = 100001"])
    err = check_errors(tmp_path, "b.sm")
    assert err.count("window size must be an integer from 1 to 100000, found 100001") == 2
    assert err.endswith("1 file, 2 errors, 0 warnings\n")


@pytest.mark.parametrize("real", REALS)
def test_window_1_accepted(tmp_path, real):
    v = run(tmp_path, real, ["u64a = roll_avg(G, 1)", "u64b = roll_range(G * 2, 1)"], script=["G == 7: @stop"])
    assert (v["u64a"], v["u64b"]) == ("7", "0")


def test_window_0_refused(tmp_path):
    write_project(tmp_path, ["u64a = roll_avg(G, 0)"])
    err = check_errors(tmp_path, "b.sm")
    assert "b.sm:31:24:\n  |     u64a = roll_avg(G, 0)\n" in err
    assert "^ window size must be an integer from 1 to 100000, found 0\n" in err


# ---- integer conversions: clamp, then truncate toward zero ---------------------------

@pytest.mark.parametrize("real", REALS)
def test_u8_255_kept_256_saturates(tmp_path, real):
    v = run(tmp_path, real, ["u8a = 255", "u8b = 256"])
    assert (v["u8a"], v["u8b"]) == ("255", "255")


@pytest.mark.parametrize("real", REALS)
def test_u8_0_kept_minus_1_saturates(tmp_path, real):
    v = run(tmp_path, real, ["u8a = 0", "u8b = -1"])
    assert (v["u8a"], v["u8b"]) == ("0", "0")


@pytest.mark.parametrize("real", REALS)
def test_i8_minus_128_kept_minus_129_saturates(tmp_path, real):
    v = run(tmp_path, real, ["i8a = -128", "i8b = -129", "i16a = 127 + 1", "i16b = 40000"])
    assert (v["i8a"], v["i8b"], v["i16a"], v["i16b"]) == ("-128", "-128", "128", "32767")


@pytest.mark.parametrize("real", REALS)
def test_i8_127_kept_128_saturates(tmp_path, real):
    v = run(tmp_path, real, ["i8a = 127", "i8b = 128"])
    assert (v["i8a"], v["i8b"]) == ("127", "127")


@pytest.mark.parametrize("real", REALS)
def test_u64_and_i64_extremes(tmp_path, real):
    v = run(tmp_path, real, [
        "u64a = 18446744073709551615",  # 2^64 - 1 reads as 2^64 in R: clamped to the maximum
        "u64b = 18446744073709549568",  # 2^64 - 2048: a binary64, not a binary32
        "i64a = -9223372036854775808",  # -2^63 exactly
        "i64b = 9223372036854775807",  # reads as 2^63: clamped
        "u32a = 4294967295",
        "u32b = 4294967296",
        "i32a = -2147483648",
        "i32b = -2147483649",
    ])
    assert v["u64a"] == "18446744073709551615"
    assert v["u64b"] == ("18446744073709549568" if real == "f64" else "18446744073709551615")
    assert (v["i64a"], v["i64b"]) == ("-9223372036854775808", "9223372036854775807")
    assert v["u32a"] == "4294967295"  # in binary32 it reads as 2^32, and is clamped
    assert v["u32b"] == "4294967295"
    assert (v["i32a"], v["i32b"]) == ("-2147483648", "-2147483648")


@pytest.mark.parametrize("real", REALS)
def test_truncation_toward_zero(tmp_path, real):
    v = run(tmp_path, real, ["i8a = -2.9", "i8b = 2.9", "u8a = 0.999", "u8b = -0.5",
                             "i16a = -(5 / 2)", "i16b = 7 / 2"])
    assert (v["i8a"], v["i8b"], v["u8a"], v["u8b"]) == ("-2", "2", "0", "0")
    assert (v["i16a"], v["i16b"]) == ("-2", "3")


# ---- NaN and infinities -----------------------------------------------------------------

@pytest.mark.parametrize("real", REALS)
def test_nan_becomes_0_in_ints_floats_and_bool(tmp_path, real):
    v = run(tmp_path, real, ["u8a = 0/0", "i64a = 0/0", "f32a = 0/0", "f64a = (1/0) - (1/0)",
                             "boola = 0/0", "boolb = not (0/0)"])
    assert (v["u8a"], v["i64a"]) == ("0", "0")
    assert (v["f32a"], v["f64a"]) == ("0.000000", "0.000000")
    assert (v["boola"], v["boolb"]) == ("false", "true")


@pytest.mark.parametrize("real", REALS)
def test_nan_is_false_in_conditions(tmp_path, real):
    v = run(tmp_path, real, ["0/0: u8a = 1", "if 0/0 { u8b = 1 } else { i8a = 1 }",
                             "not (0/0): i8b = 1", "(0/0) != (0/0): u16a = 1", "(0/0) == (0/0): u16b = 1"])
    assert (v["u8a"], v["u8b"], v["i8a"], v["i8b"]) == ("0", "0", "1", "1")
    # comparisons follow IEEE-754: NaN is unequal to everything
    assert (v["u16a"], v["u16b"]) == ("1", "0")


@pytest.mark.parametrize("real", REALS)
def test_division_by_zero_gives_inf_and_clamps_into_ints(tmp_path, real):
    v = run(tmp_path, real, ["f64a = 1/0", "f64b = -1/0", "f32a = 5/0", "u8a = 1/0", "i8a = -1/0",
                             "u64a = 1/0", "i64a = -1/0", "u16a = -1/0", "boola = 1/0"])
    assert (v["f64a"], v["f64b"], v["f32a"]) == ("inf", "-inf", "inf")
    assert (v["u8a"], v["i8a"], v["u64a"], v["i64a"], v["u16a"]) == (
        "255", "-128", "18446744073709551615", "-9223372036854775808", "0")
    assert v["boola"] == "true"


@pytest.mark.parametrize("real", REALS)
def test_f32_overflows_to_inf(tmp_path, real):
    v = run(tmp_path, real, ["f32a = 3.4028234e38", "f32b = 3.4028234e38 * 2", "f64a = -1e38 * 10"])
    assert v["f32a"] == "340282346638528859811704183484516925440.000000"  # the largest binary32
    assert v["f32b"] == "inf"
    assert v["f64a"] == ("%.6f" % -1e39 if real == "f64" else "-inf")  # beyond binary32 only
    # (the literal `1e39` itself is an error where R is binary32: tests/regression/
    # test_numbers_beyond_the_float_range_in_configs.py)


# ---- binary32 against binary64 -----------------------------------------------------------

@pytest.mark.parametrize("real", REALS)
def test_16777217_through_r(tmp_path, real):
    """2^24 + 1 is a binary64 but not a binary32: an F32 element rounds it in
    both modes; a U32 or F64 element keeps it only when R is binary64."""
    v = run(tmp_path, real, ["f32a = 16777217", "u32a = 16777217", "u32b = 16777216 + 1",
                             "f64a = 16777217", "u64a = u32a + 0"])
    assert v["f32a"] == "16777216.000000"
    want = "16777217" if real == "f64" else "16777216"
    assert (v["u32a"], v["u32b"], v["u64a"]) == (want, want, want)
    assert v["f64a"] == want + ".000000"


@pytest.mark.parametrize("real", REALS)
def test_point_one_plus_point_two(tmp_path, real):
    v = run(tmp_path, real, ["boola = 0.1 + 0.2 == 0.3", "f64a = 1000.0001", "f32a = 1000.0001"])
    assert v["boola"] == ("false" if real == "f64" else "true")
    assert v["f64a"] == ("1000.000100" if real == "f64" else "1000.000122")
    assert v["f32a"] == "1000.000122"


# ---- state script options: delta_t and max_steps ---------------------------------------

def test_delta_t_largest_accepted_one_more_refused(tmp_path):
    top = str((1 << 64) - 1)
    ss = write_project(tmp_path, ["u8a = 1"], options=f"delta_t {top}", script=[f"G == {top}: @stop"])
    r = run_fsw("test", str(ss))
    assert r.code == 0 and r.out.startswith("state script ran for 2 steps\n")
    assert f"  G = {top}\n" in r.out
    write_project(tmp_path, ["u8a = 1"], options=f"delta_t {1 << 64}")
    assert check_errors(tmp_path, "b.ss") == (
        "state script error @ b.ss:2:9:\n"
        "  | delta_t 18446744073709551616\n"
        "  |         ^ `delta_t` must be a positive integer, found `18446744073709551616`\n"
        "fsw check: 1 file, 1 error, 0 warnings\n")


def test_delta_t_1_accepted_0_refused(tmp_path):
    ss = write_project(tmp_path, ["u8a = 1"], options="delta_t 1", script=["G == 3: @stop"])
    assert run_fsw("test", str(ss)).out.startswith("state script ran for 4 steps\n")
    write_project(tmp_path, ["u8a = 1"], options="delta_t 0")
    assert "^ `delta_t` must be a positive integer, found `0`\n" in check_errors(tmp_path, "b.ss")


@pytest.mark.parametrize("real", REALS)
def test_max_steps_exactly_enough_passes_one_less_fails(tmp_path, real):
    ss = write_project(tmp_path, ["u8a = 1"], options="delta_t 10\nmax_steps 10", script=["G == 90: @stop"])
    r = run_fsw("test", str(ss), "--real", real)
    assert r.code == 0 and r.out.startswith("state script ran for 10 steps\n")
    ss = write_project(tmp_path, ["u8a = 1"], options="delta_t 10\nmax_steps 9", script=["G == 90: @stop"])
    r = run_fsw("test", str(ss), "--real", real)
    assert r.code == 1
    assert r.out.startswith("state script ran for 9 steps\n0 asserts passed\n"
                            "state script error @ ")
    assert "^ `@stop` not reached within 9 steps" in r.out
    assert final_values(r.out)["G"] == "80"


def test_max_steps_1_accepted_0_refused(tmp_path):
    ss = write_project(tmp_path, ["u8a = 1"], options="delta_t 1\nmax_steps 1")
    assert run_fsw("test", str(ss)).out.startswith("state script ran for 1 step\n0 asserts passed\n")
    write_project(tmp_path, ["u8a = 1"], options="delta_t 1\nmax_steps 0")
    assert "^ `max_steps` must be a positive integer, found `0`\n" in check_errors(tmp_path, "b.ss")


# ---- nesting limits: refused with a diagnostic, accepted ones run ----------------------

@pytest.mark.parametrize("real", REALS)
def test_expression_200_levels_runs_201_refused(tmp_path, real):
    ok = " + ".join(["1"] * 200)  # 199 additions: 200 levels with the leaves
    v = run(tmp_path, real, [f"u8a = {ok}", "u16a = " + " - ".join(["(1 < 2)"] * 99),
                             "boola = " + " and ".join(["(u8a > 1)"] * 100)])
    assert (v["u8a"], v["u16a"], v["boola"]) == ("200", "0", "true")  # 1 - 98 clamps to 0
    write_project(tmp_path, [f"u8a = {ok} + 1"])
    assert "^ expression is nested too deeply (more than 200 levels of operators)\n" in check_errors(tmp_path, "b.sm")


@pytest.mark.parametrize("real", REALS)
def test_64_nested_guards_run_65_refused(tmp_path, real):
    deep = [" " * i + "u8a < 100 {" for i in range(64)] + [" " * 64 + "u8a = u8a + 1"]
    deep += [" " * i + "}" for i in reversed(range(64))]
    v = run(tmp_path, real, deep, script=["G == 4: @stop"])
    assert v["u8a"] == "5"
    write_project(tmp_path, ["u8a < 100: " * 65 + "u8a = 1"])
    assert "^ nested too deeply (more than 64 levels" in check_errors(tmp_path, "b.sm")


@pytest.mark.parametrize("real", REALS)
def test_64_parentheses_run_65_refused(tmp_path, real):
    v = run(tmp_path, real, ["i8a = " + "(" * 64 + "3" + ")" * 64, "i8b = " + "- " * 63 + "3"])
    assert (v["i8a"], v["i8b"]) == ("3", "-3")
    write_project(tmp_path, ["i8a = " + "(" * 65 + "3" + ")" * 65])
    assert "^ nested too deeply (more than 64 levels" in check_errors(tmp_path, "b.sm")
