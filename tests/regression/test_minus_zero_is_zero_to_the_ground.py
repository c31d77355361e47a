"""The board compares a SET's value with the live one byte for byte to
tell a change (which the declaring machine's state must allow) from a
value given again; -0.0 and 0.0 are one number but not one bit pattern,
so `fsw param set OPEN_AT=-0` on a board whose OPEN_AT is 0, in a state
that allows no change, was refused as a change (WRONG_STATE), and a
saved -0 was listed as differing from its default 0. The ground now
gives -0 as 0 (typed, or in a parameter file), as the value it is."""

from __future__ import annotations

import shutil
import struct
import time
from pathlib import Path

from conftest import run_fsw
from support.linkfw import PtyTarget, needs_cxx

RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"


def test_check_value_gives_minus_zero_as_zero():
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.params import app_parameters, check_value
    from fswkit.target.build import load

    p = app_parameters(load(str(RIG), Diagnostics()))[0]
    p = p.__class__(**{**p.__dict__, "min": -100.0})
    for given in ("-0", "-0.0", -0.0, "-0e5"):
        v, why = check_value(p, given)
        assert why is None and struct.pack("<f", v) == struct.pack("<f", 0.0), (given, v)


@needs_cxx()
def test_setting_minus_zero_over_zero_is_no_change(tmp_path):
    rig = tmp_path / "rig"
    shutil.copytree(RIG, rig)
    sm = rig / "tuned.sm"
    sm.write_text(sm.read_text().replace("F32  OPEN_AT  = 800   @min 100  @max 900   @unit psi  @when Safe Armed",
                                         "F32  OPEN_AT  = 0     @min -100 @max 900   @unit psi  @when Safe"))
    out = tmp_path / "out"
    r = run_fsw("build", str(rig), "--board", "native", "--out", str(out))
    assert r.code == 0, r.err
    with PtyTarget(out / "tuned", "--eeprom", str(tmp_path / "e.bin")) as t:
        time.sleep(0.2)
        r = run_fsw("cmd", "-p", str(rig), "--port", t.port, "set", "arm", "true")  # Safe -> Armed
        assert r.code == 0, r.err
        time.sleep(0.2)
        r = run_fsw("param", str(rig), "set", "OPEN_AT=-0", "--port", t.port)
        assert r.code == 0, r.out + r.err
        r = run_fsw("param", str(rig), "diff", "--port", t.port)
        assert r.code == 0 and "0 of 4 differ" in r.out, r.out + r.err
