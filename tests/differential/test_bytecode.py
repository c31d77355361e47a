"""The bytecode VM against the interpreter: generated machines + state
scripts (gen_programs.py) compiled to images (autocode/emit/bytecode.py),
checked by the host verifier, and run by the state-script runner of `fsw
test --native` whose machine steps through fsw::vm_step (vm_harness.py).
The exit status, the report and the per-step trace must be those of the
interpreter, in binary64 and binary32 (software F64, as on an AVR).

A second set drives generated machines with raw element values no script
can produce (NaN payloads, binary64 values between binary32 neighbours,
arbitrary 64-bit integers) and compares everything the machine writes after
every step, as test_generated.py does for the generated C++.

Deterministic: the seed is fixed. FSW_VM_CASES (default 120; `make fuzz`
2,000) and FSW_VM_RAW_CASES (default 60; `make fuzz` 1,000) set how many
cases per mode, FSW_DIFF_SEED the seed. On a mismatch the failure message
holds the case's configs (.sv/.sm/.ss) to reproduce it."""

from __future__ import annotations

import functools
import os
import shlex
import shutil
from concurrent.futures import ThreadPoolExecutor

import pytest

import gen_programs as gp
import harness as H
from vm_harness import VmBatch, VmRawBatch
from fswkit.autocode import vmverify as V
from fswkit.autocode.emit.bytecode import compile_machine
from fswkit.autocode.numeric import REALS

CASES = int(os.environ.get("FSW_VM_CASES", "120"))
RAW_CASES = int(os.environ.get("FSW_VM_RAW_CASES", "60"))
SEED = int(os.environ.get("FSW_DIFF_SEED", "1"))
SHOW = 3

needs_cxx = pytest.mark.skipif(shutil.which(shlex.split(H.default_cxx())[0]) is None,
                               reason="no host C++ compiler")


@functools.lru_cache(maxsize=2)
def _loaded(n: int) -> tuple:
    """The first `n` cases with their checked scripts and `source_line`s,
    drawn and checked once for every test of the module that reads them."""
    return tuple((c, *H.load(c)) for c in gp.cases(SEED, n))


@functools.lru_cache(maxsize=1)
def _raw_loaded() -> tuple[list, list]:
    """The raw-input cases and their checked machines, for both modes."""
    cases = [gp.machine_case(SEED, k) for k in range(RAW_CASES)]
    return cases, [H.load_machine(c) for c in cases]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    work = H.scratch_dir(str(tmp_path_factory.getbasetemp()))
    out = {"f64": [], "f32": [], "endings": {"passed": 0, "failed": 0}, "steps": 0}
    try:
        loaded = _loaded(CASES)
        cases = [c for c, _, _ in loaded]
        with ThreadPoolExecutor(H.JOBS) as pool:
            batches = {}
            for mode in ("f64", "f32"):
                batches[mode] = b = VmBatch(work, REALS[mode], pool)
                for c, s, sl in loaded:
                    b.add(c.index, s, sl)
                b._flush()
            interp = {}
            for mode in ("f64", "f32"):
                for c, s, sl in loaded:
                    interp[mode, c.index] = it = H.run_interpreter(s, REALS[mode], sl, os.path.join(work, "trace.csv"))
                    if mode == "f64":
                        out["steps"] += it.trace.count("\n") - 1
                        out["endings"]["passed" if it.code == 0 else "failed"] += 1
            for mode in ("f64", "f32"):
                try:
                    nat = batches[mode].run()
                except H.CompileFailure as e:
                    pytest.fail(f"{e}\n{cases[e.key].repro()}", pytrace=False)
                for c, _, _ in loaded:
                    d = H.first_difference(interp[mode, c.index], nat[c.index])
                    if d:
                        out[mode].append((c, d))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return out


@needs_cxx
@pytest.mark.parametrize("mode", ["f64", "f32"])
def test_vm_matches_interpreter(runs, mode):
    bad = runs[mode]
    lines = [f"{len(bad)} cases differ between the interpreter and the VM ({mode}, seed {SEED})"]
    for c, d in bad[:SHOW]:
        lines += ["", f"=== case {c.index}: {d}", c.repro()]
    assert not bad, "\n".join(lines)


@needs_cxx
def test_cases_exercise_the_vm(runs):
    """The comparison means something: scripts both pass and fail, over
    many steps."""
    if CASES < 50:
        pytest.skip("too few cases to expect both endings")
    assert runs["endings"]["passed"] > 0 and runs["endings"]["failed"] > 0, runs["endings"]
    assert runs["steps"] > 10 * CASES



@needs_cxx
@pytest.mark.parametrize("mode", ["f64", "f32"])
def test_vm_matches_interpreter_on_raw_inputs(tmp_path, mode):
    real = REALS[mode]
    cases, machines = _raw_loaded()
    with ThreadPoolExecutor(H.JOBS) as pool:
        b = VmRawBatch(str(tmp_path), real, pool)
        for c, m in zip(cases, machines):
            b.add_machine(c.index, c, m)
        nat = b.run_raw()
    bad = []
    for c, m in zip(cases, machines):
        d = H.raw_difference(c, m, H.interpret_machine(c, m, real), nat[c.index])
        if d:
            bad.append((c, d))
    lines = [f"{len(bad)} raw-input cases differ between the interpreter and the VM ({mode}, seed {SEED})"]
    for c, d in bad[:SHOW]:
        lines += ["", f"=== case {c.index}: {d}", c.repro()]
    assert not bad, "\n".join(lines)

def test_every_generated_image_verifies():
    """The host verifier accepts every image the compiler writes, in both
    evaluation types, and refuses each one for the other type."""
    for c, s, _ in _loaded(min(CASES, 200)):
        layout = V.layout_of(s.machine.sv)
        for mode in ("f64", "f32"):
            im = compile_machine(s.machine, REALS[mode])
            assert V.verify(im, layout, REALS[mode].bits // 8) == V.OK, c.repro()
            assert V.verify(im, layout, 12 - REALS[mode].bits // 8) == V.BAD_REAL


def test_cases_exercise_the_typed_instructions():
    """The generated machines reach every typed instruction (JKEY only in
    binary32, whose threshold tests they are), so the differential runs
    above hold each of them to the interpreter."""
    from collections import Counter

    for mode, typed in (("f64", (V.JINT, V.SETK, V.IADD, V.JCMP)), ("f32", (V.JKEY, V.JINT, V.SETK, V.IADD, V.JCMP))):
        seen = Counter()
        for c, s, _ in _loaded(min(CASES, 200)):
            seen.update(V.opcodes(compile_machine(s.machine, REALS[mode]), V.layout_of(s.machine.sv)))
        assert all(seen[op] >= 20 for op in typed), (mode, {hex(op): seen[op] for op in typed})


def test_compilation_is_reproducible():
    c = gp.case(SEED, 3)
    s1, _ = H.load(c)
    s2, _ = H.load(c)
    assert compile_machine(s1.machine, REALS["f64"]) == compile_machine(s2.machine, REALS["f64"])


# ---- the examples ------------------------------------------------------------------

@needs_cxx
@pytest.mark.parametrize("mode", ["f64", "f32"])
def test_example_scripts_through_the_vm(tmp_path, monkeypatch, mode):
    """Every example's state scripts: the VM's report and trace are the
    interpreter's (as test_examples.py holds the generated C++ to them)."""
    monkeypatch.setattr(H, "MAX_ROWS", 10_000_000)  # flights run for many thousand steps
    from conftest import EXAMPLES
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.project import load_script, source_of

    real = REALS[mode]
    sources: dict = {}

    def line_of(p: str, n: int) -> str:
        if p not in sources:
            sources[p] = source_of(p)
        return sources[p].line(n)

    scripts = []
    for k, path in enumerate(sorted(EXAMPLES.rglob("*.ss"))):
        s = load_script(str(path), Diagnostics(), real=real)
        if s is not None:  # a script written to fail its checks is not run
            scripts.append((k, path, s))
    assert len(scripts) >= 10
    with ThreadPoolExecutor(H.JOBS) as pool:
        b = VmBatch(str(tmp_path), real, pool)
        for k, _, s in scripts:
            b.add(k, s, line_of)
        nat = b.run()
    for k, path, s in scripts:
        it = H.run_interpreter(s, real, line_of, str(tmp_path / "trace.csv"))
        assert it.trace.count("\n") > 1
        d = H.first_difference(it, nat[k])
        assert d is None, f"{path}: {d}"


# ---- fsw compile -------------------------------------------------------------------

def _tank():
    from conftest import EXAMPLES
    return str(EXAMPLES / "tank" / "tank.sm")


def test_fsw_compile_writes_the_verified_image(tmp_path, fsw):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.project import load_machine

    out = tmp_path / "tank.fsm"
    r = fsw("compile", _tank(), "--board", "uno", "-o", str(out))
    assert r.code == 0, r.err
    m = load_machine(_tank(), Diagnostics())
    image = out.read_bytes()
    assert image == compile_machine(m, REALS["f32"])
    assert image[:4] == b"FSMB" and image[5] == 4
    assert V.verify(image, V.layout_of(m.sv), 4) == V.OK
    assert f"{out}: {len(image)} bytes, 3 states, binary32" in r.err
    r = fsw("compile", _tank(), "-o", str(out))  # default binary64
    assert r.code == 0 and out.read_bytes()[5] == 8


def test_fsw_compile_refuses_what_the_format_cannot_carry_with_a_located_error(tmp_path, fsw):
    (tmp_path / "w.sv").write_text("[state_vector]\nU64 time\nU32 state\nF32 x\nF32 y\n")
    (tmp_path / "w.sm").write_text("[state_vector]\nU64 time @alias G\nU32 state @alias S\nF32 x @read_only\nF32 y\n\n"
                                   "[A]\n.step\n    y = roll_avg(x, 65535)\n    y = roll_max(x, 65536)\n")
    out = tmp_path / "w.fsm"
    r = fsw("compile", str(tmp_path / "w.sm"), "-o", str(out))
    assert r.code == 2
    assert "w.sm:10:9:" in r.err and "roll_max over 65536 samples" in r.err and "not supported yet" in r.err
    assert "Traceback" not in r.err and not out.exists()
    (tmp_path / "w.sm").write_text("[state_vector]\nU64 time @alias G\nU32 state @alias S\nF32 x @read_only\nF32 y\n\n"
                                   "[A]\n.step\n    y = roll_avg(x, 65535)\n")
    assert fsw("compile", str(tmp_path / "w.sm"), "-o", str(out)).code == 0  # the boundary pair
    assert out.stat().st_size > 0


def test_fsw_compile_bad_input(tmp_path, fsw):
    from conftest import EXAMPLES

    r = fsw("compile", str(EXAMPLES / "tank" / "tank_typo.sm"), "-o", str(tmp_path / "x.fsm"))
    assert r.code == 2 and "tank_typo.sm:18:9" in r.err and "Traceback" not in r.err
    r = fsw("compile", _tank(), "--board", "nosuch", "-o", str(tmp_path / "x.fsm"))
    assert r.code == 2 and "unknown board" in r.err
    r = fsw("compile", _tank(), "-o", str(tmp_path / "no" / "x.fsm"))
    assert r.code == 1 and "cannot write" in r.err
    assert not (tmp_path / "x.fsm").exists()


def test_stack_depth_bounds_what_the_verifier_finds():
    """The compiler's static depth of each expression (which it refuses past
    the VM's stack) bounds the verifier's: for every generated machine the
    image's header figure is at most the deepest expression's, and equal to
    it where that expression is evaluated on the stack (typed tests and
    stores use less, or none)."""
    from fswkit.autocode.emit.bytecode import stack_depth
    from fswkit.autocode import model as M

    def exprs(stmts):
        for st in stmts:
            if type(st) is M.Assign:
                yield st.expr
            elif type(st) is M.If:
                yield st.cond
                yield from exprs(st.then)
                yield from exprs(st.orelse)

    equal = 0
    for c, s, _ in _loaded(min(CASES, 200)):
        m = s.machine
        deepest = max([stack_depth(e) for st in m.states for b in (st.entry, st.step, st.exit) for e in exprs(b)]
                      + [stack_depth(w.arg) for w in m.windows] + [0])
        got = compile_machine(m, REALS["f64"])[7]
        assert got <= deepest, c.repro()
        equal += got == deepest
    assert equal > 100  # of 200: the bound is the figure for most machines


def test_fsw_compile_refuses_an_expression_deeper_than_the_stack(tmp_path, fsw):
    (tmp_path / "d.sv").write_text("[state_vector]\nU64 time\nU32 state\nF32 x\nF32 y\n")
    deep = "x" + " + (x" * 12 + ")" * 12  # 13 values on the stack at once
    ok = "x" + " + (x" * 11 + ")" * 11  # 12
    head = "[state_vector]\nU64 time @alias G\nU32 state @alias S\nF32 x @read_only\nF32 y\n\n[A]\n.step\n"
    (tmp_path / "d.sm").write_text(head + f"    y = {ok}\n    y = {deep}\n")
    r = fsw("compile", str(tmp_path / "d.sm"), "-o", str(tmp_path / "d.fsm"))
    assert r.code == 2 and "d.sm:10:9:" in r.err and "operand stack of 13 values" in r.err, r.err
    (tmp_path / "d.sm").write_text(head + f"    y = {ok}\n")
    assert fsw("compile", str(tmp_path / "d.sm"), "-o", str(tmp_path / "d.fsm")).code == 0
    assert (tmp_path / "d.fsm").read_bytes()[7] == 12
