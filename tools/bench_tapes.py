#!/usr/bin/env python3
"""Real-flight tape replays of examples/hpr on the simulated Uno (make
bench): every tape in ../shared/flights/ replayed WHOLE, open loop, as
`fsw sim examples/hpr --tape T --out build/bench/tapes/NAME` does
(fswkit.plant.tape_replay, docs/sim.md "Replaying real flights"), the
firmware built once, two replays at a time. Prints one row per tape — the
barometric (truth) apogee, the drogue pin's time and its error against it
beside the error measured before the apogee detector waited for the
barometer to settle (2026-11-23) and the recording altimeter's own apogee
error, the main pin's altitude error against MAIN_ALT, the landing error,
the checks passed/failed — and beside them the same tape through
examples/hpr_digital (a simulated BMP280 and ADXL345 on I2C instead of
the 10-bit ADC): its apogee error, main error and checks; then
`tape replays: N passed, M failed` and the digital variant's line.

Then the perturbed replays (`--perturb`: noise, spikes, dropouts and bias
on both sensors, docs/sim.md) of EVERY tape: FSW_TAPE_PERTURB (default
200) runs a tape through the firmware's machines in the reference
interpreter (fswkit.plant.tape_interp: the same inputs and checks, about
700× real time: 200 runs of the eight tapes are ~11 CPU-minutes), and
FSW_TAPE_PERTURB_BOARD (default 1) runs a tape on the simulated board
(about 33× real time: one run of the eight is about 80 s; the bench prints
what 200 would take at the speed it measured, about 4.5 CPU-hours). For each: the runs with a pyro pin during boost (target
0), the share of runs meeting each check, the apogee error's spread.

A failed check is a measured result, printed; the tool exits non-zero only
when something crashed (a replay that could not run, a firmware that did
not build). Without ../shared/flights/ (a user's clone) it says so and
exits 0.

    tools/bench_tapes.py [--jobs 2] [--tapes DIR] [--only NAME,...]
"""

from __future__ import annotations

import argparse
import glob
import os
import sys
import time
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FLIGHTS = os.path.join(os.path.dirname(ROOT), "shared", "flights")
PROJECT = os.path.join(ROOT, "examples", "hpr")
DIGITAL = os.path.join(ROOT, "examples", "hpr_digital")  # the same computer with a BMP280 and an ADXL345 on I2C
OUT = os.path.join(ROOT, "build", "bench", "tapes")
FIRMWARE = os.path.join(OUT, "firmware")  # a build of its own: nobody rebuilds it mid-run
# drogue pin − barometric apogee, s, before the detector waited for the barometer to settle (2026-11-23)
BEFORE = {"camoes_cats": 0.01, "genesis_cats": 0.07, "halcyon_cats": -0.87, "hedy_cats": -0.29,
          "lince_cats": -0.28, "ndrt2020_raven": 0.26, "prometheus_telemega": 0.26, "prometheus_telemetrum": 0.12}


def fmt(x, spec: str) -> str:
    """x formatted, or a dash as wide as the spec's width when absent."""
    if x is None:
        width = "".join(ch for ch in spec.split(".")[0] if ch.isdigit())
        return format("—", f">{width or 1}")
    return format(x, spec)


def setup(project: str = PROJECT, firmware: str = FIRMWARE):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.link.layout import from_app
    from fswkit.plant import tape_replay as tr
    from fswkit.sim.command import build
    from fswkit.target.build import load

    diags = Diagnostics()
    what = "examples/" + os.path.basename(project)
    app = load(project, diags)
    if app is None:
        sys.exit(f"bench_tapes: {what} does not load:\n" + diags.render())
    layout = from_app(app)
    cfg = tr.load_config(app, layout, None)
    built = build(project, out=firmware)
    if isinstance(built, int):
        sys.exit(f"bench_tapes: {what}'s firmware did not build")
    elf, board = built
    return app, layout, cfg, elf, board


def replay(path: str, app, layout, cfg, elf, board, suffix: str = ""):
    from fswkit.plant import tape_replay as tr

    tape, truth = tr.load_tape(path, cfg)
    name = os.path.splitext(os.path.basename(path))[0]
    t0 = time.perf_counter()
    o = tr.execute(tape, truth, cfg, app, elf, board, layout, os.path.join(OUT, name + suffix))
    return tape, truth, o, time.perf_counter() - t0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--jobs", type=int, default=2, help="replays at a time (default 2)")
    ap.add_argument("--tapes", default=FLIGHTS, help=f"the tapes' folder (default {FLIGHTS})")
    ap.add_argument("--only", help="replay only these tapes (names without .csv, comma-separated)")
    args = ap.parse_args()
    if not os.path.isdir(args.tapes):
        print(f"tape replays: skipped: no tapes folder at {args.tapes} (the real-flight tapes live beside the kit)")
        return 0
    paths = sorted(p for p in glob.glob(os.path.join(args.tapes, "*.csv")))
    if args.only:
        keep = set(args.only.split(","))
        paths = [p for p in paths if os.path.splitext(os.path.basename(p))[0] in keep]
    if not paths:
        print(f"tape replays: skipped: no tapes (*.csv) in {args.tapes}")
        return 0
    from fswkit.plant import tape_replay as tr

    app, layout, cfg, elf, board = setup()
    digital = setup(DIGITAL, os.path.join(OUT, "firmware-digital"))
    crashed = 0
    t0 = time.perf_counter()
    with ThreadPoolExecutor(max(1, args.jobs)) as pool:
        futures = {p: pool.submit(replay, p, app, layout, cfg, elf, board) for p in paths}
        d_futures = {p: pool.submit(replay, p, *digital, "-digital") for p in paths}
        results, d_results = {}, {}
        for into, futs in ((results, futures), (d_results, d_futures)):
            for p, fut in futs.items():
                try:
                    into[p] = fut.result()
                except Exception as e:  # a replay that could not run: a crash of the bench
                    into[p] = e
    wall = time.perf_counter() - t0
    print(f"real-flight tape replays of examples/hpr on the simulated Uno (fsw sim --tape), whole, "
          f"from {args.tapes}")
    head = (f"{'tape':<22} {'apogee m':>8} {'apogee s':>8} {'drogue s':>8} {'err s':>6} {'recorder':>8} "
            f"{'before':>6} {'main m':>7} {'landing s':>9} {'checks':>7} {'digital':>7} {'d.main':>6} {'d.checks':>8} "
            f"{'flight s':>8} {'wall s':>6}  result")
    print(head)
    print("-" * len(head))
    passed = failed = 0
    d_passed = d_failed = 0
    flown = walls = 0.0
    for p in paths:
        name = os.path.splitext(os.path.basename(p))[0]
        r = results[p]
        if isinstance(r, Exception):
            crashed += 1
            failed += 1
            print(f"{name:<22} ERROR {type(r).__name__}: {r}")
            continue
        tape, truth, o, w = r
        n = o.numbers
        checks = o.report.checks
        ok = all(c.passed for c in checks)
        passed += ok
        failed += not ok
        rec = tr.recorder_event(truth, "apogee")
        rec_err = rec[1] - truth.apogee_s if rec is not None else None
        drogue = n.get("apogee_err_s")
        drogue_t = None if drogue is None else truth.apogee_s + drogue
        good = sum(c.passed for c in checks)
        bad = "; ".join(f"{c.name.split(' (')[0]}: {c.detail}" for c in checks if not c.passed)
        flown += tape.span
        walls += w
        d = d_results[p]
        if isinstance(d, Exception):
            crashed += 1
            d_failed += 1
            d_err = d_main = None
            d_checks = "ERROR"
            bad += f"; digital: {type(d).__name__}: {d}"
        else:
            d_o = d[2]
            d_ok = all(c.passed for c in d_o.report.checks)
            d_passed += d_ok
            d_failed += not d_ok
            d_err, d_main = d_o.numbers.get("apogee_err_s"), d_o.numbers.get("main_err_m")
            d_checks = f"{sum(c.passed for c in d_o.report.checks)}/{len(d_o.report.checks)}"
            if not d_ok:
                ok = False
                bad += "; digital: " + "; ".join(f"{c.name.split(' (')[0]}: {c.detail}"
                                                 for c in d_o.report.checks if not c.passed)
        print(f"{name:<22} {fmt(truth.apogee_m_agl, '8.1f')} {fmt(truth.apogee_s, '8.3f')} {fmt(drogue_t, '8.3f')} "
              f"{fmt(drogue, '+6.2f')} {fmt(rec_err, '+8.2f')} {fmt(BEFORE.get(name), '+6.2f')} "
              f"{fmt(n.get('main_err_m'), '+7.1f')} "
              f"{fmt(n.get('landing_err_s'), '+9.2f')} {f'{good}/{len(checks)}':>7} {fmt(d_err, '+7.2f')} "
              f"{fmt(d_main, '+6.1f')} {d_checks:>8} {tape.span:8.1f} {w:6.1f}  "
              + ("pass" if ok else "FAIL " + bad.lstrip("; ")))
        for line in o.report.lines:
            if line.strip().startswith("SKIP"):
                print(f"{'':<22} {line.strip()}")
    print("columns: apogee m/s = the tape's barometric apogee (truth); drogue s = the firmware's drogue pin; "
          "err s = drogue − apogee (target: −0.5 to +1.0, and nearer 0 than the recorder's); recorder = the recording "
          "altimeter's own apogee event − apogee; before = err s before this detector (2026-11-23); "
          "main m = truth altitude at the main pin − MAIN_ALT; landing s = landing state − the tape's landing; "
          "digital, d.main, d.checks = err s, main m and the checks of examples/hpr_digital (the tape's pressure "
          "and acceleration through a simulated BMP280 and ADXL345 instead of the 10-bit ADC)")
    if walls:
        print(f"{flown:.0f} s of flight replayed in {wall:.0f} s wall with {args.jobs} at a time "
              f"({flown / walls:.2f}× real time per replay); files in {OUT}")
    print(f"tape replays: {passed} passed, {failed} failed")
    print(f"digital tape replays (examples/hpr_digital): {d_passed} passed, {d_failed} failed")
    crashed += perturbed(args.tapes, paths, layout, cfg, elf, board, args.jobs)
    return 1 if crashed else 0


def _interp_runs(args):
    """One tape's perturbed runs in the interpreter (a worker process)."""
    path, n, seed = args
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.link.layout import from_app
    from fswkit.plant import tape_interp as ti
    from fswkit.plant import tape_replay as tr
    from fswkit.target.build import load

    app = load(PROJECT, Diagnostics())
    cfg = tr.load_config(app, from_app(app), None)
    tape, truth = tr.load_tape(path, cfg)
    t0 = time.perf_counter()
    runs = ti.perturbed(app, cfg, tape, truth, n, seed)
    return runs, time.perf_counter() - t0, tape.span


def _board_runs(path, n, seed, layout, cfg, elf, board):
    from fswkit.plant import tape_replay as tr

    tape, truth = tr.load_tape(path, cfg)
    t0 = time.perf_counter()
    results = tr.robustness(tape, truth, cfg, elf, board, layout, n, seed, workers=1)
    bad = [r for r in results if r.error is not None]
    return [(r.numbers, r.checks) for r in results if r.error is None], time.perf_counter() - t0, tape.span, bad


SHORT = (("no pyro pin", "boost"), ("drogue pin", "drogue"), ("main pin", "main"), ("landing", "landing"))


def _row(name: str, runs: list, wall: float, span: float) -> str:
    n = len(runs)
    boost = sum(1 for nums, _ in runs if nums.get("boost_pyro", 0))
    share = {}
    for _nums, checks in runs:
        for c in checks:
            key = next((k for prefix, k in SHORT if c.name.startswith(prefix)), c.name)
            got = share.setdefault(key, [0, 0])
            got[0] += c.passed
            got[1] += 1
    cells = []
    for _, key in SHORT:
        got = share.get(key)
        cells.append(f"{'—':>7}" if got is None else f"{100.0 * got[0] / got[1]:6.1f}%")
    errs = sorted(nums["apogee_err_s"] for nums, _ in runs if "apogee_err_s" in nums)
    pct = (lambda q: errs[min(len(errs) - 1, int(q * len(errs)))]) if errs else None
    spread = (f"{pct(0.05):+6.2f} {pct(0.5):+6.2f} {pct(0.95):+6.2f}  [{errs[0]:+.2f}, {errs[-1]:+.2f}]"
              if errs else "—")
    speed = n * span / wall if wall else 0.0
    return f"{name:<22} {n:5d} {boost:6d} " + " ".join(cells) + f"  {spread}  {speed:7.0f}×"


def perturbed(folder: str, paths: list, layout, cfg, elf, board, jobs: int) -> int:
    """The perturbed replays of every tape, in the interpreter and on the
    board: a table each; 1 if a run crashed, else 0."""
    from concurrent.futures import ProcessPoolExecutor

    n = int(os.environ.get("FSW_TAPE_PERTURB", "200"))
    nb = int(os.environ.get("FSW_TAPE_PERTURB_BOARD", "1"))
    seed = int(os.environ.get("FSW_TAPE_PERTURB_SEED", "1"))
    crashed = 0
    head = (f"{'tape':<22} {'runs':>5} {'boost':>6} {'no pyro':>7} {'drogue':>7} {'main':>7} {'landing':>7}  "
            f"{'apogee error p5 p50 p95 [min, max] s':<36}  {'speed':>8}")
    note = ("columns: boost = runs with a pyro pin during boost (target 0); no pyro / drogue / main / landing = "
            "share of the runs meeting that check of fsw sim --tape (— where it does not apply: halcyon never "
            "comes down to the main, hedy and halcyon never land); speed = flight seconds replayed per wall "
            "second")
    names = [os.path.splitext(os.path.basename(p))[0] for p in paths]
    if n > 0:
        print(f"\nperturbed replays in the reference interpreter (fswkit.plant.tape_interp; fsw sim --tape T "
              f"--perturb {n} --seed {seed} draws the same perturbations), {n} a tape")
        print(head)
        print("-" * len(head))
        t0 = time.perf_counter()
        with ProcessPoolExecutor(max(1, jobs)) as pool:
            futs = [pool.submit(_interp_runs, (p, n, seed)) for p in paths]
            for name, fut in zip(names, futs):
                try:
                    runs, wall, span = fut.result()
                except Exception as e:  # a crash of the bench
                    crashed = 1
                    print(f"{name:<22} ERROR {type(e).__name__}: {e}")
                    continue
                print(_row(name, runs, wall, span), flush=True)
        print(note)
        print(f"{n * len(paths)} interpreted replays in {time.perf_counter() - t0:.0f} s wall with {jobs} at a time")
    if nb > 0:
        print(f"\nperturbed replays on the simulated Uno (fsw sim --tape T --perturb {nb} --seed {seed}), "
              f"{nb} a tape")
        print(head)
        print("-" * len(head))
        board_wall = 0.0
        for name, p in zip(names, paths):
            runs, wall, span, bad = _board_runs(p, nb, seed, layout, cfg, elf, board)
            board_wall += wall
            for r in bad:
                crashed = 1
                print(f"{name:<22} ERROR run {r.index}: {r.error}")
            print(_row(name, runs, wall, span), flush=True)
        print(note)
        print(f"these runs took {board_wall:.0f} s of wall time one at a time: 200 a tape would take about "
              f"{200 / nb * board_wall / 3600:.1f} CPU-hours (the bench keeps them in the interpreter)")
    return crashed

if __name__ == "__main__":
    sys.exit(main())
