"""A parameter's `@min`/`@max` may use an earlier parameter, and the
range then takes that parameter's default, fixed when the firmware is
built: `F32 DROGUE_ALT = 200 @min 50 @max MAIN_ALT` reads as "the drogue
below the main", but after `fsw param set MAIN_ALT=500` the board still
refuses a DROGUE_ALT above 150, and after MAIN_ALT=100 it still takes
one of 140, above the main. The check said nothing (a local's initial
value that uses a parameter is an error, for the same reason). Now `fsw
check` warns at the name in the bound; a default that uses one is as
before (a default is a build-time value)."""

from __future__ import annotations

import shutil
from pathlib import Path

from conftest import run_fsw

RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"


def _rig(tmp_path, decl: str) -> Path:
    rig = tmp_path / "rig"
    shutil.copytree(RIG, rig)
    sm = rig / "tuned.sm"
    sm.write_text(sm.read_text().replace("U16  HOLD_MS  = 500   @min 10   @max 60000", decl))
    return rig


def test_a_bound_that_uses_a_parameter_is_warned_where_it_names_it(tmp_path):
    rig = _rig(tmp_path, "U16  HOLD_MS  = 500   @min 10   @max OPEN_AT + 1")
    r = run_fsw("check", str(rig / "tuned.app"))
    assert r.code == 0, r.err
    assert ("state machine config warning @ " in r.err and "tuned.sm:10:38:" in r.err
            and "`@max` value of `HOLD_MS` uses parameter `OPEN_AT`: its default, fixed when the firmware is "
                "built; the range does not follow a change of `OPEN_AT` from the ground" in r.err), r.err
    assert run_fsw("check", "--strict", str(rig / "tuned.app")).code != 0


def test_a_default_that_uses_a_parameter_is_not(tmp_path):
    rig = _rig(tmp_path, "U16  HOLD_MS  = OPEN_AT - 300   @min 10   @max 60000")
    r = run_fsw("check", str(rig / "tuned.app"))
    assert r.code == 0 and "0 warnings" in r.err, r.err
