#!/usr/bin/env python3
"""Front-end and interpreter benchmarks against ../shared/targets.md (`make bench`).

Measures, and prints as a table next to the targets:

- the state-script interpreter on the tank example (`examples/tank/tank.ss`
  with its `@stop` moved from `G == 1000` to `G == 20000`: 2,001 steps, all
  in `TankVentControl`), steps per second in binary64 and binary32, the best
  of several runs (each run compiles the script, then steps it);
- `fsw check` of a generated machine of 2,000 states and 20,000 lines: the
  whole command in a fresh process (start-up included), best of three, and
  the front end alone in this process (load, then the C++ emitter when it
  is there: the `fsw gen` half of the target);
- with `--callgrind`: the same two as instruction counts under valgrind
  (deterministic, independent of machine load): instructions per
  interpreter step (a 20,001-step run minus a 1-step run, over 20,000) and
  instructions of the whole `fsw check`.

Times are CPU time (user + system) of this process or of the `fsw`
child, not wall-clock time: on a shared machine the wall clock mostly
measures the neighbours. The best of several runs is reported; the
instruction counts are the figures to compare over time.
"""

from __future__ import annotations

import argparse
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TANK = ROOT / "examples" / "tank"

STEPS_TARGET = 100_000  # steps/s, state-script interpreter, tank example
CHECK_TARGET = 2.0  # s, fsw check + fsw gen of a 2,000-state, 20,000-line machine


# ---- the programs ----------------------------------------------------------------------

def tank_project(folder: Path, stop_at: int) -> Path:
    """The tank example with its `@stop` at `G == stop_at`."""
    for name in ("tank.sv", "tank.sm"):
        shutil.copy(TANK / name, folder / name)
    text = (TANK / "tank.ss").read_text()
    assert "G == 1000: @stop" in text, "the tank script changed: update tools/bench.py"
    (folder / "tank.ss").write_text(text.replace("G == 1000: @stop", f"G == {stop_at}: @stop"))
    return folder / "tank.ss"


def big_machine(folder: Path, states: int = 2000) -> Path:
    """A machine of `states` states, ten lines each (20,013 lines for 2,000),
    every state using the whole language: entry/step/exit blocks, if /
    else-if / else in both forms, chained comparisons, `roll_*` calls,
    transitions."""
    (folder / "big.sv").write_text(
        "[Sensors]\nU64 time\nU32 state\nF64 pressure\nF32 accel\nI32 count\n"
        "[Effectors]\nbool valve\nU8 mode\nU16 level\n")
    out = ["[state_vector]", "U64 time @alias G", "U32 state @alias S", "F64 pressure @read_only",
           "F32 accel @read_only", "I32 count", "bool valve", "U8 mode", "U16 level",
           "[local]", "F64 limit = 800 @read_only", "U16 window = 10 @read_only", "U64 n = 0"]
    for i in range(states):
        out += [
            f"[S{i}]",
            ".entry",
            f"    count = count + {i % 97} - mode * 2",
            ".step",
            f"    if pressure > limit - {i % 50} and roll_avg(accel, window) < 3.5 {{",
            "        valve = true",
            f"    }} else if 500 < pressure <= limit and not valve: n = n + roll_max(pressure, {1 + i % 20})",
            f"    T > {1000 + i} and (count >= 3 or level == 0): -> S{(i + 1) % states}",
            ".exit",
            "    valve = false",
        ]
    (folder / "big.sm").write_text("\n".join(out) + "\n")
    return folder / "big.sm"


# ---- measurements --------------------------------------------------------------------------

def steps_per_second(script_path: Path, real_name: str, runs: int) -> tuple[float, int]:
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.numeric import REALS
    from fswkit.autocode.project import load_script
    from fswkit.run.script import run

    d = Diagnostics()
    script = load_script(str(script_path), d)
    if script is None:
        raise SystemExit(f"bench: {script_path} does not compile:\n{d.render()}")
    best, steps = float("inf"), 0
    for _ in range(runs):
        t = time.process_time()
        res = run(script, REALS[real_name])
        best = min(best, time.process_time() - t)
        steps = res.steps
        if not res.passed:
            raise SystemExit(f"bench: {script_path} failed:\n{res.report()}")
    return steps / best, steps


def fsw_command(*args: str) -> list[str]:
    return [sys.executable, "-c", "import sys; from fswkit.cli import main; sys.exit(main(sys.argv[1:]))", *args]


def child_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def check_seconds(sm: Path, runs: int) -> float:
    """CPU seconds of the whole `fsw check` command, start-up included."""
    best = float("inf")
    for _ in range(runs):
        t = child_cpu()
        p = subprocess.run(fsw_command("check", str(sm)), capture_output=True, text=True)
        best = min(best, child_cpu() - t)
        if p.returncode != 0 or ", 0 errors," not in p.stderr:
            raise SystemExit(f"bench: fsw check {sm} failed:\n{p.stderr[-3000:]}")
    return best


def front_end_seconds(sm: Path, runs: int) -> tuple[float, float | None]:
    """(load with warnings, as `fsw check` does; C++ emission of the machine
    or None when there is no emitter)."""
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.numeric import F64MODE
    from fswkit.autocode.project import load_machine

    try:
        from fswkit.autocode.emit.machine import emit_machine
    except ImportError:
        emit_machine = None
    best_load = best_emit = float("inf")
    for _ in range(runs):
        t = time.process_time()
        m = load_machine(str(sm), Diagnostics(), warnings=True)
        best_load = min(best_load, time.process_time() - t)
        if emit_machine is not None and m is not None:
            t = time.process_time()
            emit_machine(m, F64MODE)
            best_emit = min(best_emit, time.process_time() - t)
    return best_load, (best_emit if emit_machine is not None else None)


def callgrind(cmd: list[str], workdir: Path) -> int:
    """Instructions executed by `cmd` under callgrind."""
    out = workdir / "callgrind.out"
    p = subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", *cmd],
                       capture_output=True, text=True)
    m = re.search(r"Collected\s*:\s*(\d+)", p.stderr)
    if p.returncode not in (0, 1) or not m:
        raise SystemExit(f"bench: callgrind failed:\n{p.stderr[-3000:]}")
    return int(m.group(1))


# ---- the table ---------------------------------------------------------------------------

def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=7, help="runs of each timing; the best counts")
    ap.add_argument("--callgrind", action="store_true", help="also count instructions under valgrind")
    args = ap.parse_args(argv)

    rows: list[tuple[str, str, str, str]] = []
    ok = True
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "tank").mkdir()
        (tmp / "big").mkdir()
        script = tank_project(tmp / "tank", 20000)
        for real in ("f64", "f32"):
            rate, steps = steps_per_second(script, real, args.runs)
            met = rate >= STEPS_TARGET
            ok &= met
            rows.append((f"state-script interpreter, tank ({steps:,} steps), --real {real}",
                         f"{rate:,.0f} steps/s CPU", f">= {STEPS_TARGET:,} steps/s", "ok" if met else "MISSED"))
        sm = big_machine(tmp / "big")
        lines = sum(1 for _ in sm.open())
        wall = check_seconds(sm, max(1, min(args.runs, 3)))
        load, emit = front_end_seconds(sm, max(1, min(args.runs, 3)))
        total = wall + (emit or 0.0)
        met = total <= CHECK_TARGET
        ok &= met
        rows.append((f"fsw check, 2,000 states / {lines:,} lines (whole command)",
                     f"{wall:.2f} s CPU", f"<= {CHECK_TARGET:g} s (with gen)", "ok" if met else "MISSED"))
        rows.append(("  of which the front end (load + checks + warnings)", f"{load:.2f} s CPU", "", ""))
        if emit is not None:
            rows.append(("  C++ emission of that machine (the `fsw gen` half)", f"{emit:.2f} s CPU", "", ""))
            rows.append(("  check + emission", f"{total:.2f} s CPU", f"<= {CHECK_TARGET:g} s", "ok" if met else "MISSED"))
        if args.callgrind:
            if shutil.which("valgrind") is None:
                rows.append(("callgrind", "valgrind not installed", "", ""))
            else:
                for d in ("long", "one"):
                    (tmp / d).mkdir()
                long_script = tank_project(tmp / "long", 20000)  # 2,001 steps
                one_step = tank_project(tmp / "one", 0)  # 1 step: start-up and compilation
                for real in ("f64", "f32"):
                    a = callgrind(fsw_command("test", str(long_script), "--real", real), tmp)
                    b = callgrind(fsw_command("test", str(one_step), "--real", real), tmp)
                    rows.append((f"instructions per interpreter step, tank, --real {real}",
                                 f"{(a - b) / 2000:,.0f}", "(callgrind)", ""))
                ir = callgrind(fsw_command("check", str(sm)), tmp)
                rows.append((f"instructions, fsw check of the {lines:,}-line machine", f"{ir:,}", "(callgrind)", ""))

    w = [max(len(r[i]) for r in rows + [("measure", "measured", "target", "")]) for i in range(4)]
    line = lambda r: "  ".join(c.ljust(w[i]) for i, c in enumerate(r)).rstrip()  # noqa: E731
    print(line(("measure", "measured", "target", "")))
    print(line(tuple("-" * x for x in w[:3]) + ("",)))
    for r in rows:
        print(line(r))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
