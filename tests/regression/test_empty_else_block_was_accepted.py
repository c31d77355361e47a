"""`else { }` with nothing inside was accepted (and did nothing); spec §4.3
and the reference implementation refuse an `else` with no statement:
"expected logic after else", however the empty block is spelled. Empty
braces after a condition stay allowed."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES, run_fsw

TANK_SV = (EXAMPLES / "tank" / "tank.sv").read_text()
TANK_SM = (EXAMPLES / "tank" / "tank.sm").read_text()
GUARDED = "    if tankPressure > 775 {\n        valveOpen = true\n        counter = counter + 1\n    }\n    else: valveOpen = false\n"


@pytest.mark.parametrize("spelling", ["else { }", "else {}", "else {\n    }", "else\n    {\n\n    # nothing\n    }"])
def test_else_with_an_empty_block_is_refused(tmp_path, spelling):
    assert GUARDED in TANK_SM
    (tmp_path / "p.sv").write_text(TANK_SV)
    (tmp_path / "p.sm").write_text(TANK_SM.replace(GUARDED, "    tankPressure > 1: valveOpen = true\n    " + spelling + "\n"))
    r = run_fsw("check", "p.sm", cwd=tmp_path)
    assert r.code == 1
    line = TANK_SM[:TANK_SM.index(GUARDED)].count("\n") + 2
    assert f"state machine config error @ p.sm:{line}:5:\n  |     else" in r.err
    assert r.err.count("expected logic after else") == 1 and r.err.count(" error @ ") == 1


def test_empty_braces_after_a_condition_and_a_nonempty_else_are_accepted(tmp_path):
    (tmp_path / "p.sv").write_text(TANK_SV)
    (tmp_path / "p.sm").write_text(TANK_SM.replace(GUARDED, "    tankPressure > 1 { }\n    else {\n        valveOpen = true\n    }\n"))
    r = run_fsw("check", "p.sm", cwd=tmp_path)
    assert r.code == 0, r.err


def test_an_else_block_whose_statement_has_an_error_gets_that_error_only(tmp_path):
    (tmp_path / "p.sv").write_text(TANK_SV)
    (tmp_path / "p.sm").write_text(TANK_SM.replace(GUARDED, "    tankPressure > 1 { }\n    else {\n        nope = true\n    }\n"))
    r = run_fsw("check", "p.sm", cwd=tmp_path)
    assert r.code == 1 and "unknown element `nope`" in r.err and "expected logic after else" not in r.err
