"""`roll_avg` was NaN for up to N - 1 steps after an infinite sample left
its window, while the window held only finite samples: the running sum
subtracted the leaving inf from a sum that held it (inf - inf), and only the
next lap boundary replaced the poisoned sum. With `x` inf for one step and 1
after, `roll_avg(x, 3)` read NaN (0 once assigned, false in every guard) on
the steps whose window was [1, 1, 1]. Spec §4.6: a window holds the last N
samples, and roll_avg is their mean.

Now a window counts the infinite samples it holds and sums only the finite
ones: the mean is +inf or -inf while one sign of infinity is in the window,
NaN while both are (inf + -inf), and the mean of the finite samples once
they have left, bit for bit the value it had before wherever no infinite
sample is involved. The interpreter, the generated C++ (`fsw test
--native`) and the bytecode VM (fsw_vm.cpp, the same runtime function)
agree, in binary64 and binary32."""

from __future__ import annotations

import os
import shutil
import sys
from concurrent.futures import ThreadPoolExecutor

import pytest

from conftest import ROOT, run_fsw

from fswkit.run.native import CXX

SV = "[Vehicle]\nU64 time\nU32 state\nF64 x\n"
SM = """[state_vector]
U64 time @alias G
U32 state @alias S
F64 x @read_only

[local]
F64 a3 = 0
F64 a2 = 0
bool high = false

[Only]
.step
    a3 = roll_avg(x, 3)
    a2 = roll_avg(x, 2)
    high = roll_avg(x, 3) > 0.5
"""
# x: inf at G == 0, -inf at G == 5, 1 on every other step.
SS = """[options]
delta_t 1

[all_states]
true: x = 1
G == 0: x = 1/0
G == 5: x = -1/0
G <= 2: @assert a3 == 1/0 and high
G == 1: @assert a2 == 1/0
G == 2: @assert a2 == 1
G >= 3 and G <= 4: @assert a3 == 1 and a2 == 1 and high
G == 5: @assert a3 == -1/0 and a2 == -1/0 and not high
G == 6: @assert a2 == -1/0 and a3 == -1/0
G == 7: @assert a2 == 1 and a3 == -1/0
G == 8: @assert a2 == 1 and a3 == 1 and high
G == 8: @stop
"""
# Both infinities in one window: the mean is NaN (0 when assigned, false).
SS_BOTH = """[options]
delta_t 1

[all_states]
true: x = 1
G == 0: x = 1/0
G == 1: x = -1/0
G == 1: @assert a3 == 0 and a2 == 0 and not high
G == 2: @assert a3 == 0 and a2 == -1/0 and not high
G == 3: @assert a3 == -1/0 and a2 == 1
G == 4: @assert a3 == 1 and a2 == 1 and high
G == 4: @stop
"""


@pytest.fixture(scope="module")
def project(tmp_path_factory):
    d = tmp_path_factory.mktemp("avg")
    for name, text in (("w.sv", SV), ("w.sm", SM), ("w.ss", SS), ("w_both.ss", SS_BOTH)):
        (d / name).write_text(text)
    return d


@pytest.mark.parametrize("real", ["f64", "f32"])
@pytest.mark.parametrize("script", ["w.ss", "w_both.ss"])
def test_the_interpreter_averages_the_samples_the_window_holds(project, script, real):
    r = run_fsw("test", str(project / script), "--real", real)
    assert r.code == 0, r.out + r.err


needs_cxx = pytest.mark.skipif(shutil.which(CXX) is None, reason="no host C++ compiler")


@needs_cxx
@pytest.mark.parametrize("script", ["w.ss", "w_both.ss"])
def test_the_generated_cpp_agrees(project, script):
    for real in ("f64", "f32"):
        interpreted = run_fsw("test", str(project / script), "--real", real)
        native = run_fsw("test", "--native", str(project / script), "--real", real)
        assert native.code == 0, native.out + native.err
        assert native.out == interpreted.out


@needs_cxx
def test_the_bytecode_vm_agrees(tmp_path):
    sys.path.insert(0, str(ROOT / "tests" / "differential"))
    try:
        import harness as H
        from gen_programs import Case
        from vm_harness import VmBatch
    finally:
        sys.path.pop(0)
    from fswkit.autocode.numeric import REALS

    cases = [Case(0, k, "w", SV, SM, ss) for k, ss in enumerate((SS, SS_BOTH))]
    loaded = [(c, *H.load(c)) for c in cases]
    work = str(tmp_path / "vm")
    os.mkdir(work)
    with ThreadPoolExecutor(2) as pool:
        for real in ("f64", "f32"):
            batch = VmBatch(work, REALS[real], pool)
            for c, s, source_line in loaded:
                batch.add(c.index, s, source_line)
            batch._flush()
            got = batch.run()
            for c, s, source_line in loaded:
                it = H.run_interpreter(s, REALS[real], source_line, os.path.join(work, "t.csv"))
                assert it.code == 0, it.report
                assert H.first_difference(it, got[c.index]) is None, H.first_difference(it, got[c.index])
