"""When `G` wrapped around at 2^64 and the machine refused the step, the
script's failure pointed at line 1, column 1 of the script, whatever stood
there (a comment, a blank line, `[options]`), though the message says
"lower `delta_t`" and spec §8 has errors point at what is at fault. It now
points at the value of `delta_t`, in the interpreter's report and in the
generated script runner's (`fsw test --native`) alike."""

from __future__ import annotations

import shutil

import pytest

from conftest import run_fsw

from fswkit.run.native import CXX

SV = "[Vehicle]\nU64 time\nU32 state\n"
SM = "[state_vector]\nU64 time @alias G\nU32 state @alias S\n\n[Only]\n"
SS = """# G grows by 2^63 each step: the third step wraps it to 0
[options]
max_steps 10
delta_t   9223372036854775808

[all_states]
G == 1: @stop
"""
LOCATED = ("state script error @ w.ss:4:11:\n"
           "  | delta_t   9223372036854775808\n"
           "  |           ^ the machine refused the step: `G` did not increase "
           "(it wrapped around at 2^64: lower `delta_t`)\n")


@pytest.fixture(scope="module")
def script(tmp_path_factory):
    d = tmp_path_factory.mktemp("wrap")
    for name, text in (("w.sv", SV), ("w.sm", SM), ("w.ss", SS)):
        (d / name).write_text(text)
    return d / "w.ss"


def test_the_interpreter_points_at_delta_t(script):
    r = run_fsw("test", script.name, cwd=script.parent)
    assert r.code == 1, r.out + r.err
    assert "state script ran for 3 steps\n0 asserts passed\n" + LOCATED + "final state vector:\n" in r.out


@pytest.mark.skipif(shutil.which(CXX) is None, reason="no host C++ compiler")
def test_the_native_runner_points_at_delta_t(script):
    native = run_fsw("test", "--native", script.name, cwd=script.parent)
    assert native.code == 1, native.out + native.err
    assert native.out == run_fsw("test", script.name, cwd=script.parent).out
    assert LOCATED in native.out
