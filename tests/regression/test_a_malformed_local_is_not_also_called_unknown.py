"""A local or a parameter whose line was malformed after its name (`F64 a
@read_only = 1`, `F64 a =`, `F64 a = (1`) was reported where it stands and
then again at every use, as ``unknown element `a` ``: a second, false
error (the name is declared; its line is what is wrong) that buried the
real one among repeats. Spec §8 wants the independent errors; now a name
whose declaration was reported is not reported again where it is read or
assigned, and a name nobody declared still is."""

from __future__ import annotations

import pytest

from conftest import run_fsw

SV = "[Vehicle]\nU64 time\nU32 state\nF64 x\n"
SM = """[state_vector]
U64 time @alias G
U32 state @alias S
F64 x

[local]
{decl}
F64 b = a + 1

[parameters]
F32 P = {param} @min 0 @max 10

[Only]
.step
    x = a + b + P + roll_avg(a, 2)
    a = 2
    P > 1: x = zz
"""


@pytest.mark.parametrize("decl", ["F64 a @read_only = 1", "F64 a =", "F64 a = (1", "F64 a = 1 2"])
def test_a_malformed_declaration_is_said_once(tmp_path, decl):
    (tmp_path / "m.sv").write_text(SV)
    (tmp_path / "m.sm").write_text(SM.format(decl=decl, param="1 +"))
    r = run_fsw("check", "m.sm", cwd=tmp_path)
    assert r.code == 1, r.out + r.err
    assert "m.sm:7:" in r.err and "m.sm:11:" in r.err  # the two malformed lines
    assert "unknown element `a`" not in r.err and "unknown element `P`" not in r.err, r.err
    assert "m.sm:17:16:" in r.err and "unknown element `zz`" in r.err  # a name nobody declared
    assert "3 errors" in r.out + r.err, r.err
