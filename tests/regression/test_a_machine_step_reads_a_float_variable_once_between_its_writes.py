"""A machine's step read an F32 variable's bytes again at every use, even
in the statement right after the one that stored it, and tested T through
a call at each test: on AVR each is a call (read_F32, f32_read_key,
machine_T32, about 20 cycles with its arguments). The rocket's nav made
seventeen of them a step on the demo flight: the pressure read three times
for its gate, `p`, `d` and `x` read back right after their assignments, T
twice.

Now, in binary32 R, a state function reads an F32 variable once into a
C++ local where a statement reads it and later ones may again, and an
assignment keeps the value it stored (fsw::write_F32_read: a NaN stored
as +0 reads +0); the statements after it in the same block, and the
blocks inside them, read the local (its threshold tests take the key of
the value, fsw::f32_key_gt and f32_key_ge). A variable assigned in a branch reads its
bytes again after the branches. T is taken once a function where it is
tested twice or more. The values are the same bit for bit (a statement
has no side effect but its store): the interpreter and the generated C++
agree on a machine made of those cases, NaN, -0 and branches included."""

from __future__ import annotations

import re
import shutil

import pytest

from conftest import run_fsw
from support.configs import example_copy

from fswkit.run.native import CXX


def _function(cpp: str, name: str) -> str:
    start = cpp.index(f"uint8_t {name}(")
    return cpp[start:cpp.index("\n}\n", start)]


def test_the_rockets_nav_reads_each_value_once_a_step(tmp_path):
    proj = example_copy("rocket", tmp_path)
    r = run_fsw("gen", str(proj), "--out", str(tmp_path / "gen"))
    assert r.code == 0, r.out + r.err
    step = _function((tmp_path / "gen" / "nav.gen.cpp").read_text(), "s1_step")
    # the pressure: one read for its difference, its gate and `good = pressure`
    assert step.count("fsw::read_F32(sv + E_pressure)") == 1, step
    assert "fsw::f32_read_key(sv + E_pressure)" not in step, step
    # d, p and x are read from what their assignments stored
    for local in ("L_d", "L_p", "L_x"):
        assert f"fsw::read_F32(loc + {local})" not in step, step
        assert f"fsw::f32_read_key(loc + {local})" not in step, step
        assert f"fsw::write_F32_read(loc + {local}, " in step, step
    assert step.count("fsw::machine_T32(machine)") == 1, step
    # the pad pressure, assigned in a branch, is read from its bytes after it
    assert step.count("fsw::read_F32(sv + E_padPressure)") == 3, step


def test_a_binary64_build_reads_as_before(tmp_path):
    proj = example_copy("rocket", tmp_path)
    r = run_fsw("gen", str(proj), "--board", "native", "--out", str(tmp_path / "gen"))
    assert r.code == 0, r.out + r.err
    step = _function((tmp_path / "gen" / "nav.gen.cpp").read_text(), "s1_step")
    assert "write_F32_read" not in step and "f32_key_g" not in step, step


SV = "[Vehicle]\nU64 time\nU32 state\nF32 x\nF32 y\nbool b\n"
SM = """[state_vector]
U64 time @alias G
U32 state @alias S
F32 x @read_only
bool b @read_only
F32 y

[local]
F32 a = 0
F32 n = 7
F32 m = 0
F32 z = 0

[Only]
.step
    a = x / x
    y = a + 1
    m = -x
    z = 1 / m
    if a < 1 and a > -1: n = a + 2
    if b { a = 5 } else { n = n + a }
    y = y + a + n
    if T > 2 and T < 100 and y > 0: m = T
    z = z + m
"""
# x = 0: a stores NaN (read as +0), m stores -0 (1 / m is -inf); b: a
# assigned in one branch, n in the other, both read after them.
SS = """[options]
delta_t 1

[all_states]
true: x = 0
G >= 2: b = true
G >= 3: x = 2
G <= 1: @assert a == 0 and y == 3 and n == 2 and z == -1/0
G == 2: @assert a == 5 and y == 8 and z == -1/0
G == 3: @assert y == 9 and m == 3 and z == 2.5
G == 3: @stop
"""


def test_the_held_values_are_the_variables_values(tmp_path):
    for name, text in (("h.sv", SV), ("h.sm", SM), ("h.ss", SS)):
        (tmp_path / name).write_text(text)
    interpreted = run_fsw("test", str(tmp_path / "h.ss"), "--real", "f32")
    assert interpreted.code == 0, interpreted.out + interpreted.err
    if shutil.which(CXX) is None:
        pytest.skip("no host C++ compiler")
    native = run_fsw("test", "--native", str(tmp_path / "h.ss"), "--real", "f32")
    assert native.code == 0, native.out + native.err
    assert native.out == interpreted.out
