#!/usr/bin/env python3
"""Closed-loop flights of examples/rocket on the simulated Uno for seeds 1
to 20 (make bench): the firmware built once, each seed flown in lock-step
with the rocket plant (fswkit.plant, docs/sim.md "Closed-loop flights"),
two flights at a time. Prints one row per seed — true and detected apogee,
the apogee error in metres and seconds, the drogue's altitude and how far
below apogee it fired, the main's altitude against MAIN_ALT, landing,
pass — and exits 1 if any flight fails a check.

    tools/bench_flights.py [--seeds 1-20] [--jobs 2] [--out DIR]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

from fswkit.plant.cosim import CosimError
from fswkit.plant.run import SetupError, execute, prepare

PROJECT = os.path.join(ROOT, "examples", "rocket")
OUT = os.path.join(ROOT, "build", "bench", "flights-rocket")  # a build of its own: nobody rebuilds it mid-run


def seeds(text: str) -> list[int]:
    out = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out += list(range(int(a), int(b or a) + 1))
    return out


def build() -> tuple[str, object]:
    from fswkit.sim.command import build as build_for_sim

    built = build_for_sim(PROJECT, out=OUT)
    if isinstance(built, int):
        sys.exit("bench_flights: the rocket's firmware did not build")
    return built


def fly(seed: int, elf: str, board, out: str | None):
    _app, layout, sc = prepare(PROJECT, "rocket", seed=seed)
    return execute(sc, elf, board, layout, os.path.join(out, f"seed{seed}") if out else None)


def fmt(x, spec: str) -> str:
    return "—" if x is None else format(x, spec)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", default="1-20", help="seeds to fly, e.g. 1-20 or 3,7,9 (default 1-20)")
    ap.add_argument("--jobs", type=int, default=2, help="flights at a time (default 2)")
    ap.add_argument("--out", help="also write each flight's files into OUT/seedN")
    args = ap.parse_args()
    try:
        prepare(PROJECT, "rocket")
    except SetupError as e:
        sys.exit(f"bench_flights: {e}")
    elf, board = build()
    todo = seeds(args.seeds)
    t0 = time.perf_counter()
    with ThreadPoolExecutor(max(1, args.jobs)) as pool:
        futures = {s: pool.submit(fly, s, elf, board, args.out) for s in todo}
        results = {}
        for s, fut in futures.items():
            try:
                results[s] = fut.result()
            except CosimError as e:
                results[s] = e
    wall = time.perf_counter() - t0
    head = (f"{'seed':>4} {'apogee m':>9} {'detected':>9} {'err m':>6} {'err s':>6} {'drogue m':>9} "
            f"{'below':>6} {'main m':>7} {'vs MAIN':>8} {'landed':>6} {'sim s':>6} {'wall s':>6}  result")
    print("closed-loop flights of examples/rocket on the simulated Uno (fsw sim --plant rocket)")
    print(head)
    print("-" * len(head))
    failed = 0
    for s in todo:
        r = results[s]
        if isinstance(r, Exception):
            failed += 1
            print(f"{s:>4} {'':>9} {'':>9} {'':>6} {'':>6} {'':>9} {'':>6} {'':>7} {'':>8} {'':>6} {'':>6} {'':>6}  "
                  f"ERROR {r}")
            continue
        f = r.report.facts
        ok = r.report.passed
        failed += not ok
        main_err = None if f.get("main_alt_m") is None else f["main_alt_m"] - f["main_config_m"]
        bad = ", ".join(c.name.split(" ")[0] + "…" for c in r.report.checks if not c.passed)
        print(f"{s:>4} {fmt(f.get('true_apogee_m'), '9.1f')} {fmt(f.get('detected_apogee_m'), '9.1f')} "
              f"{fmt(f.get('apogee_error_m'), '+6.1f')} {fmt(f.get('apogee_error_s'), '+6.2f')} "
              f"{fmt(f.get('drogue_alt_m'), '9.1f')} {fmt(f.get('drogue_drop_m'), '6.1f')} "
              f"{fmt(f.get('main_alt_m'), '7.1f')} {fmt(main_err, '+8.1f')} {'yes' if f.get('landed') else 'NO':>6} "
              f"{f['sim_s']:6.1f} {f['wall_s']:6.1f}  {'pass' if ok else 'FAIL ' + bad}")
    walls = [r.run.wall_s for r in results.values() if not isinstance(r, Exception)]
    sims = [r.run.sim_s for r in results.values() if not isinstance(r, Exception)]
    if walls:
        print(f"{len(todo) - failed} of {len(todo)} flights pass; {sum(sims):.0f} s simulated in {wall:.0f} s wall "
              f"with {args.jobs} at a time (per flight: {min(walls):.1f}–{max(walls):.1f} s wall, "
              f"{sum(sims) / sum(walls):.2f}× real time each)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
