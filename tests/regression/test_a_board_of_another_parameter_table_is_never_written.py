"""`fsw param --ignore-schema` lifted the check of the target's parameter
table as well as the hello's schema: against a board reflashed with other
parameters (here tests/param/tuned with HOLD_MS renamed DELAY_MS: the same
id, type and range) `set HOLD_MS=700 --ignore-schema` reported HOLD_MS
set while it set the board's DELAY_MS, and `list` showed the board's
values under the project's names. A value means a parameter only through
its table, so the table check holds whatever --ignore-schema says (that
flag is for a schema that differs, as everywhere)."""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import pytest

from conftest import run_fsw
from support.linkfw import PtyTarget, needs_cxx

pytestmark = needs_cxx()
RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"


@pytest.mark.parametrize("action", [("set", "HOLD_MS=700"), ("list",), ("get", "HOLD_MS")])
def test_ignore_schema_does_not_lift_the_parameter_table(tmp_path, action):
    other = tmp_path / "other"
    shutil.copytree(RIG, other)
    sm = other / "tuned.sm"
    sm.write_text(sm.read_text().replace("HOLD_MS", "DELAY_MS"))
    out = tmp_path / "out"
    r = run_fsw("build", str(other), "--board", "native", "--out", str(out))
    assert r.code == 0, r.err
    with PtyTarget(out / "tuned", "--eeprom", str(tmp_path / "e.bin")) as t:
        time.sleep(0.2)
        r = run_fsw("param", str(RIG), *action, "--port", t.port, "--ignore-schema")
        assert r.code == 1, r.out + r.err
        assert "parameter table" in r.err and "build and flash it again" in r.err, r.err
        assert "HOLD_MS" not in r.out, r.out
        r = run_fsw("param", str(other), "get", "DELAY_MS", "--port", t.port)
        assert r.out.strip() == "DELAY_MS = 500", r.out + r.err
