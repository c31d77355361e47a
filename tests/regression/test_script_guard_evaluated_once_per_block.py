"""A braced state-script guard was evaluated once for its whole block: in
`a { a = false ⏎ b = b + 1 }` the second input still ran. Spec §5 (and the
reference implementation) evaluate the guard just before each input, so an
input that makes the guard false stops the rest of its block. The
interpreter and the generated native script runner must agree."""

from __future__ import annotations

import shutil

import pytest

from conftest import run_fsw

from fswkit.run.native import CXX

SV = "[Vehicle]\nU64 time\nU32 state\nbool a\nU8 b\nU8 c\n"
SM = ("[state_vector]\nU64 time @alias G\nU32 state @alias S\nbool a\nU8 b\nU8 c\n\n"
      "[Only]\n.step\n    c = b\n")
SS = """[options]
delta_t 1

[all_states]
G == 0 {
    a = true
}
a {
    a = false
    b = b + 1
}
G == 0 {
    c = 7
    b = b + c
}
G == 0: @assert b == 7 and not a
G == 1: @stop
"""


@pytest.fixture(scope="module")
def script(tmp_path_factory):
    d = tmp_path_factory.mktemp("guards")
    for ext, text in (("sv", SV), ("sm", SM), ("ss", SS)):
        (d / f"g.{ext}").write_text(text)
    return d / "g.ss"


def test_an_input_that_falsifies_its_guard_stops_its_block(script):
    r = run_fsw("test", str(script))
    assert r.code == 0, r.out + r.err
    assert "  a = false\n  b = 7\n" in r.out  # `b = b + 1` did not run; a true guard still runs every input


@pytest.mark.skipif(shutil.which(CXX) is None, reason="no host C++ compiler")
def test_the_native_script_runner_agrees(script):
    interpreted = run_fsw("test", str(script))
    native = run_fsw("test", "--native", str(script))
    assert native.code == 0, native.out + native.err
    assert native.out == interpreted.out
