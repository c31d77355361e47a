#!/usr/bin/env python3
"""A dispersion study of examples/rocket through its real firmware (make
bench): 1,000 closed-loop flights on simulated Unos, each with its own draw
of examples/rocket/dispersion.toml (motor impulse, mass, drag, vertical
gusts, sensor bias, noise, spikes, dropouts, brown-out resets), as many at
a time as this machine has cores (fsw sim --runs; docs/sim.md, "Dispersion
studies"). Prints the study's table — P of each check with its 95 %
interval, the apogee-detection and main-altitude errors' percentiles, the
failing runs and the command that flies each again — then the flights per
hour against shared/targets.md (>= 2,000 on 2 cores; ~455 before), and
writes study.txt and study.csv into build/bench/study-rocket.

Flights per hour is a wall-clock rate on a machine that may be shared; the
line under it gives the same rate from the CPU time the runs used (the
flights' own processes and their simulated boards), which does not depend on
what else runs: cores × 3,600 / CPU seconds per flight.

    tools/bench_study.py [--runs 1000] [--jobs CORES] [--seed 1]     (FSW_STUDY_RUNS=N make bench: N runs)
"""

from __future__ import annotations

import argparse
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

from fswkit.plant import dispersion, study
from fswkit.plant.run import SetupError, prepare
from fswkit.progress import progress

PROJECT = os.path.join(ROOT, "examples", "rocket")
DISPERSION = os.path.join(PROJECT, "dispersion.toml")
OUT = os.path.join(ROOT, "build", "bench", "study-rocket")  # a build of its own: nobody rebuilds it mid-study
TARGET_PER_HOUR = 2000
BEFORE_PER_HOUR = 455  # shared/targets.md, measured 2026-11-23 (~455 with two flights at a time)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=int(os.environ.get("FSW_STUDY_RUNS", "1000")),
                    help="flights in the study (default 1000, or FSW_STUDY_RUNS)")
    ap.add_argument("--jobs", type=int, default=study.cores(), help="flights at a time (default: the cores)")
    ap.add_argument("--seed", type=int, default=1, help="the study's seed (default 1)")
    args = ap.parse_args()
    from fswkit.sim.command import build

    try:
        app, layout, sc = prepare(PROJECT, "rocket", seed=args.seed)
    except SetupError as e:
        sys.exit(f"bench_study: {e}")
    built = build(PROJECT, out=OUT)
    if isinstance(built, int):
        sys.exit("bench_study: the rocket's firmware did not build")
    elf, board = built
    disp = dispersion.load(DISPERSION)
    rel = os.path.relpath(DISPERSION, ROOT)
    setup = study.Setup(app, layout, os.path.join(PROJECT, "plant.toml"), elf, board, disp, args.seed,
                        ["fsw", "sim", "examples/rocket", "--plant", "rocket", "--dispersion", rel],
                        study.span_of(sc))
    done = failed = 0
    t0 = time.monotonic()
    with progress("study", total=args.runs, unit="runs") as bar:
        def on_result(r):
            nonlocal done, failed
            done += 1
            failed += not r.passed
            bar.update(done, failed=failed)

        results, complete = study.run_study(setup, args.runs, args.jobs, on_result)
    wall = time.monotonic() - t0
    text = study.text(setup, results, args.runs, args.jobs, wall, complete, rel)
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "study.txt"), "w") as f:
        f.write(text)
    with open(os.path.join(OUT, "study.csv"), "w") as f:
        f.write(study.csv_text(results))
    n = len(results)
    per_hour = n / wall * 3600 if wall > 0 else 0.0
    cpu = sum(r.cpu_s for r in results) / n if n else float("nan")
    sim_s = sum(r.sim_s for r in results) / n if n else float("nan")
    cores = min(args.jobs, study.cores())
    cpu_rate = cores * 3600 / cpu if n and cpu > 0 else 0.0
    print(text, end="")
    print()
    print(f"{'measure':<58} {'target':>9} {'before (2026-11-23)':>20} {'measured':>10}")
    print(f"{f'closed-loop firmware flights per hour, {args.jobs} at a time':<58} {'>= 2,000':>9} "
          f"{f'~{BEFORE_PER_HOUR}':>20} {per_hour:>10,.0f}  {'ok' if per_hour >= TARGET_PER_HOUR else 'MISSED'}")
    print(f"{f'  the same from CPU time ({cores} cores × 3,600 / {cpu:.2f} s a flight)':<58} {'':>9} {'':>20} "
          f"{cpu_rate:>10,.0f}")
    speed = sum(r.sim_s for r in results) / sum(r.wall_s for r in results) if n else 0.0
    print(f"{'  a flight: simulated seconds, and × real time as flown':<58} {'':>9} {'':>20} "
          f"{f'{sim_s:.1f} s, {speed:.1f}×':>10}")
    print(f"wrote {os.path.relpath(OUT, ROOT)}/study.txt, study.csv")
    return 0 if complete and not any(r.error for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
