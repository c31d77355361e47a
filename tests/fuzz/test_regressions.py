"""Inputs the fuzzer and the property tests found that once broke the front
end, each named after what broke. Every one must now give diagnostics only."""

from __future__ import annotations

import os

from conftest import EXAMPLES, run_fsw

TANK_SV = (EXAMPLES / "tank" / "tank.sv").read_text()
TANK_SM = (EXAMPLES / "tank" / "tank.sm").read_text()


def project(tmp_path, ss: str, sm: str = TANK_SM, sv: str = TANK_SV):
    for ext, text in (("sv", sv), ("sm", sm), ("ss", ss)):
        (tmp_path / f"p.{ext}").write_text(text)
    return tmp_path / "p.ss"


def test_split_options_header_without_delta_t(tmp_path):
    """`[opt ions]` (no header) and no `delta_t`: locating the missing option
    looked for "options" in the line and raised ValueError (exit 3)."""
    ss = project(tmp_path, "[opt ions]\n[all_states]\nG >= 10: @stop\n")
    for argv in (("check", str(ss)), ("test", str(ss))):
        r = run_fsw(*argv)
        assert r.code in (1, 2), r.err
        assert "internal error" not in r.err
        assert "p.ss:1:1:\n  | [opt ions]\n  | ^ missing option `delta_t`" in r.err


def test_missing_delta_t_points_at_the_options_header(tmp_path):
    ss = project(tmp_path, "# options\n  [ options ]  # here\nmax_steps 5\n[all_states]\nG >= 10: @stop\n")
    r = run_fsw("check", str(ss))
    assert r.code == 1
    assert f"{os.path.basename(ss)}:2:5:" in r.err and "missing option `delta_t`" in r.err


TANK_SS = (EXAMPLES / "tank" / "tank.ss").read_text()


def test_option_with_5000_digits(tmp_path):
    """`delta_t 1000…0` (5,001 digits): the exact value went through
    Fraction(text), and Python refuses int() of over 4,300 digits
    (ValueError, exit 3). Now: too long to be a count, a located error."""
    ss = project(tmp_path, TANK_SS.replace("delta_t 10", "delta_t 1" + "0" * 5000))
    r = run_fsw("check", str(ss))
    assert r.code == 1 and "internal error" not in r.err
    assert "`delta_t` must be a positive integer" in r.err


def test_option_with_5000_zeros_is_exact(tmp_path):
    ss = project(tmp_path, TANK_SS.replace("delta_t 10", "delta_t 10." + "0" * 5000))
    r = run_fsw("test", str(ss))
    assert r.code == 0, r.err
    assert r.out.startswith("state script ran for 101 steps\n")


def test_binary32_literal_with_5000_digits(tmp_path):
    """A 5,000-digit literal in binary32 mode: rounding it exactly went
    through Fraction(text) (ValueError, exit 3). It is 2 when rounded."""
    sm = TANK_SM.replace("F64 pi                  = 3.14159", "F64 pi = 1." + "9" * 5000 + "5")
    ss = project(tmp_path, TANK_SS, sm=sm)
    for real in ("f32", "f64"):
        r = run_fsw("test", str(ss), "--real", real)
        assert r.code == 0, r.err
        assert "  pi = 2.000000\n" in r.out


def test_binary32_literal_of_a_million_digits_is_quick(tmp_path):
    """Rounding keeps 200 significant digits and a sticky one: no quadratic
    int() of the whole literal (which took minutes)."""
    import time

    from fswkit.autocode.numeric import F32MODE

    t = time.process_time()
    assert F32MODE.literal("0." + "3" * 1_000_000) == F32MODE.literal("0.33333334")
    assert F32MODE.literal("1" + "0" * 100_000 + "e-100000") == 1.0
    assert time.process_time() - t < 1.0


def _cpu(f) -> float:
    import time

    t = time.process_time()
    f()
    return time.process_time() - t


def test_long_line_with_a_tab_lexes_in_linear_time():
    """Every token's column came from `visual_col`, which expands the line
    up to the token: quadratic, 28 s for a 160 KB line with a tab."""
    from fswkit.autocode.diagnostics import Diagnostics, Source
    from fswkit.autocode.lexer import lex

    text = "[S]\n.step\n\tx = " + " + ".join(["a"] * 40000) + "\n"
    toks: list = []
    assert _cpu(lambda: toks.extend(lex(Source.from_text("p.sm", text), Diagnostics(), "sm"))) < 3
    assert toks[2][0].col == 9 and toks[2][-1].col == 8 + len(text.split("\n")[2]) - 1


def test_many_window_sizes_with_errors_check_in_linear_time(tmp_path):
    """Each `roll_*` call counted the errors so far by building their list:
    20,000 calls with an unknown name took 26 s."""
    sm = TANK_SM.replace("    counter = 0\n", "    counter = 0\n" + "".join(
        f"    counter = roll_avg(zz{i}, 3)\n" for i in range(20000)), 1)
    (tmp_path / "p.sv").write_text(TANK_SV)
    (tmp_path / "p.sm").write_text(sm)
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.project import load_machine

    d = Diagnostics()
    assert _cpu(lambda: load_machine(str(tmp_path / "p.sm"), d)) < 8
    assert d.error_count == 20000  # 100 of them kept (diagnostics.PER_FILE)


def test_many_chained_locals_check_in_linear_time(tmp_path):
    """Each local's initial value was resolved against a copy of every name
    declared so far: 40,000 locals (1 MB) took 13 s."""
    sm = TANK_SM.replace("[local]\n", "[local]\nU8 l0 = 1\n" + "".join(
        f"U8 l{i} = l{i - 1} + 1\n" for i in range(1, 40000)), 1)  # 40,000 B of locals
    (tmp_path / "p.sv").write_text(TANK_SV)
    (tmp_path / "p.sm").write_text(sm)
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.project import load_machine

    d = Diagnostics()
    assert _cpu(lambda: load_machine(str(tmp_path / "p.sm"), d)) < 6
    assert d.error_count == 0


def test_call_inside_a_window_size(tmp_path):
    """`roll_avg(x, roll_max(1, 3))`: the size was resolved without a way to
    resolve calls (TypeError, exit 3). Now: the nested call is not a
    constant, located at the call; in a script too."""
    (tmp_path / "machine").mkdir()
    (tmp_path / "script").mkdir()
    sm = TANK_SM.replace("        counter = counter + 1",
                         "        counter = roll_avg(tankPressure, 1 + roll_max(1, 3))")
    project(tmp_path / "machine", TANK_SS, sm=sm)
    ss = TANK_SS.replace("true: @assert", "roll_min(G, roll_avg(2, 2)) >= 0: @assert")
    path = project(tmp_path / "script", ss)
    for where, at in (("machine", "p.sm:19:46:"), ("script", "p.ss:15:13:")):
        r = run_fsw("check", str(tmp_path / where))
        assert r.code == 1 and "internal error" not in r.err, r.err
        assert at in r.err and r.err.count("window size must be a constant") == 1, r.err
    assert run_fsw("test", str(path)).code == 2
