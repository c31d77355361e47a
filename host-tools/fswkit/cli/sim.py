"""`fsw sim`: the firmware on the simulated board, free-running with UART0
on a pseudo-terminal (`board_run`: fswkit.sim), or flown in closed loop
against a plant (`--plant`, `plant_run`: fswkit.plant.run). Both build
with the build service (fswkit.sim.command.build), `[budget]` included."""

from __future__ import annotations

import os
import sys
import time

from fswkit.cli.common import EXIT_CONFIG, flown, folder_and_firmware


def _firmware_param_file(path: str) -> bool:
    """Whether `--params FILE` names a file of the firmware's parameters
    (top-level `NAME = value` lines only) rather than a plant's or a tape's
    configuration (tables, or an `extends` of another such file)."""
    import tomllib

    from fswkit.autocode.diagnostics import read_input

    try:  # a FIFO or a device is not read (the reader below says so)
        doc = tomllib.loads(read_input(path).decode("utf-8"))
    except (OSError, ValueError):  # TOMLDecodeError, a bad encoding, an integer too long for int()
        return False  # the plant's or the tape's reader says what is wrong with it
    # a plant's or a tape's file may hold no table of its own when it `extends` another
    return bool(doc) and "extends" not in doc and not any(isinstance(v, dict) for v in doc.values())


def cmd_sim(args) -> int:
    given = "--fw-params"  # the option that named the firmware's parameters, for messages
    if getattr(args, "params", None) is not None and _firmware_param_file(args.params):
        if getattr(args, "fw_params", None) is not None:
            sys.stderr.write("fsw sim: --params and --fw-params both name the firmware's parameters: give one\n")
            return EXIT_CONFIG
        args.fw_params, args.params = args.params, None
        given = "--params"
    if any(getattr(args, k, None) is not None for k in ("runs", "run", "dispersion", "jobs")):
        if getattr(args, "fw_params", None) is not None:
            what = (f"--params {args.fw_params} holds the firmware's parameters (NAME = value lines, as --fw-params "
                    "takes)" if given == "--params" else "--fw-params flies one firmware's parameters")
            sys.stderr.write(f"fsw sim: {what}; a study flies the firmware as built (not with --runs, --jobs, --run "
                             "or --dispersion)\n")
            return EXIT_CONFIG
        if getattr(args, "tape", None) is not None or getattr(args, "perturb", None) is not None:
            sys.stderr.write("fsw sim: --runs, --jobs, --run and --dispersion fly the rocket plant, not a --tape\n")
            return EXIT_CONFIG
        if getattr(args, "eeprom_file", None) is not None:
            sys.stderr.write("fsw sim: --eeprom-file is for the free-running board on a pty, not a study\n")
            return EXIT_CONFIG
        from fswkit.cli.sim_study import study_run
        return study_run(args)
    if getattr(args, "tape", None) is not None:
        return tape_run(args)
    if getattr(args, "perturb", None) is not None:
        sys.stderr.write("fsw sim: --perturb needs --tape FLIGHT.csv\n")
        return EXIT_CONFIG
    if args.plant is not None:
        return plant_run(args)
    if args.params is not None or args.fault is not None or args.seed is not None:
        sys.stderr.write("fsw sim: --params, --seed and --fault need --plant rocket|tank\n")
        return EXIT_CONFIG
    return board_run(args)


def _fw_image(args):
    """The EEPROM image of `--fw-params` for the project, or 2 after a message."""
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.plant.run import SetupError, firmware_params
    from fswkit.target.build import BuildError, load

    diags = Diagnostics()
    try:
        app = load(args.project, diags, args.board)
        if app is None:
            sys.stderr.write(diags.render() + "\n")
            return 2
        return firmware_params(app, args.fw_params)[1]
    except (BuildError, SetupError) as e:
        sys.stderr.write(f"fsw sim: {e}\n")
        return 2


def board_run(args) -> int:
    """`fsw sim PROJECT|FW.elf`: build, start with UART0 on a pty, print the
    pty's path on standard output, run until Ctrl-C or --duration."""
    from fswkit.sim.board import SimBoard, SimError, link_problem, sim_board
    from fswkit.sim.command import analog_args, build, is_elf, say

    if args.duration is not None and not 0 < args.duration < 1e9:
        say("--duration must be a positive number of simulated seconds")
        return 2
    if args.link is not None and link_problem(args.link) is not None:
        say(link_problem(args.link))
        return 2
    if args.eeprom_file is not None and _memory_file_problem(args.eeprom_file, "--eeprom-file") is not None:
        say(_memory_file_problem(args.eeprom_file, "--eeprom-file"))
        return 2
    image = None  # --fw-params: checked before any build
    if args.fw_params is not None:
        if is_elf(args.project) or args.project.endswith(".elf"):
            say("--fw-params needs the project (its parameters' table), not a firmware ELF")
            return 2
        image = _fw_image(args)
        if isinstance(image, int):
            return image
    if image is not None and args.eeprom_file is not None:
        say("--fw-params programs the EEPROM that --eeprom-file keeps: give one of them")
        return 2
    if is_elf(args.project) or args.project.endswith(".elf"):
        if args.board is None:
            say(f"{args.project}: a firmware ELF needs --board (the board it was built for, e.g. uno)")
            return 2
        try:
            board = sim_board(args.board)
        except SimError as e:
            say(str(e))
            return 2
        elf = args.project
    else:
        def analog_problem(board):
            problem = analog_args(args.analog or [], board)
            return problem if isinstance(problem, str) else None
        built = build(args.project, args.board, args.out, before=analog_problem)
        if isinstance(built, int):
            return built
        elf, board = built
    analog = analog_args(args.analog or [], board)
    if isinstance(analog, str):
        say(analog)
        return 2
    try:
        b = SimBoard(elf, board, uart="pty", analog=analog, link=args.link, eeprom=image,
                     eeprom_file=args.eeprom_file)
    except SimError as e:
        say(str(e))
        return 1
    with b:
        sys.stdout.write(f"{b.port}\n")
        sys.stdout.flush()
        pace = "as fast as it can" if args.fast else "in real time"
        end = f"for {args.duration:g} simulated s" if args.duration else "until Ctrl-C"
        link = f" (and {args.link})" if args.link else ""
        say(f"{board.name} ({b.mcu} at {b.f_cpu / 1e6:g} MHz) runs {pace} {end}; UART0 is {b.port}{link}")
        t0 = time.monotonic()
        try:
            r = b.go(until=args.duration, realtime=not args.fast)
        except SimError as e:
            say(str(e))
            return 1
        wall = time.monotonic() - t0
        why = {"target": "duration reached", "interrupted": "stopped", "done": "the firmware stopped itself",
               "crashed": "the firmware crashed", "sim-limit": "simulated-time limit",
               "wall-limit": "wall-clock limit"}.get(r.stop, r.stop)
        say(f"{why} at {r.time:.6f} s simulated ({r.cycle:,} cycles) after {wall:.2f} s")
        dropped = int(b.info().get("dropped", "0"))
        if dropped:
            say(f"{dropped:,} UART bytes were sent while no program had the port open")
        try:
            ram = b.ram_usage()
            say(f"stack high-water {ram.stack:,} B; RAM {ram.static:,} B static + {ram.stack:,} B stack = "
                 f"{ram.total:,} of {ram.ram:,} B")
        except SimError as e:
            say(f"stack not measured: {e}")
    for why in b.save_errors:  # the board's memory was not kept: said, never a silent success
        say(why)
    return 1 if r.stop == "crashed" or b.save_errors else 0


def _memory_file_problem(path: str, option: str) -> str | None:
    """What forbids keeping a memory of the board in `path` (read at the
    start, replaced at the end), or None: it must be a regular file, or
    nothing yet, in a folder that exists, and never a recording (a FIFO
    would wait for a writer, a folder or a device is not a memory's file)."""
    import stat

    from fswkit.outputs import recording

    if not path:
        return f"{option} needs a path (the file that keeps the memory)"
    if os.path.isdir(path):
        return f"{option} {path}: it is a folder (name a file to keep the memory in)"
    if os.path.exists(path):
        try:
            regular = stat.S_ISREG(os.stat(path).st_mode)
        except OSError as e:
            return f"{option} {path}: {e.strerror or e}"
        if not regular:
            return f"{option} {path}: not a regular file (a FIFO, a device): the memory is kept in a file"
        kind = recording(path)
        if kind is not None:
            return f"{option} {path}: {kind} (a recording) is there: it is never overwritten; choose another name"
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        return f"{option} {path}: no such folder {folder}"
    return None


def plant_run(args) -> int:
    """`fsw sim PROJECT --plant rocket|tank`: build, fly, write the files, print the checks."""
    from fswkit.outputs import OutputError
    from fswkit.plant.run import SetupError, execute, prepare, refuse_inputs
    from fswkit.sim.command import build, is_elf, say
    from fswkit.target.build import BuildError, default_output

    for opt, given in (("--duration", args.duration is not None), ("--fast", args.fast),
                       ("--analog", bool(args.analog)), ("--link", args.link is not None),
                       ("--eeprom-file", args.eeprom_file is not None)):
        if given:
            say(f"{opt} is for the free-running board on a pty; with --plant the scenario drives the run")
            return 2
    if args.fault and args.plant != "rocket":
        say(f"--fault {args.fault} is a fault of the rocket plant; the tank's scenario has its regulator "
            "failure built in")
        return 2
    if is_elf(args.project) or args.project.endswith(".elf"):
        say(f"{args.project}: --plant needs the project (its folder or .app: the plant reads its machines "
            "and pins), not a firmware ELF")
        return 2
    try:
        seed = 1 if args.seed is None else args.seed
        app, layout, sc = prepare(args.project, args.plant, params=args.params, seed=seed, fault=args.fault,
                                  board=args.board, fw_params=args.fw_params)
    except SetupError as e:
        for line in str(e).splitlines():
            sys.stderr.write(f"fsw sim: {line}\n" if line and not line.startswith((" ", "|")) else line + "\n")
        return 2
    try:
        out = args.out or default_output(app, f"{args.plant}-flight")
        os.makedirs(out, exist_ok=True)
        refuse_inputs(out, [args.params, args.fw_params])
    except (OutputError, BuildError) as e:
        say(str(e))
        return 2
    except OSError as e:
        from fswkit.outputs import not_a_folder

        say(f"cannot create the output folder {out}: {not_a_folder(out) or e.strerror or e}")
        return 2
    built = build(args.project, args.board)  # into the project's build folder; `out` is the flight's
    if isinstance(built, int):
        return built
    elf, board = built
    what = f"seed {sc.seed}" + (f", fault {sc.fault}" if sc.fault else "")
    say(f"{args.plant} plant at {sc.rate} Hz in lock-step with the {board.name}, {what}; up to {sc.max_s:g} s "
        "simulated")
    return flown(lambda: execute(sc, elf, board, layout, out), out)


def tape_run(args) -> int:
    """`fsw sim PROJECT --tape FLIGHT.csv [--perturb N --seed S]`: build,
    replay the tape open loop, write the files, print the events and checks
    (fswkit.plant.tape_replay)."""
    from fswkit.link.layout import LayoutError, from_app
    from fswkit.outputs import OutputError, write_text
    from fswkit.plant import tape_replay as tr
    from fswkit.plant.run import refuse_inputs
    from fswkit.sim.command import is_elf, say
    from fswkit.target.build import BuildError, default_output, load
    from fswkit.autocode.diagnostics import Diagnostics

    for opt, given in (("--duration", args.duration is not None), ("--fast", args.fast),
                       ("--analog", bool(args.analog)), ("--link", args.link is not None),
                       ("--plant", args.plant is not None), ("--fault", args.fault is not None),
                       ("--eeprom-file", args.eeprom_file is not None)):
        if given:
            say(f"{opt} does not go with --tape: the tape drives the run")
            return 2
    if args.seed is not None and args.perturb is None:
        say("--seed with --tape needs --perturb N (a plain replay has no randomness)")
        return 2
    if args.perturb is not None and not 1 <= args.perturb <= tr.MAX_PERTURB:
        say(f"--perturb {args.perturb}: from 1 to {tr.MAX_PERTURB:,} replays (a larger run is several, each with "
            "its own --seed)")
        return 2
    if is_elf(args.project) or args.project.endswith(".elf"):
        say(f"{args.project}: --tape needs the project (its folder or .app), not a firmware ELF")
        return 2
    diags = Diagnostics()
    try:
        app = load(args.project, diags, args.board)
    except BuildError as e:
        say(str(e))
        return 2
    if app is None:
        sys.stderr.write(diags.render() + "\n")
        return 2
    image = None
    if args.fw_params is not None:
        from fswkit.plant.run import SetupError, firmware_params

        try:
            app, image = firmware_params(app, args.fw_params)
        except SetupError as e:
            sys.stderr.write(f"fsw sim: {e}\n")
            return 2
    try:
        layout = from_app(app)
        cfg = tr.load_config(app, layout, args.params)
        cfg.eeprom = image
        tape, truth = tr.load_tape(args.tape, cfg)
    except (LayoutError, tr.ReplayError) as e:
        for line in str(e).splitlines():
            sys.stderr.write(f"fsw sim: {line}\n")
        return 2
    name = os.path.splitext(os.path.basename(args.tape))[0]
    try:
        out = args.out or default_output(app, f"tape-{name}")
        refuse_inputs(out, [args.tape, args.params, args.fw_params], extra=("perturb.csv", "perturb.txt"))
    except (OutputError, BuildError) as e:
        say(str(e))
        return 2
    built = folder_and_firmware(args.project, args.board, out)
    if isinstance(built, int):
        return built
    elf, board = built
    if args.perturb is not None:
        from fswkit import outputs

        seed = 1 if args.seed is None else args.seed
        say(f"{args.perturb} perturbed replays of {args.tape} ({tape.span:.0f} s of flight each), seed {seed}")
        t0 = time.monotonic()
        complete = True
        with outputs.stopped_by_signals():
            try:
                results = tr.robustness(tape, truth, cfg, elf, board, layout, args.perturb, seed)
            except tr.StoppedRuns as e:
                results, complete = e.results, False
        text, ok = tr.robustness_text(results, tape, args.perturb, seed, time.monotonic() - t0, complete)
        sys.stdout.write(text)
        sys.stdout.flush()
        try:
            write_text(os.path.join(out, "perturb.csv"), tr.robustness_csv(results), what="the runs' table")
            write_text(os.path.join(out, "perturb.txt"), text, what="the summary")
        except OutputError as e:
            say(str(e))
            return 1
        say(f"wrote {os.path.join(out, 'perturb.txt')}, {os.path.join(out, 'perturb.csv')}")
        if not complete:
            say(f"stopped after {len(results)} of {args.perturb} perturbed replays")
            return 128 + (outputs.stopped_by or 2)
        return 0 if ok else 1
    say(f"replaying {args.tape} ({tape.rows:,} rows, {tape.span:.1f} s) open loop on the {board.name}")
    return flown(lambda: tr.execute(tape, truth, cfg, app, elf, board, layout, out), out)
