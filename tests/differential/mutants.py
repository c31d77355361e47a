"""Checks the checker: puts one deliberate bug (a mutant) into the emitter,
the runtime or the interpreter and runs the differential cases against it;
a good test run reports mismatches. Nothing on disk changes: functions are
replaced in this process only, and a runtime mutant edits a copy of
firmware/src that native.RUNTIME then points to.

    python tests/differential/mutants.py NAME [CASES [RAW_CASES [SEED]]]
    python tests/differential/mutants.py list

docs/differential.md lists what each mutant does and how many of
test_generated.py's cases catch it."""

from __future__ import annotations

import atexit
import inspect
import os
import shutil
import sys
import tempfile
import textwrap
import time
from concurrent.futures import ThreadPoolExecutor

import gen_programs as gp
import harness as H
from fswkit.run import interp, native
from fswkit.autocode import thresholds
from fswkit.autocode.emit import expr
from fswkit.autocode.numeric import REALS


def patch_function(owner, name: str, old: str, new: str) -> None:
    """Replaces `owner.name` by a copy whose source has `old` replaced."""
    f = getattr(owner, name)
    src = textwrap.dedent(inspect.getsource(f))
    if src.count(old) != 1:
        raise SystemExit(f"mutant out of date: `{old}` not found once in {name}")
    namespace = dict(sys.modules[f.__module__].__dict__)
    exec(compile(src.replace(old, new), f"<mutant of {name}>", "exec"), namespace)
    setattr(owner, name, namespace[name])


def patch_runtime(file: str, old: str, new: str) -> None:
    """Points native.RUNTIME at a copy of the runtime with `old` replaced."""
    top = tempfile.mkdtemp(prefix="fswmutant-")
    atexit.register(shutil.rmtree, top, True)
    copy = os.path.join(top, "src")
    shutil.copytree(native.RUNTIME, copy)
    path = os.path.join(copy, file)
    with open(path) as f:
        text = f.read()
    if text.count(old) != 1:
        raise SystemExit(f"mutant out of date: `{old}` not found once in {file}")
    with open(path, "w") as f:
        f.write(text.replace(old, new))
    native.RUNTIME = copy


E = expr.ExprEmitter
MUTANTS = {
    "int_add_limit": lambda: patch_function(expr, "exact_sum_limit", "- 1 - abs(k)", "+ 1 - abs(k)"),
    "threshold_even": lambda: patch_function(thresholds, "greater", "return (key64(mf), even)",
                                             "return (key64(mf), not even)"),
    "int_compare_fold": lambda: patch_function(expr, "folded_compare",
                                               "points = (lo, hi) if not lo <= c <= hi else (lo, hi, c)",
                                               "points = (lo, hi)"),
    "const_store_negzero": lambda: patch_function(E, "constant_store", "value = to_type(t, x)",
                                                  "value = to_type(t, x)\n"
                                                  "    value = value + 0 if t.kind == 'float' else value"),
    "round24_ties_up": lambda: patch_runtime("fsw_convert.cpp",
                                             "if (low > half || (low == half && (m & unit) != 0))",
                                             "if (low >= half)"),
    "u64_no_sticky": lambda: patch_runtime("fsw_convert.cpp", "lo |= sticky;", "(void)sticky;"),
    "f64_soft_ties_away": lambda: patch_runtime("fsw_f64.cpp",
                                                "if (guard != 0 && (sticky || (sig & 1u) != 0)) ++sig;",
                                                "if (guard != 0 && (sticky || (sig & 1u) != 0 || true)) ++sig;"),
    "chain_lambda_order": lambda: patch_function(E, "cond",
                                                 'test = " && ".join(f"{names[k]} {op} {names[k + 1]}"',
                                                 'test = " && ".join(f"{names[k + 1]} {op} {names[k]}"'),
    "slowpath_sat": lambda: patch_function(E, "int_add", 'sat = "over" if tt.hi', 'sat = "false" if tt.hi'),
    "window_neg0": lambda: patch_runtime("fsw_window.h", "return (x != x || x == 0) ? Real(0) : x;",
                                         "return (x != x) ? Real(0) : x;"),
    "interp_T_nowrap": lambda: patch_function(interp.MachineRun, "pre_step_view",
                                              "(g - self.entry_time) % (1 << 64)", "(g - self.entry_time)"),
    "f32_threshold_key": lambda: patch_function(thresholds, "greater",
                                                "return (key32(0.0 if c == 0 else c), False)",
                                                "return (key32(c), False)"),
}


def main(argv: list[str]) -> int:
    if not argv or argv[0] == "list":
        print("\n".join(MUTANTS))
        return 0
    name = argv[0]
    cases = int(argv[1]) if len(argv) > 1 else 1000
    raw_cases = int(argv[2]) if len(argv) > 2 else 300
    seed = int(argv[3]) if len(argv) > 3 else 1
    MUTANTS[name]()
    # Objects of mutants must not mix with the project's cache.
    os.environ["FSW_DIFF_CACHE"] = os.path.join(tempfile.gettempdir(), "fswkit-mutant-cache")
    work = H.scratch_dir(tempfile.gettempdir())
    caught: dict[str, list[int]] = {}
    t0 = time.monotonic()
    try:
        if cases:
            for mode, c, it, nat in H.run_cases(gp.cases(seed, cases), ["f64", "f32"], work, timeout=60):
                if nat is None or H.first_difference(it, nat):
                    caught.setdefault(mode, []).append(c.index)
        if raw_cases:
            cs = [gp.machine_case(seed, k) for k in range(raw_cases)]
            ms = [H.load_machine(c) for c in cs]
            with ThreadPoolExecutor(H.JOBS) as pool:
                for mode in ("f64", "f32"):
                    b = H.RawBatch(work, REALS[mode], pool, timeout=60)
                    for c, m in zip(cs, ms):
                        b.add_machine(c.index, c, m)
                    nat = b.run_raw()
                    for c, m in zip(cs, ms):
                        if H.raw_difference(c, m, H.interpret_machine(c, m, REALS[mode]), nat[c.index]):
                            caught.setdefault("raw " + mode, []).append(c.index)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    summary = ", ".join(f"{len(v)} {k} (e.g. {v[:5]})" for k, v in caught.items()) or "NOT CAUGHT"
    print(f"{name}: {summary}; {time.monotonic() - t0:.0f} s")
    return 0 if caught else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
