#!/usr/bin/env python3
"""CPU busy time of the rocket's firmware (make bench): examples/rocket
flown closed-loop on the simulated Uno (fsw sim examples/rocket --plant
rocket --seed 1) with the board's profiler counting, in simavr cycles, every
call of each task's step (interrupts taken meanwhile included) and each
executor cycle's busy span (the first task's start to the last task's end).
Prints, next to the figures before this work (2026-11-23) and the targets
(/work/shared/targets.md, second wave): busy time per cycle (average and
worst), each task's average and worst step, the flight's outcome.

Then the core rocket, the rocket as the issue's targets measured it
(2026-11-23: without the recorder, the parameters and the pyro channels with
their resume banks that came after; tools/bench_firmware.py core builds it
for the 8 KB target): its CPU awake per cycle against the 400 µs target.

Then the same rocket at 1 kHz: a variant built here from examples/rocket's
configs with `rate 1000` for the application and every task (and `[time]
source cycle` when `fsw check` refuses the millisecond clock at that rate),
flown whole: its overruns, faults and late cycles from the firmware's last
health frame, its busy time per cycle, and the checks of the flight.

    tools/bench_busy.py [--seed 1] [--skip-1khz]

Exits 1 when a flight fails its checks or the 1 kHz flight has an overrun
or a fault; late cycle starts are counted, not failed (a cycle after a long
step starts late by design: docs/runtime.md)."""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

from fswkit.plant import report as reports
from fswkit.plant.cosim import CosimError, fly
from fswkit.plant.run import SetupError, prepare

PROJECT = os.path.join(ROOT, "examples", "rocket")
OUT = os.path.join(ROOT, "build", "bench", "busy")
CONFIGS = (".sv", ".sm", ".ss", ".aio", ".dio", ".app", ".toml")

# second-wave table, "today" column (measured 2026-11-23)
BEFORE = {"busy_avg": 957.0, "busy_worst": 1932.0, "step_worst": 1140.0, "sense": 395.0,
          "flash": 10658, "ram": 730}
TARGET = {"busy_avg": 400.0, "step_worst": 300.0, "flash": 8192}
# the link's steps and the rocket's size before the in-place framer
# (2026-11-28, at commit 1001b63), and what that change alone costs (the
# rocket built from 1001b63 with only the link's files changed; the rest of
# `now` may hold other work)
LINK_BEFORE = {"downlink": (183.9, 728.6), "uplink": (39.6, 375.2), "flash": 23040, "ram": 1364}
LINK_DELTA = {"flash": 484, "ram": -1}
# busy per cycle, average (µs), task steps and the executor between them,
# before the executor read the clock once per task run and its task rows
# one field at a time (2026-12-06)
EXEC_BEFORE = {"busy_avg": 745.9, "sum_avg": 531.0, "awake": 1182.2}


def variant_1khz(folder: str = os.path.join(OUT, "rocket-1khz")) -> tuple[str, str]:
    """examples/rocket at 1 kHz, written into `folder` from the example's own
    configs (nothing copied by hand): (folder, time source). The millisecond
    clock when `fsw check` accepts it at 1 kHz, else `source cycle`.
    (tests/examples/test_rocket_1khz.py checks and builds it.)"""
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import BuildError, load

    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    for name in sorted(os.listdir(PROJECT)):
        src = os.path.join(PROJECT, name)
        if os.path.isfile(src) and name.endswith(CONFIGS):
            shutil.copy(src, folder)
        elif os.path.isdir(src) and name != "build":  # data the plant reads (motor files)
            shutil.copytree(src, os.path.join(folder, name))
    app_path = os.path.join(folder, "rocket.app")
    with open(app_path) as f:
        text = f.read()
    text = re.sub(r"(?m)^rate(\s+)\d+", r"rate\g<1>1000", text, count=1)  # [application]'s, not [log]'s
    text = re.sub(r"(?m)^(\w+\s+(?:uplink|inputs|machine \w+|outputs|telemetry|recorder)\s+)rate=\d+", r"\1rate=1000", text)
    for source in ("clock", "cycle"):
        with open(app_path, "w") as f:
            f.write(re.sub(r"(?m)^source\s+\w+", f"source {source}", text))
        diags = Diagnostics()
        try:
            app = load(folder, diags)
        except BuildError:
            app = None
        if app is not None and not diags.errors:
            return folder, source
    sys.exit(f"bench_busy: the 1 kHz variant of the rocket does not check:\n{diags.render()}")


def variant_core(folder: str = os.path.join(OUT, "rocket-core")) -> str:
    """examples/rocket as the issue's targets measured it, written into
    `folder`: tools/bench_firmware.py's `without_later_features`."""
    from bench_firmware import without_later_features

    shutil.rmtree(folder, ignore_errors=True)
    shutil.copytree(PROJECT, folder, ignore=shutil.ignore_patterns("build"))
    without_later_features(folder)
    return folder


def build(project: str, out: str):
    from fswkit.sim.command import build as build_for_sim

    built = build_for_sim(project, out=out)
    if isinstance(built, int):
        sys.exit(f"bench_busy: {project} did not build")
    return built


def task_steps(elf: str, n_tasks: int) -> list[int]:
    """Each task's step function (flash byte address), from the firmware's
    task table (kTasks: rows whose first member is the step's word address)."""
    from fswkit.target.build import elf_symbols  # demangles the names LTO gave a suffix too

    rows = [(a, n) for a, n, kind, name in elf_symbols(elf)
            if kind in "tTrRdD" and name == "fsw_gen::(anonymous namespace)::kTasks"]
    if not rows:
        sys.exit(f"bench_busy: {elf} has no task table kTasks")
    start, size = rows[0]
    with tempfile.TemporaryDirectory() as tmp:
        image = os.path.join(tmp, "text.bin")  # .text from address 0 (the vectors)
        subprocess.run(["avr-objcopy", "-O", "binary", "-j", ".text", elf, image], check=True)
        with open(image, "rb") as f:
            data = f.read()[start:start + size]
    row = size // n_tasks
    return [2 * int.from_bytes(data[i * row:i * row + 2], "little") for i in range(n_tasks)]


def flash_ram(elf: str) -> tuple[int, int]:
    from fswkit.target.build import elf_size

    return elf_size(elf)


def flown(project: str, out: str, seed: int):
    """Builds and flies `project` with its task steps profiled: (app, board,
    flight run, report, ELF)."""
    try:
        app, layout, sc = prepare(project, "rocket", seed=seed)
    except SetupError as e:
        sys.exit(f"bench_busy: {e}")
    elf, board = build(project, out)
    steps = task_steps(elf, len(app.tasks))
    try:
        run = fly(sc, elf, board, layout, profile=steps)
    except CosimError as e:
        sys.exit(f"bench_busy: the flight of {project} did not finish: {e}")
    return app, board, run, reports.rocket(run, sc), elf


def us(cycles: float, f_cpu: int) -> float:
    return cycles * 1e6 / f_cpu


def table(app, board, run, rep) -> dict:
    """Prints the busy time and each task's steps; returns the figures."""
    p, f = run.profile, int(board.f_cpu)
    period = 1e6 / app.rate
    avg, worst = us(p.frame_total / max(1, p.frames), f), us(p.frame_worst, f)
    steps = [(t.name, us(fp.total / max(1, fp.calls), f), us(fp.worst, f), fp.calls)
             for t, fp in zip(app.tasks, p.functions)]
    sum_avg = sum(a for _, a, _, _ in steps)
    # awake: every cycle the CPU did not sleep, from reset to the flight's end, per executor cycle -- the
    # tasks, the executor, the flight's save after the tasks (a [pyro] application's resume banks),
    # interrupts, and the main loop's passes between cycles
    awake = us((run.sim_s * f - p.sleep) / max(1, p.frames), f)
    print(f"  {run.sim_s:.1f} s simulated, {p.frames:,} executor cycles profiled; the flight's checks: "
          f"{sum(c.passed for c in rep.checks)} of {len(rep.checks)} pass")
    print(f"  {'':<34} {'avg µs':>8} {'worst µs':>9}")
    print(f"  {'busy per cycle (first task start to last task end)':<52}{avg:>8.1f} {worst:>9.1f}   "
          f"{100 * avg / period:.1f} % of the {period:g} µs period on average")
    print(f"  {'CPU awake per cycle (all but sleep)':<52}{awake:>8.1f} {'':>9}   "
          f"{100 * awake / period:.1f} %: the span above, the flight's save, interrupts, the loop between cycles")
    print(f"  {'sum of the task steps per cycle':<52}{sum_avg:>8.1f}")
    for name, a, w, calls in steps:
        print(f"    task {name:<46}{a:>8.1f} {w:>9.1f}   ({calls:,} steps)")
    return {"busy_avg": avg, "busy_worst": worst, "sum_avg": sum_avg, "steps": steps, "awake": awake}


def health(run) -> dict:
    h = run.session.health if run.session is not None else None
    if not h:
        return {}
    return {"late": h["late"], "cycles": h["cycles"],
            "overruns": sum(t["overruns"] for t in h["tasks"]), "faults": sum(t["faults"] for t in h["tasks"]),
            "safed": [t["name"] for t in h["tasks"] if t["mode_name"] != "enabled"],
            "by_task": {t["name"]: (t["overruns"], t["faults"], t["worst_us"]) for t in h["tasks"]}}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, default=1, help="the flight's seed (default 1, the demo flight)")
    ap.add_argument("--skip-1khz", action="store_true", help="only the 100 Hz rocket")
    args = ap.parse_args()
    status = 0

    app, board, run, rep, elf = flown(PROJECT, os.path.join(OUT, "rocket"), args.seed)
    flash, ram = flash_ram(elf)
    print(f"examples/rocket at {app.rate} Hz on the simulated Uno, seed {args.seed} "
          f"(fsw sim examples/rocket --plant rocket), cycles counted by the board's profiler")
    got = table(app, board, run, rep)
    own = {n: (a, w) for n, a, w, _ in got["steps"]}
    worst_name, _, worst_step, _ = max(got["steps"], key=lambda s: s[2])
    print()
    head = f"  {'measure':<44} {'before (2026-11-23)':>20} {'now':>10} {'target':>10}"
    print(head)
    print("  " + "-" * (len(head) - 2))
    print(f"  {'busy span per cycle, average (µs)':<44} {'':>20} {got['busy_avg']:>10,.0f} "
          f"{'':>10}   (first task start to last task end: the task steps {got['sum_avg']:,.0f}, the executor "
          f"and interrupts between them {got['busy_avg'] - got['sum_avg']:,.0f}; before one clock read a task run, "
          f"2026-12-06: {EXEC_BEFORE['busy_avg']:,.0f}, of it {EXEC_BEFORE['busy_avg'] - EXEC_BEFORE['sum_avg']:,.0f} "
          f"between the steps)")
    print(f"  {'CPU awake per cycle, average (µs)':<44} {BEFORE['busy_avg']:>20,.0f} {got['awake']:>10,.0f} "
          f"{'≤ 400':>10}   (all the CPU did not sleep: the busy span, the flight's save after the tasks, the "
          f"interrupts and the main loop between cycles; before the loop slept through interrupts it had no work "
          f"for and the save read its tables a field at a time, 2026-12-06: {EXEC_BEFORE['awake']:,.0f})")
    print(f"  {'busy per cycle, worst (µs)':<44} {BEFORE['busy_worst']:>20,.0f} {got['busy_worst']:>10,.0f} {'':>10}")
    print(f"  {'worst task step (µs)':<44} {BEFORE['step_worst']:>20,.0f} {worst_step:>10,.0f} {'≤ 300':>10}   "
          f"({worst_name})")
    print(f"  {'sense step, average (µs)':<44} {BEFORE['sense']:>20,.0f} {own.get('sense', (0, 0))[0]:>10,.0f} "
          f"{'':>10}   (60 % of it waited on the ADC before)")
    print(f"  {'nav step, average / worst (µs)':<44} {'':>20} "
          f"{'%.0f / %.0f' % own.get('nav', (0, 0)):>10} {'':>10}")
    print(f"  {'downlink step, average / worst (µs)':<44} {'%.0f / %.0f' % LINK_BEFORE['downlink']:>20} "
          f"{'%.0f / %.0f' % own.get('downlink', (0, 0)):>10} {'≤ 300':>10}   (before the in-place framer, "
          "2026-11-28: hello and health composed in the step)")
    print(f"  {'uplink step, average / worst (µs)':<44} {'%.0f / %.0f' % LINK_BEFORE['uplink']:>20} "
          f"{'%.0f / %.0f' % own.get('uplink', (0, 0)):>10} {'':>10}")
    print(f"  {'rocket firmware flash (B)':<44} {BEFORE['flash']:>20,} {flash:>10,} {'≤ 8,192':>10}   "
          f"(before the in-place framer: {LINK_BEFORE['flash']:,}; the link's change {LINK_DELTA['flash']:+,})")
    print(f"  {'rocket firmware RAM, data + bss (B)':<44} {BEFORE['ram']:>20,} {ram:>10,} {'':>10}   "
          f"(before the in-place framer: {LINK_BEFORE['ram']:,}; the link's change {LINK_DELTA['ram']:+,})")
    if not rep.passed:
        status = 1
        print("  THE FLIGHT FAILS: " + ", ".join(c.name for c in rep.checks if not c.passed))

    # the rocket as the targets measured it (2026-11-23): without the
    # recorder, the parameters and the pyro channels (with the resume banks
    # and their flight save) that came after, as tools/bench_firmware.py
    # core builds it for the 8 KB target
    folder = variant_core()
    app, board, run, rep, elf = flown(folder, os.path.join(folder, "build"), args.seed)
    flash, ram = flash_ram(elf)
    print()
    print(f"the core rocket ({os.path.relpath(folder, ROOT)}: examples/rocket without the recorder, the parameters "
          f"and the pyro channels, as the targets of 2026-11-23 measured it), seed {args.seed}")
    core = table(app, board, run, rep)
    print(f"  {'CPU awake per cycle, average (µs)':<44} {BEFORE['busy_avg']:>20,.0f} {core['awake']:>10,.0f} "
          f"{'≤ 400':>10}   ({'met' if core['awake'] <= TARGET['busy_avg'] else 'MISSED'}; the whole rocket above "
          f"{got['awake']:,.0f}: its flight save, recorder and parameters)")
    print(f"  flash {flash:,} B, static RAM {ram:,} B (data + bss)")
    if not rep.passed:
        status = 1
        print("  THE FLIGHT FAILS: " + ", ".join(c.name for c in rep.checks if not c.passed))

    if not args.skip_1khz:
        folder, source = variant_1khz()
        app, board, run, rep, elf = flown(folder, os.path.join(folder, "build"), args.seed)
        print()
        print(f"the rocket at 1 kHz ({os.path.relpath(folder, ROOT)}: examples/rocket's configs with rate 1000 "
              f"for the application and every task, [time] source {source}), seed {args.seed}")
        got = table(app, board, run, rep)
        h = health(run)
        if not h:
            status = 1
            print("  NO HEALTH FRAME was received: overruns and faults unknown")
        else:
            print(f"  firmware's last health frame: {h['cycles']:,} cycles, {h['overruns']} overrun(s), "
                  f"{h['faults']} fault(s), {h['late']} late cycle(s), safed tasks: {', '.join(h['safed']) or 'none'}"
                  f"   (target: 0 overruns, 0 faults through a whole flight; before: machines safed in flight)")
            over = {n: v[0] for n, v in h["by_task"].items() if v[0]}
            if over:
                print("  overruns by task: " + ", ".join(f"{n} {k}" for n, k in over.items()))
            # late starts are counted, not failed: with the executor sleeping,
            # a cycle after a long step starts late by design (docs/runtime.md)
            if h["overruns"] or h["faults"] or h["safed"]:
                status = 1
        if not rep.passed:
            status = 1
            print("  THE FLIGHT FAILS: " + ", ".join(c.name for c in rep.checks if not c.passed))
    return status


if __name__ == "__main__":
    sys.exit(main())
