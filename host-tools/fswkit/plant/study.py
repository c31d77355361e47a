"""Dispersion studies (`fsw sim PROJECT --plant rocket --runs N
--dispersion FILE.toml`): N closed-loop flights of the real firmware, each
on its own simulated board with its own draw of the dispersions
(fswkit.plant.dispersion), several at a time in a pool of processes (each
pinned to one CPU with its board: a lock-step flight is a ping-pong
between the two). A run stops when its outcome is decided: the landed
state seen (no linger), the run's time limit, or the plant's touchdown plus
its landed timeout.

The study's result: for each check, the share of runs that passed it with
a 95 % Wilson interval; the distributions (percentiles) of the apogee
detection error and of the main's altitude error; every failing run with
the command that flies it again alone, exactly (`--seed S --run I`); the
flights per hour. `text` renders it, `csv_text` gives one row per run.
"""

from __future__ import annotations

import math
import multiprocessing
import os
import resource
import shlex
import signal
import time
from dataclasses import dataclass, field

import numpy as np

from . import report as reports
from .cosim import CosimError, fly
from .dispersion import Dispersion, Draw, apply, draw
from .params import ParamsError
from .scenario import load as load_scenario


@dataclass
class Setup:
    """What every run shares: the project as loaded, its parameters file,
    the firmware built once, the dispersion and the study's seed; and the
    command line's words for the replay command."""

    app: object
    layout: object
    params: str
    elf: str
    board: object
    disp: Dispersion
    seed: int
    command: list = field(default_factory=list)  # `fsw sim PROJECT --plant rocket ...` without --runs/--run
    span_s: float | None = None  # the flight's end, s after ignition (span_of): events drawn up to it


def span_of(sc) -> float:
    """How long after ignition a scenario's flight may last (its max_s less
    its ignition_s): a run's spikes, dropouts and gusts are drawn that far."""
    return sc.max_s - (sc.ignition_s or 0.0)


def draw_run(setup: Setup, index: int) -> Draw:
    """Run `index` of the study's draw, its events up to the flight's end."""
    return draw(setup.disp, setup.seed, index, span_s=setup.span_s)


@dataclass
class RunResult:
    index: int
    draw: Draw
    checks: list = field(default_factory=list)  # (key, name, passed, detail)
    facts: dict = field(default_factory=dict)
    error: str | None = None
    sim_s: float = 0.0
    wall_s: float = 0.0
    cpu_s: float = 0.0  # this process and its simulated board
    resets: list = field(default_factory=list)
    motor_ns: float | None = None

    @property
    def passed(self) -> bool:
        return self.error is None and all(c[2] for c in self.checks)


def check_key(name: str) -> str:
    """A check's name without its numbers, the same whether it passed or not
    ("main fired within ±15 m of MAIN_ALT = 150 m" -> "main fired")."""
    return " ".join(name.split()[:2])


def scenario_for(setup: Setup, d: Draw):
    """Run `d`'s scenario: plant.toml loaded with the run's noise seed, the
    dispersions applied, no lingering after the landed state."""
    sc = load_scenario("rocket", setup.params, setup.app, setup.layout, d.noise_seed, None)
    sc.app = setup.app
    sc.p["scenario"]["linger_s"] = 0.0
    apply(sc, d)
    return sc


def _cpu() -> float:
    s, c = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return s.ru_utime + s.ru_stime + c.ru_utime + c.ru_stime


def fly_run(setup: Setup, index: int) -> RunResult:
    """Flies run `index` of the study (no files)."""
    d = draw_run(setup, index)
    res = RunResult(index, d)
    cpu0, wall0 = _cpu(), time.perf_counter()
    try:
        sc = scenario_for(setup, d)
        res.motor_ns = sc.motor.total
        run = fly(sc, setup.elf, setup.board, setup.layout)
        rep = reports.rocket(run, sc)
        res.checks = [(check_key(c.name), c.name, c.passed, c.detail) for c in rep.checks]
        res.facts = rep.facts
        res.sim_s, res.resets = run.sim_s, list(run.resets)
    except (CosimError, ParamsError) as e:  # ParamsError: plant.toml changed under a running study
        res.error = str(e)
    res.wall_s, res.cpu_s = time.perf_counter() - wall0, _cpu() - cpu0
    return res


# ---- the pool ------------------------------------------------------------------------------

_setup: Setup | None = None  # the workers' copy (inherited at fork)


TERM_GRACE_S = 10  # a worker told to stop is gone by then, however its SystemExit fares


def _on_term(signum, _frame):
    # The pool stops its workers with one SIGTERM and waits for them without
    # a limit. Where Python only prints an exception (an at-fork hook, a
    # __del__) the SystemExit is lost, so the alarm's default action ends
    # the worker anyway; its board sees its pipe close and stops.
    signal.signal(signal.SIGALRM, signal.SIG_DFL)
    signal.alarm(TERM_GRACE_S)
    raise SystemExit(128 + signum)  # unwinds: the run's board is closed on the way out


def _worker_init(cpus) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    signal.signal(signal.SIGTERM, _on_term)
    signal.signal(signal.SIGHUP, _on_term)
    try:
        cpu = cpus.get(timeout=5)
        if cpu is not None:
            os.sched_setaffinity(0, {cpu})  # this worker and the boards it starts
    except Exception:  # noqa: BLE001 (no affinity on this system, or the queue is gone: run unpinned)
        pass


def _worker_run(index: int) -> RunResult:
    return fly_run(_setup, index)


def cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def run_study(setup: Setup, runs: int, jobs: int, on_result=None) -> tuple[list[RunResult], bool]:
    """Flies runs 0..runs-1, `jobs` at a time; calls on_result(result) as
    each ends. (results in run order, complete): complete is False when
    Ctrl-C or a stopping signal (fswkit.outputs.Stopped) ended it early,
    with the runs finished by then."""
    global _setup
    _setup = setup
    results: list[RunResult] = []
    jobs = max(1, min(jobs, runs))
    ctx = multiprocessing.get_context("fork")
    cpus = ctx.Queue()
    try:
        allowed = sorted(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        allowed = []
    for i in range(jobs):
        cpus.put(allowed[i % len(allowed)] if len(allowed) > 1 else None)
    pool = ctx.Pool(jobs, initializer=_worker_init, initargs=(cpus,))
    complete = False
    try:
        for res in pool.imap_unordered(_worker_run, range(runs), chunksize=1):
            results.append(res)
            if on_result is not None:
                on_result(res)
        complete = True
    except KeyboardInterrupt:
        pass
    finally:
        if complete:
            pool.close()
        else:
            pool.terminate()
        pool.join()
        _setup = None
    results.sort(key=lambda r: r.index)
    return results, complete


# ---- the table -----------------------------------------------------------------------------

def wilson(k: int, n: int, z: float = 1.959964) -> tuple[float, float]:
    """The Wilson score interval of a proportion k/n (95 % for the default z)."""
    if n == 0:
        return 0.0, 1.0
    p = k / n
    den = 1 + z * z / n
    mid = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return max(0.0, mid - half), min(1.0, mid + half)


PERCENTILES = (0, 5, 50, 95, 100)
ERRORS = (("apogee_error_s", "apogee detection − true apogee", "s", "+.3f"),
          ("apogee_error_m", "highest telemetered − true apogee", "m", "+.1f"),
          ("main_error_m", "main's altitude − its configured altitude", "m", "+.1f"))


def _facts(r: RunResult) -> dict:
    f = dict(r.facts)
    if "main_alt_m" in f and f.get("main_config_m") is not None:
        f["main_error_m"] = f["main_alt_m"] - f["main_config_m"]
    return f


def replay_command(setup: Setup, index: int) -> str:
    return " ".join(shlex.quote(w) for w in setup.command + ["--seed", str(setup.seed), "--run", str(index)])


def text(setup: Setup, results: list[RunResult], runs: int, jobs: int, wall: float, complete: bool,
         disp_path: str | None) -> str:
    n = len(results)
    lines = [f"dispersion study: {setup.layout.name}, {n} of {runs} runs"
             + ("" if complete else " (stopped early: the table covers the runs that finished)")
             + f", seed {setup.seed}, dispersion {disp_path or 'none'}; {jobs} at a time"]
    if n and wall > 0:
        cpu = sum(r.cpu_s for r in results) / n
        sim = sum(r.sim_s for r in results) / n
        lines.append(f"speed: {n / wall * 3600:,.0f} flights per hour ({wall:.1f} s wall for {n}); per flight "
                     f"{sim:.1f} s simulated, {cpu:.2f} s of CPU")
    names: dict[str, str] = {}
    for r in results:
        for key, name, passed, _ in r.checks:
            if key not in names or passed:
                names[key] = name
    lines.append("checks (P = share of runs passing, 95 % Wilson interval; a run that could not finish fails "
                 "every check):")
    width = max([len(x) for x in names.values()] + [len("every check")])
    for key, name in names.items():
        k = sum(1 for r in results if any(c[0] == key and c[2] for c in r.checks))
        lo, hi = wilson(k, n)
        lines.append(f"  {name:<{width}}  {k:5d}/{n:<5d} P {k / n:.3f}  [{lo:.3f}, {hi:.3f}]")
    k = sum(r.passed for r in results)
    lo, hi = wilson(k, n)
    if n:
        lines.append(f"  {'every check':<{width}}  {k:5d}/{n:<5d} P {k / n:.3f}  [{lo:.3f}, {hi:.3f}]")
    lines.append("errors (percentiles over the runs that had the event):")
    lines.append(f"  {'':<44}" + "".join(f"{'p' + str(q) if q not in (0, 100) else ('min' if q == 0 else 'max'):>9}"
                                       for q in PERCENTILES) + "     runs")
    facts = [_facts(r) for r in results]
    for key, label, unit, spec in ERRORS:
        xs = np.array([f[key] for f in facts if f.get(key) is not None and math.isfinite(f[key])], dtype=float)
        if xs.size:
            cells = "".join(f"{format(float(np.percentile(xs, q)), spec):>9}" for q in PERCENTILES)
            lines.append(f"  {label + ' (' + unit + ')':<44}{cells}  {xs.size:5d}")
        else:
            lines.append(f"  {label + ' (' + unit + ')':<44}  never seen")
    bad = [r for r in results if not r.passed]
    if bad:
        lines.append(f"failing runs ({len(bad)}; each flies again alone, exactly, with its files, by the command "
                     "under it):")
        for r in bad:
            why = r.error or "; ".join(f"{c[1]}: {c[3]}" for c in r.checks if not c[2])
            extra = ""
            if r.draw.brownout_s is not None:  # drawn; a flight that ended first had no reset
                extra = (f" [brown-out {r.draw.brownout_s:.2f} s after ignition]" if r.resets else
                         f" [brown-out drawn at {r.draw.brownout_s:.2f} s after ignition, after the run's end: no reset]")
            lines.append(f"  run {r.index}{extra}: {why}")
            lines.append(f"    {replay_command(setup, r.index)}")
    lines.append(f"{n - len(bad)} of {n} runs passed every check")
    return "\n".join(lines) + "\n"


def _cell(x) -> str:
    if x is None:
        return ""
    if isinstance(x, bool):
        return str(int(x))
    if isinstance(x, float):
        return f"{x:.6g}"
    return str(x)


def csv_text(results: list[RunResult]) -> str:
    keys = list(dict.fromkeys(c[0] for r in results for c in r.checks))
    draw_keys = list(Draw(0, 0, 0).row())
    fact_keys = ["true_apogee_m", "true_apogee_s", "apogee_error_s", "apogee_error_m", "main_error_m"]
    head = (["run", "noise_seed"] + draw_keys + ["motor_ns", "resets"] + fact_keys
            + [k.replace(" ", "_") for k in keys] + ["passed", "sim_s", "cpu_s", "error"])
    out = [",".join(head)]
    for r in results:
        row = r.draw.row()
        f = _facts(r)
        passed = {c[0]: c[2] for c in r.checks}
        cells = ([r.index, r.draw.noise_seed] + [row[k] for k in draw_keys]
                 + [r.motor_ns, ";".join(f"{t:.3f}" for t in r.resets)] + [f.get(k) for k in fact_keys]
                 + [passed.get(k) for k in keys] + [r.passed, r.sim_s, r.cpu_s,
                                                    (r.error or "").replace(",", ";").replace("\n", " ")])
        out.append(",".join(_cell(x) for x in cells))
    return "\n".join(out) + "\n"
