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
