"""A parameter's bounds are checked as values of its type, but its default
was not: `U8 A = 1.5 @min 0 @max 5` passed `fsw check` and the firmware's
default was 1 (the ground then refused the 1.5 the config says, as not a
whole number). And a bound or default that F32 cannot hold apart from
zero became zero without a word: `F32 GAIN = 0.5 @min 1e-50 @max 1` let
the board take GAIN = 0, which the config excluded (a divisor, say), and
`set GAIN=1e-50` was taken as 0. Now the default is judged as the bounds
are (a whole number within an integer type, a finite number of a float
type), and a number that F32 holds as 0 is refused where it is written:
in the config, a parameter file, `fsw param set`, `fsw test --param`."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from conftest import run_fsw

RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"


def _rig(tmp_path, decl: str) -> Path:
    rig = tmp_path / "rig"
    shutil.copytree(RIG, rig)
    sm = rig / "tuned.sm"
    sm.write_text(sm.read_text().replace("[parameters]\n", "[parameters]\n" + decl + "\n"))
    return rig


@pytest.mark.parametrize("decl, col, words", [
    ("U8   GAIN = 1.5 @min 0 @max 5", 6, "the default of `GAIN` must be a whole number in 0..255 (U8), not 1.5"),
    ("I16  GAIN = 40000 @min 0 @max 5", 6, "the default of `GAIN` must be a whole number in -32768..32767 (I16), "
                                           "not 40000"),
    ("F32  GAIN = 1e39 @min 0 @max 5", 6, "the default of `GAIN` is beyond binary32 (F32): 1e+39"),
    ("F32  GAIN = 0.5 @min 1e-50 @max 1", 17, "`@min` of `GAIN` is 1e-50, which F32 holds as 0: give 0, or a "
                                              "number F32 holds apart from 0 (from 1.4e-45)"),
    ("F32  GAIN = -0.5 @min -1 @max -1e-50", 26, "`@max` of `GAIN` is -1e-50, which F32 holds as 0"),
    ("F32  GAIN = 1e-50 @min 0 @max 1", 6, "the default of `GAIN` is 1e-50, which F32 holds as 0"),
])
def test_the_config_is_refused_where_it_is_written(tmp_path, decl, col, words):
    rig = _rig(tmp_path, decl)
    r = run_fsw("check", str(rig / "tuned.app"))
    assert r.code != 0, r.err
    assert f"tuned.sm:9:{col}:" in r.err and words in r.err, r.err


def test_a_value_f32_holds_as_zero_is_refused_from_the_ground(tmp_path):
    rig = _rig(tmp_path, "F32  GAIN = 0.5 @min 0 @max 1")
    assert run_fsw("check", str(rig / "tuned.app")).code == 0
    r = run_fsw("param", str(rig), "set", "GAIN=1e-50", "--port", str(tmp_path / "no-port"))
    assert r.code == 2 and "`GAIN` is F32: 1e-50 is held as 0" in r.err, r.err
    f = tmp_path / "p.toml"
    f.write_text("GAIN = -1e-60\n")
    r = run_fsw("param", str(rig), "diff", str(f), "--port", str(tmp_path / "no-port"))
    assert r.code == 2 and f"{f}:1:8: `GAIN` is F32: -1e-60 is held as 0" in r.err, r.err
    for ok in ("GAIN=0", "GAIN=1.4e-45", "GAIN=-0"):  # zero itself, and the smallest number F32 holds
        r = run_fsw("param", str(rig), "set", ok, "--port", str(tmp_path / "no-port"))
        assert "held as 0" not in r.err, r.err
