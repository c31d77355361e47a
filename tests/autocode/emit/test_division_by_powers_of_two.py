"""Division by a constant power of two is emitted as a multiplication by
its reciprocal (autocode/emit/expr.py, ExprEmitter.exact_reciprocal): the
same bits (both round the one exact quotient), with no division routine on
an 8-bit MCU. Other divisors stay divisions. The differential tests hold
the generated code to the interpreter bit for bit."""

from __future__ import annotations

import re

from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.emit.machine import emit_machine
from fswkit.autocode.numeric import F32MODE, F64MODE
from fswkit.autocode.project import load_machine

SV = "[S]\nU64 time\nU32 state\nF32 a\nF32 b\nF32 c\nF32 d\nF32 e\nF32 f\nF32 g\n"
SM = """[state_vector]
U64 time @alias G
U32 state @alias S
F32 a
F32 b
F32 c
F32 d
F32 e
F32 f
F32 g

[local]
F32 EIGHT = 8
F32 THREE = 3
F32 n = 4

[Run]
.step
    n = n + 1
    b = a / 64
    c = a / -0.25
    d = a / EIGHT
    e = a / THREE
    f = a / n
    g = a / 1e-39
"""


def step_code(tmp_path, real) -> str:
    (tmp_path / "m.sm").write_text(SM)
    (tmp_path / "m.sv").write_text(SV)
    diags = Diagnostics()
    m = load_machine(str(tmp_path / "m.sm"), diags, str(tmp_path / "m.sv"))
    assert m is not None, diags.render()
    return next(t for name, t in emit_machine(m, real).items() if name.endswith(".cpp"))


def assigned(code: str, element: str) -> str:
    return re.search(r"write_F32\(sv \+ E_" + element + r", (.*)\);  //", code).group(1)


def test_powers_of_two_multiply(tmp_path):
    code = step_code(tmp_path, F32MODE)
    assert assigned(code, "b").endswith("* 0.015625f)")
    assert assigned(code, "c").endswith("* (-4.0f))")
    assert assigned(code, "d").endswith("* 0.125f)")  # a local the machine never writes is a constant


def test_other_divisors_divide(tmp_path):
    code = step_code(tmp_path, F32MODE)
    assert " / 3.0f)" in assigned(code, "e")
    # written: not a constant (in binary32 R, the value `n = n + 1` stored, held in a local)
    held = re.search(r"const fsw::Real (f\d+) = fsw::write_F32_read\(loc \+ L_n, ", code).group(1)
    assert assigned(code, "f").endswith(f" / {held})")
    assert " / " in assigned(code, "g")  # not a power of two in binary32 (and 1/it is not normal)


def test_binary64_too(tmp_path):
    code = step_code(tmp_path, F64MODE)
    assert re.search(r"\* 0\.015625\)", assigned(code, "b"))
