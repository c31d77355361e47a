"""`fsw compile --board uno` (binary32) of a machine with `tankPressure >
1e39` wrote an image and exited 0: 1e39 is infinity in binary32, the
comparison was compiled against it, and the image (157 bytes instead of
187) never opened the valve. `fsw check` of the application and `fsw
test --real f32` refuse such a number where it stands; `fsw compile` now
does the same for the evaluation type it compiles for, and so does `fsw
machine upload` (the application's board)."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES

TANK = EXAMPLES / "tank"


@pytest.fixture
def machine(tmp_path):
    sm = tmp_path / "lit.sm"
    sm.write_text((EXAMPLES / "stand" / "tank_700.sm").read_text().replace("tankPressure > 700", "tankPressure > 1e39"))
    return sm


@pytest.mark.parametrize("how", [("--board", "uno"), ("--real", "f32")])
def test_a_number_past_binary32_is_refused_where_it_stands(fsw, machine, tmp_path, how):
    out = tmp_path / "lit.fsm"
    r = fsw("compile", str(machine), "--sv", str(TANK / "tank.sv"), *how, "-o", str(out))
    assert r.code == 2, r.err
    line = next(i for i, t in enumerate(machine.read_text().splitlines(), 1) if "1e39" in t)
    assert f"lit.sm:{line}:23:" in r.err and "outside the representable range of binary32" in r.err, r.err
    assert not out.exists()


def test_binary64_holds_it(fsw, machine, tmp_path):
    r = fsw("compile", str(machine), "--sv", str(TANK / "tank.sv"), "-o", str(tmp_path / "lit.fsm"))
    assert r.code == 0, r.err


def test_fsw_machine_upload_refuses_it_for_the_uno(fsw, machine):
    r = fsw("machine", str(EXAMPLES / "stand"), "upload", str(machine), "--port", "/dev/ttyNOPE")
    assert r.code == 2 and "outside the representable range of binary32, the uno's" in r.err, r.err
