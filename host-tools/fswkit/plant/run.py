"""`fsw sim PROJECT --plant rocket|tank`: build the firmware, fly it in
closed loop against the plant on the simulated board, write the link log,
the truth-and-telemetry CSV, the plot and the summary into the output
folder, print the summary and the checks; exit 1 if a check fails.

`prepare` + `execute` are the same steps for tests and tools (one build,
many flights)."""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import os
import shutil
import sys
import tempfile
from dataclasses import dataclass

from fswkit.autocode.diagnostics import Diagnostics
from fswkit.link.log import LogError
from fswkit.outputs import Stopped, stopped_by_signals

from . import report as reports
from .cosim import CosimError, Run, fly
from .params import ParamsError
from .scenario import FAULTS, PLANTS
from .scenario import load as load_scenario

FILES = {"log": "telemetry.log", "csv": "flight.csv", "png": "flight.png", "summary": "summary.txt"}


class SetupError(Exception):
    """Bad input (options, configs, parameters): message(s) printed, exit 2."""


@dataclass
class Flight:
    run: Run
    report: reports.Report
    scenario: object
    files: dict


def _say(text: str) -> None:
    sys.stderr.write(f"fsw sim: {text}\n")
    sys.stderr.flush()


def prepare(project: str, plant: str, *, params: str | None = None, seed: int = 1, fault: str | None = None,
            board: str | None = None):
    """(app, layout, scenario) for a project folder and its parameters
    file; SetupError with located messages for bad input."""
    from fswkit.target.build import BuildError, load
    from fswkit.link.layout import LayoutError, from_app

    if plant not in PLANTS:
        raise SetupError(f"--plant {plant}: one of {', '.join(PLANTS)}")
    if fault is not None and fault not in FAULTS:
        raise SetupError(f"--fault {fault}: one of {', '.join(FAULTS)}")
    diags = Diagnostics()
    try:
        app = load(project, diags, board)
    except BuildError as e:
        raise SetupError(str(e)) from None
    if app is None:
        raise SetupError(diags.render())
    try:
        layout = from_app(app)
    except LayoutError as e:
        raise SetupError(str(e)) from None
    if params is None:
        params = os.path.join(os.path.dirname(app.path) or ".", "plant.toml")
    try:
        sc = load_scenario(plant, params, app, layout, seed, fault)
    except ParamsError as e:
        raise SetupError("\n".join(e.errors)) from None
    return app, layout, sc


def budget_checks(app, elf: str, run: Run) -> list[reports.Check]:
    """The application's [budget] against the flown firmware: flash from the
    ELF, RAM as static data plus the stack's high-water mark measured on the
    board during this run. None set: the board's memory."""
    from fswkit.target.build import BuildError, elf_size

    out = []
    try:
        flash, _ram = elf_size(elf)
    except BuildError as e:
        return [reports.Check("the firmware's size", False, str(e))]
    whose = "the application's [budget]" if app.flash_budget is not None else f"the {app.board.name}'s memory"
    limit = app.flash_budget or app.board.flash
    out.append(reports.Check(f"flash within {whose}", flash <= limit, f"{flash:,} of {limit:,} B"))
    ram = run.ram.get("ram_usage")
    whose = "the application's [budget]" if app.ram_budget is not None else f"the {app.board.name}'s memory"
    limit = app.ram_budget or app.board.ram
    if ram is None or isinstance(ram, str):
        out.append(reports.Check(f"RAM within {whose}", False, f"the stack was not measured: {ram}"))
    else:
        out.append(reports.Check(f"RAM within {whose}, stack included", ram.total <= limit,
                                 f"{ram.static:,} B static + {ram.stack:,} B stack high-water = "
                                 f"{ram.total:,} of {limit:,} B"))
    return out


INCOMPLETE = "incomplete"  # OUT/incomplete: the files of the last run that did not finish


class Interrupted(Exception):
    """A run stopped before its end (its partial files are kept apart)."""


def execute(sc, elf: str, board, layout, out: str | None, *, quiet: bool = False) -> Flight:
    """Flies the scenario; writes the files into `out` (None: none). CosimError
    if the run could not go on.

    A run's files are one set: they are written into a fresh folder inside
    `out` and moved into place only once all of them are (the summary last,
    after the previous summary is gone), so `out` never holds one run's log
    beside another's summary. A run that does not finish (an error, Ctrl-C,
    SIGTERM, SIGHUP)
    leaves the previous set as it was and its own partial files in
    `out/incomplete/`, with a note saying so."""
    if out is None:
        return _execute(sc, elf, board, layout, None)
    os.makedirs(out, exist_ok=True)
    stage = tempfile.mkdtemp(prefix=".run-", dir=out)
    with stopped_by_signals():
        try:
            flight = _execute(sc, elf, board, layout, stage)
        except BaseException as e:
            _set_aside(stage, out, e)
            raise
        flight.files = _install(stage, out)
    return flight


def _execute(sc, elf, board, layout, folder: str | None) -> Flight:
    files = {k: os.path.join(folder, v) for k, v in FILES.items()} if folder is not None else {}
    meta = {"source": f"fsw sim --plant {sc.kind}", "clock": "simulated", "seed": sc.seed, "fault": sc.fault}
    run = fly(sc, elf, board, layout, files.get("log"), log_meta=meta)
    rep = reports.rocket(run, sc) if sc.kind == "rocket" else reports.tank(run, sc)
    rep.checks += budget_checks(sc.app, elf, run)
    if folder is not None:
        reports.write_csv(run, layout, sc.state_element, files["csv"])
        title = (f"{layout.name}: {sc.kind} plant, seed {sc.seed}" + (f", fault {sc.fault}" if sc.fault else "")
                 + (" — all checks pass" if rep.passed else " — CHECKS FAIL"))
        with open(files["csv"], "rb") as f:
            digest = hashlib.sha256(f.read()).hexdigest()
        reports.plot(run, sc, files["png"], title, digest)
        with open(files["summary"], "w") as f:
            f.write(rep.text())
    return Flight(run, rep, sc, files)


def _install(stage: str, out: str) -> dict:
    """Moves a finished run's files from `stage` into `out`: the old summary
    goes first and the new one comes last, so a summary always describes
    the files beside it."""
    files = {k: os.path.join(out, v) for k, v in FILES.items()}
    with contextlib.suppress(FileNotFoundError):
        os.unlink(files["summary"])
    for k in ("log", "csv", "png", "summary"):
        os.replace(os.path.join(stage, FILES[k]), files[k])
    shutil.rmtree(stage, ignore_errors=True)
    return files


def _set_aside(stage: str, out: str, why: BaseException) -> None:
    """A run that did not finish: its files to `out/incomplete/`, with a note."""
    if isinstance(why, Stopped):
        reason = f"stopped by {why}"
    else:
        reason = "interrupted (Ctrl-C)" if isinstance(why, KeyboardInterrupt) else f"stopped: {why}"
    try:
        with open(os.path.join(stage, "INCOMPLETE.txt"), "w") as f:
            f.write(f"This run did not finish ({reason}): its files are partial, and it has no summary.\n"
                    f"The files in {out} are those of the last run that finished.\n")
        target = os.path.join(out, INCOMPLETE)
        shutil.rmtree(target, ignore_errors=True)
        os.replace(stage, target)
    except OSError:
        shutil.rmtree(stage, ignore_errors=True)


def main(args) -> int:
    """The `fsw sim ... --plant` command."""
    from fswkit.sim.command import _build, _is_elf

    for opt, given in (("--duration", args.duration is not None), ("--fast", args.fast),
                       ("--analog", bool(args.analog)), ("--link", args.link is not None)):
        if given:
            _say(f"{opt} is for the free-running board on a pty; with --plant the scenario drives the run")
            return 2
    if args.fault and args.plant != "rocket":
        _say(f"--fault {args.fault} is a fault of the rocket plant; the tank's scenario has its regulator "
             "failure built in")
        return 2
    if _is_elf(args.project) or args.project.endswith(".elf"):
        _say(f"{args.project}: --plant needs the project (its folder or .app: the plant reads its machines "
             "and pins), not a firmware ELF")
        return 2
    try:
        seed = 1 if args.seed is None else args.seed
        app, layout, sc = prepare(args.project, args.plant, params=args.params, seed=seed, fault=args.fault,
                                  board=args.board)
    except SetupError as e:
        for line in str(e).splitlines():
            sys.stderr.write(f"fsw sim: {line}\n" if line and not line.startswith((" ", "|")) else line + "\n")
        return 2
    from fswkit.target.build import default_out

    out = args.out or os.path.join(default_out(app), f"{args.plant}-flight")
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as e:
        _say(f"cannot create the output folder {out}: {e.strerror or e}")
        return 2
    built = _build(argparse.Namespace(project=args.project, board=args.board, out=None))
    if isinstance(built, int):
        return built
    elf, board = built
    what = f"seed {sc.seed}" + (f", fault {sc.fault}" if sc.fault else "")
    _say(f"{args.plant} plant at {sc.rate} Hz in lock-step with the {board.name}, {what}; up to {sc.max_s:g} s "
         "simulated")
    incomplete = (f"; its partial files are in {os.path.join(out, INCOMPLETE)}, and the files in {out} are "
                  "still the last finished run's")
    try:
        flight = execute(sc, elf, board, layout, out)
    except Stopped as e:
        _say(f"stopped by {e}" + incomplete)
        return 128 + e.signum
    except KeyboardInterrupt:
        _say("interrupted" + incomplete)
        raise
    except (CosimError, LogError) as e:  # LogError: the log could not be written (a full disk)
        _say(str(e) + incomplete)
        return 1
    except OSError as e:
        _say(f"cannot write {e.filename or out}: {e.strerror or e}" + incomplete)
        return 1
    sys.stdout.write(flight.report.text())
    sys.stdout.flush()
    _say("wrote " + ", ".join(flight.files[k] for k in ("log", "csv", "png", "summary")))
    return 0 if flight.report.passed else 1
