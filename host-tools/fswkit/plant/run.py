"""Closed-loop flights (`fsw sim PROJECT --plant rocket|tank`, whose
command is fswkit.cli.sim): the firmware flown against the plant on the
simulated board, the link log, the truth-and-telemetry CSV, the plot and
the summary written into the output folder as one set, and the checks,
the application's [budget] among them.

`prepare` + `execute` are the same steps for the command (fswkit.cli.sim),
tests and tools (one build, many flights)."""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
import struct
import sys
import tempfile
from dataclasses import dataclass

from fswkit.autocode.diagnostics import Diagnostics
from fswkit.outputs import RECORDING_MAGIC, OutputError, Stopped, file_head, stopped_by_signals

from . import report as reports
from .cosim import Run, fly
from .params import ParamsError
from .scenario import PLANTS, parse_fault
from .scenario import load as load_scenario

FILES = {"log": "telemetry.log", "csv": "flight.csv", "png": "flight.png", "record": "record.log",
         "summary": "summary.txt"}
OPTIONAL = ("record",)  # written only by some runs (the flight recorder's dump)


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
            board: str | None = None, fw_params: str | None = None):
    """(app, layout, scenario) for a project folder and its parameters
    file; SetupError with located messages for bad input. `fw_params`: a
    file of the firmware's parameters (docs/parameters.md), programmed into
    the board's EEPROM before boot; the checks see its values."""
    from fswkit.target.build import BuildError, load
    from fswkit.link.layout import LayoutError, from_app

    if plant not in PLANTS:
        raise SetupError(f"--plant {plant}: one of {', '.join(PLANTS)}")
    if fault is not None:
        try:
            parse_fault(fault)
        except ValueError as e:
            raise SetupError(str(e)) from None
    diags = Diagnostics()
    try:
        app = load(project, diags, board)
    except BuildError as e:
        raise SetupError(str(e)) from None
    if app is None:
        raise SetupError(diags.render())
    image = None
    if fw_params is not None:
        app, image = firmware_params(app, fw_params)
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
    sc.eeprom = image
    return app, layout, sc


def firmware_params(app, path: str):
    """(the application as it runs with the parameter file at `path`, the
    EEPROM image that makes the firmware boot with it: its bank A);
    SetupError for a project without parameters or a bad file."""
    from fswkit.autocode.params import app_parameters, app_with_values, bank_image
    from fswkit.param.files import ParamFileError, read_params

    params = app_parameters(app)
    if not params:
        raise SetupError(f"--fw-params {path}: the application declares no parameters")
    try:
        values = read_params(path, params)
    except ParamFileError as e:
        raise SetupError(str(e)) from None
    return app_with_values(app, values), bank_image(params, values, seq=1)


def budget_checks(app, elf: str, run: Run) -> list[reports.Check]:
    """The application's [budget] against the flown firmware (the build
    service's `budget`: the board's memory where it sets none): flash from
    the ELF, RAM as static data plus the stack's high-water mark measured
    on the board during this run."""
    from fswkit.target.build import BuildError, budget, elf_size

    out = []
    try:
        flash, _ram = elf_size(elf)
    except BuildError as e:
        return [reports.Check("the firmware's size", False, str(e))]
    limits = budget(app)
    limit, whose = limits["flash"]
    out.append(reports.Check(f"flash within {whose}", flash <= limit, f"{flash:,} of {limit:,} B"))
    ram = run.ram.get("ram_usage")
    limit, whose = limits["RAM"]
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


def refuse_inputs(out: str, inputs, extra=()) -> None:
    """Before any work: an OutputError when a file a flight or a replay
    writes into `out` (FILES, and `extra` names) is one of the command's
    `inputs` (its plant or tape file, its dispersion, its parameters):
    the set of files replaces what is there, and an input is never lost."""
    from fswkit.outputs import not_an_input

    for name in list(FILES.values()) + list(extra):
        not_an_input(os.path.join(out, name), inputs, what=f"flight's {name}")
    refuse_users_files(out, list(FILES.values()) + list(extra) + [INCOMPLETE])


def _kit_log(path: str) -> bool:
    """Whether `path` is a link log a run of `fsw sim` wrote (its header's
    "source"), not a recording of a real link."""
    head = file_head(path, len(RECORDING_MAGIC) + 4)
    if head is None or len(head) < len(RECORDING_MAGIC) + 4 or not head.startswith(RECORDING_MAGIC):
        return False
    n = struct.unpack("<I", head[len(RECORDING_MAGIC):])[0]
    if n > 1 << 22:
        return False
    whole = file_head(path, len(head) + n)
    try:
        meta = json.loads(whole[len(head):])
    except (TypeError, ValueError):
        return False
    return isinstance(meta, dict) and str(meta.get("source", "")).startswith("fsw sim")


# What shows that a folder holds the files of an earlier run of `fsw sim`:
# the run's link log, the table of a study or of a tape's perturbed
# replays, the note of a run that did not finish (their first bytes).
_RUN_MARKS = {"study.txt": b"dispersion study: ", "perturb.txt": b"robustness: ",
              os.path.join(INCOMPLETE, "INCOMPLETE.txt"): b"This run did not finish"}


def is_run_folder(out: str) -> bool:
    """Whether an earlier run of `fsw sim` wrote the folder `out` (_RUN_MARKS)."""
    if _kit_log(os.path.join(out, FILES["log"])):
        return True
    for name, mark in _RUN_MARKS.items():
        head = file_head(os.path.join(out, name), len(mark))
        if head is not None and head == mark:
            return True
    return False


def refuse_users_files(out: str, names) -> None:
    """Before any work: an OutputError when `out` holds any of `names`, the
    files (and the `incomplete` folder) a run writes, replaces or removes
    there, and is not a folder an earlier run of `fsw sim` wrote
    (`is_run_folder`): a flight's files replace only an earlier run's,
    never a user's `flight.csv`, `summary.txt`, link log or folder."""
    if os.path.lexists(out) and not os.path.isdir(out):
        raise OutputError(f"{out} is a file, not a folder: name a folder for the run's files (--out)")
    there = [n for n in names if os.path.lexists(os.path.join(out, n))]
    odd = [n for n in there if n != INCOMPLETE and not os.path.isfile(os.path.join(out, n))]
    if odd:  # a folder, a FIFO, a device where a file goes: the set could not be moved in whole
        raise OutputError(f"{os.path.join(out, odd[0])} is not a regular file: a run's {odd[0]} replaces only a "
                          "file; move it away, or name another --out")
    if not there or is_run_folder(out):
        return
    shown = ", ".join(there[:4]) + (f" and {len(there) - 4} more" if len(there) > 4 else "")
    raise OutputError(f"{out} holds files an earlier run of fsw sim did not write ({shown}): a run replaces "
                      "only its own files; name another --out, or move them away")


def _execute(sc, elf, board, layout, folder: str | None) -> Flight:
    files = {k: os.path.join(folder, v) for k, v in FILES.items()} if folder is not None else {}
    meta = {"source": f"fsw sim --plant {sc.kind}", "clock": "simulated", "seed": sc.seed, "fault": sc.fault}
    run = fly(sc, elf, board, layout, files.get("log"), log_meta=meta)
    rep = reports.rocket(run, sc) if sc.kind == "rocket" else reports.tank(run, sc)
    flight_record = None
    if sc.app.log is not None:
        flight_record = _recorder(sc, run, rep)
    rep.checks += budget_checks(sc.app, elf, run)
    if folder is not None:
        reports.write_csv(run, layout, sc.state_element, files["csv"])
        title = (f"{layout.name}: {sc.kind} plant, seed {sc.seed}" + (f", fault {sc.fault}" if sc.fault else "")
                 + (" — all checks pass" if rep.passed else " — CHECKS FAIL"))
        with open(files["csv"], "rb") as f:
            digest = hashlib.sha256(f.read()).hexdigest()
        reports.plot(run, sc, files["png"], title, digest)
        if flight_record is not None:
            from fswkit.recorder.dump import write_flight

            write_flight(files["record"], sc.app, *flight_record)
        with open(files["summary"], "w") as f:
            f.write(rep.text())
    return Flight(run, rep, sc, files)


def _recorder(sc, run: Run, rep) -> tuple | None:
    """The flight recorder's part of the report (docs/recorder.md): the
    record read from the board's EEPROM after the flight, against the
    telemetry and the truth; (plan, flight) to write as record.log."""
    from fswkit.recorder.check import flight_report

    truth = None
    if sc.kind == "rocket":
        i, j = run.columns.index("time_s"), run.columns.index("altitude_m")
        truth = ([r[i] for r in run.rows], [r[j] for r in run.rows])
    lines, checks, record = flight_report(sc.app, run, reports.Check, truth=truth,
                                          alt_element=getattr(sc, "altitude_element", None))
    rep.lines += lines
    rep.checks += checks
    return record


def _install(stage: str, out: str) -> dict:
    """Moves a finished run's files from `stage` into `out`: the old summary
    goes first and the new one comes last, so a summary always describes
    the files beside it."""
    files = {k: os.path.join(out, v) for k, v in FILES.items()}
    with contextlib.suppress(FileNotFoundError):
        os.unlink(files["summary"])
    for k in ("log", "csv", "png", "record", "summary"):
        if k in OPTIONAL and not os.path.exists(os.path.join(stage, FILES[k])):
            with contextlib.suppress(FileNotFoundError):
                os.unlink(files[k])  # the previous run's: it does not belong to this set
            files.pop(k)
            continue
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
