"""Differential at scale: generated machines + state scripts (gen_programs.py)
run by the interpreter and by the generated C++ compiled for this host must
give the same exit status, the same report and the same per-step trace, in
binary64 and in binary32 (software F64, as on an AVR). A second set drives
generated machines with raw element values no script can produce (NaN
payloads, binary64 values between binary32 neighbours, arbitrary 64-bit
integers) and compares everything the machine writes after every step.

Deterministic: the seed is fixed. FSW_DIFF_CASES (default 300; `make fuzz`
runs 20,000) and FSW_DIFF_RAW_CASES (default 200; `make fuzz` 5,000) set
how many per mode, FSW_DIFF_SEED the seed (for long runs). On a mismatch
the failure message holds the configs of the case (.sv/.sm/.ss) to
reproduce it with `fsw test --native`.
docs/differential.md says what is covered and what was found."""

from __future__ import annotations

import functools
import os
import re
import shlex
import shutil
import time
from concurrent.futures import ThreadPoolExecutor

import pytest

import gen_programs as gp
import harness as H
from fswkit.autocode.numeric import REALS

CASES = int(os.environ.get("FSW_DIFF_CASES", "300"))
RAW_CASES = int(os.environ.get("FSW_DIFF_RAW_CASES", "200"))
SEED = int(os.environ.get("FSW_DIFF_SEED", "1"))
SHOW = 3  # mismatches printed in full

needs_cxx = pytest.mark.skipif(shutil.which(shlex.split(H.default_cxx())[0]) is None,
                               reason="no host C++ compiler")
CHUNK = 2000  # cases per program (bounds memory and disk on long runs)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Every case through both paths in both modes, once for the module:
    the mismatches, and how the interpreter's runs ended."""
    modes = ("f64", "f32")
    out = {"scripts": {m: [] for m in modes}, "raw": {m: [] for m in modes},
           "endings": {"passed": 0, "assertion failed": 0, "not reached": 0, "refused the step": 0}, "steps": 0}
    t0 = time.monotonic()
    for start in range(0, max(CASES, RAW_CASES), CHUNK):
        work = H.scratch_dir(str(tmp_path_factory.getbasetemp()))
        try:
            _run_chunk(out, work, _loaded(start, max(0, min(CHUNK, CASES - start))),
                       [gp.machine_case(SEED, k) for k in range(start, min(start + CHUNK, RAW_CASES))])
        finally:
            shutil.rmtree(work, ignore_errors=True)
    H.prune_cache()
    out["seconds"] = time.monotonic() - t0
    return out


@functools.lru_cache(maxsize=1)
def _loaded(start: int, n: int) -> tuple:
    """Cases start.. start + n - 1, each with its checked script and its
    `source_line`: drawn and checked once for the fixture and the fast-path
    count, whose first chunk they share (the last one drawn is kept)."""
    return tuple((c, *H.load(c)) for c in gp.cases(SEED, n, start))


def _run_chunk(out: dict, work: str, loaded: tuple, raw_cases: list) -> None:
    cases = [c for c, _, _ in loaded]
    machines = [H.load_machine(c) for c in raw_cases]
    modes = ("f64", "f32")
    with ThreadPoolExecutor(H.JOBS) as pool:
        batches, raw_batches = {}, {}
        for mode in modes:  # generated C++ first: it compiles while the interpreter runs
            if loaded:
                batches[mode] = b = H.Batch(work, REALS[mode], pool)
                for c, s, sl in loaded:
                    b.add(c.index, s, sl)
                b._flush()
            if raw_cases:
                raw_batches[mode] = rb = H.RawBatch(work, REALS[mode], pool)
                for c, m in zip(raw_cases, machines):
                    rb.add_machine(c.index, c, m)
                rb._flush()
        interp, raw_interp = {}, {}
        for mode in modes:
            for c, s, sl in loaded:
                interp[mode, c.index] = it = H.run_interpreter(s, REALS[mode], sl, os.path.join(work, "trace.csv"))
                if mode == "f64":
                    out["steps"] += it.trace.count("\n") - 1
                    out["endings"]["passed"] += it.code == 0
                    for k in ("assertion failed", "not reached", "refused the step"):
                        out["endings"][k] += k in it.report
            for c, m in zip(raw_cases, machines):
                raw_interp[mode, c.index] = H.interpret_machine(c, m, REALS[mode])
        for mode in modes:
            if loaded:
                nat = _native(batches[mode].run, {c.index: c for c in cases})
                for c, _, _ in loaded:
                    d = H.first_difference(interp[mode, c.index], nat[c.index])
                    if d:
                        out["scripts"][mode].append((c, d))
            if raw_cases:
                nat = _native(raw_batches[mode].run_raw, {c.index: c for c in raw_cases})
                for c, m in zip(raw_cases, machines):
                    d = H.raw_difference(c, m, raw_interp[mode, c.index], nat[c.index])
                    if d:
                        out["raw"][mode].append((c, d))


def _native(run, cases):
    try:
        return run()
    except H.CompileFailure as e:
        pytest.fail(f"{e}\n{cases[e.key].repro()}", pytrace=False)


def _report(kind: str, mode: str, bad: list) -> str:
    lines = [f"{len(bad)} {kind} cases differ between the interpreter and the native code ({mode}, seed {SEED})"]
    for c, d in bad[:SHOW]:
        lines += ["", f"=== case {c.index}: {d}", c.repro()]
    if len(bad) > SHOW:
        lines.append(f"... and cases {[c.index for c, _ in bad[SHOW:]]}")
    return "\n".join(lines)


@needs_cxx
@pytest.mark.parametrize("mode", ["f64", "f32"])
def test_generated_scripts_match(runs, mode):
    bad = runs["scripts"][mode]
    assert not bad, _report("script", mode, bad)


@needs_cxx
@pytest.mark.parametrize("mode", ["f64", "f32"])
def test_raw_inputs_match(runs, mode):
    bad = runs["raw"][mode]
    assert not bad, _report("raw-input", mode, bad)


@needs_cxx
def test_runs_end_every_way(runs):
    """The generated scripts pass, fail an assert, run out of steps and hit
    a step error (G wrapped): every ending of the runner is compared."""
    if CASES < 300:
        pytest.skip("too few cases to expect every ending")
    endings = runs["endings"]
    assert all(n > 0 for n in endings.values()), endings
    assert endings["passed"] > CASES // 2, endings
    assert runs["steps"] > 20 * CASES


def test_generator_reaches_the_fast_paths(monkeypatch):
    """The generated programs make the emitter take every fast path many
    times over (counted while emitting them again, in binary32, where all of
    them exist), so a regression in any of them shows up as a mismatch."""
    if CASES < 300:
        pytest.skip("too few cases to count on every path")
    from fswkit.autocode.emit import expr, script as emit_script
    from fswkit.autocode import model as M

    counts = dict.fromkeys(("int_compare", "int_compare folded", "int_add", "int_add slow path",
                            "constant_store", "constant_store NaN/inf/-0", "float_threshold F32",
                            "float_threshold F64", "chain split", "chain lambda", "folded local",
                            "window", "window sampled in some states", "lock", "negated constant",
                            "chain split, negated constant"), 0)
    E = expr.ExprEmitter

    def counting(name, key):
        orig = getattr(E, name)

        def wrapper(self, *args):
            r = orig(self, *args)
            if r is not None:
                key(self, args, r)
            return r
        monkeypatch.setattr(E, name, wrapper)

    def bump(k, n=1):
        counts[k] += n

    def negated(args) -> bool:  # `x < -5`, `-GATE < x`: a constant behind a minus sign, folded
        return any(type(o) is M.Neg for o in args)

    counting("int_compare", lambda self, a, r: (bump("int_compare folded" if r in ("true", "false") else "int_compare"),
                                                negated(a) and bump("negated constant")))
    counting("int_add", lambda self, a, r: (bump("int_add"), "round_to_f32_precision" in r and bump("int_add slow path")))
    counting("constant_store", lambda self, a, r: (bump("constant_store"),
                                                   re.search(r"// (inf|-inf|-0\.0)$", r) and bump("constant_store NaN/inf/-0")))
    counting("float_threshold", lambda self, a, r: (bump("float_threshold F32" if "f32_read_key" in r or "f32_key_g" in r else
                                                         "float_threshold F64" if "f64_read_key" in r else
                                                         "int_compare folded"),
                                                    negated(a) and bump("negated constant")))
    orig_cond = E.cond

    def cond(self, e):
        r = orig_cond(self, e)
        if type(e) is M.ChainCmp:
            bump("chain lambda" if r.startswith("([&]") else "chain split")
            if not r.startswith("([&]") and any(type(o) is M.Neg for o in e.operands):
                bump("chain split, negated constant")
        return r
    monkeypatch.setattr(E, "cond", cond)
    for c, script, source_line in _loaded(0, min(CASES, 1000)):
        files = emit_script.script_files(script, REALS["f32"], source_line)
        m = script.machine
        counts["folded local"] += sum(1 for v in m.vars if v.kind == M.LOCAL and f"L_{v.name} =" not in
                                      "".join(files.values()))
        counts["window"] += len(m.windows) + len(script.windows)
        # windows skipped in the states that can no longer read them (emit.machine.window_needs)
        counts["window sampled in some states"] += "sampled where still read" in "".join(files.values())
        counts["lock"] += m.sv.lock
    assert all(n >= 20 for n in counts.values()), counts
