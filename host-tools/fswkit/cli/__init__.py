"""The `fsw` command line."""

from __future__ import annotations

import argparse
import os
import re
import sys

from fswkit import __version__
from fswkit.autocode.diagnostics import Diagnostics

EXIT_OK, EXIT_FAIL, EXIT_CONFIG, EXIT_INTERNAL = 0, 1, 2, 3
CONFIG_EXTS = (".sv", ".sm", ".ss", ".app")


def _print_diags(diags: Diagnostics) -> None:
    if diags.items:
        sys.stderr.write(diags.render() + "\n")


def _plural(n: int, word: str) -> str:
    return f"{n} {word}{'' if n == 1 else 's'}"


# ---- fsw check ----------------------------------------------------------------

def collect(paths: list[str], diags: Diagnostics) -> list[str] | None:
    files: list[str] = []
    for p in paths:
        if os.path.isdir(p):
            for root, dirs, names in os.walk(p):
                dirs[:] = sorted(d for d in dirs if not d.startswith("."))
                files += [os.path.normpath(os.path.join(root, n))
                          for n in sorted(names) if n.endswith(CONFIG_EXTS)]
        elif p.endswith(CONFIG_EXTS) or not os.path.exists(p):
            files.append(p)
        else:
            sys.stderr.write(f"fsw check: {p}: not a config file (expected {', '.join(CONFIG_EXTS)} or a folder)\n")
            return None
    return files


def cmd_check(args) -> int:
    from fswkit.autocode.project import load_machine, load_script, load_sv

    diags = Diagnostics()
    files = collect(args.paths, diags)
    if files is None:
        return EXIT_CONFIG
    if not files:
        sys.stderr.write("fsw check: no config files found\n")
        return EXIT_FAIL
    for f in files:
        if f.endswith(".sv"):
            load_sv(f, diags)
        elif f.endswith(".sm"):
            load_machine(f, diags, args.sv, warnings=True)
        elif f.endswith(".app"):
            from fswkit.autocode.app import load_app
            load_app(f, diags)
        else:
            load_script(f, diags, args.sm, args.sv)
    _print_diags(diags)
    errors, warnings = diags.error_count, diags.warning_count
    sys.stderr.write(f"fsw check: {_plural(len(files), 'file')}, {_plural(errors, 'error')}, "
                     f"{_plural(warnings, 'warning')}\n")
    if errors or (args.strict and warnings):
        return EXIT_FAIL
    return EXIT_OK


# ---- fsw test -------------------------------------------------------------------

def _scripts(paths: list[str]) -> list[str] | None:
    """The scripts named, a folder standing for every `.ss` in it."""
    out: list[str] = []
    for p in paths:
        if os.path.isdir(p):
            found = sorted(os.path.join(p, n) for n in os.listdir(p) if n.endswith(".ss"))
            if not found:
                sys.stderr.write(f"fsw test: {p}: no state scripts (.ss) in this folder\n")
                return None
            out += found
        else:
            out.append(p)
    return out


def cmd_test(args) -> int:
    from fswkit.autocode.numeric import REALS

    real_name = args.real
    if args.board is not None:
        from fswkit.autocode.board import BoardError, load_board
        try:
            board = load_board(args.board)
        except BoardError as e:
            sys.stderr.write(f"fsw test: {e}\n")
            return EXIT_CONFIG
        if real_name is not None and real_name != board.real:
            sys.stderr.write(f"fsw test: --real {real_name} contradicts board `{board.name}`, "
                             f"whose evaluation type is {board.real}\n")
            return EXIT_CONFIG
        real_name = board.real
    real = REALS[real_name or "f64"]
    if args.coverage and args.native:
        sys.stderr.write("fsw test: --coverage follows the interpreter's run: leave out --native\n")
        return EXIT_CONFIG
    scripts = _scripts(args.script)
    if scripts is None:
        return EXIT_CONFIG
    if args.trace and len(scripts) > 1:
        sys.stderr.write("fsw test: --trace writes one script's run: name one script\n")
        return EXIT_CONFIG
    codes = []
    coverage: dict[str, list] = {}  # machine path -> [machine, taken, visited]
    for path in scripts:
        if len(scripts) > 1:
            sys.stdout.write(f"== {path}\n")
            sys.stdout.flush()
        code, result = _test_one(path, args, real)
        codes.append(code)
        if result is not None and args.coverage:
            m = result[0]
            entry = coverage.setdefault(os.path.abspath(m.path), [m, set(), set()])
            entry[1] |= result[1].taken
            entry[2] |= result[1].visited
    incomplete = _report_coverage(coverage) if args.coverage else False
    if len(scripts) > 1:
        passed = codes.count(EXIT_OK)
        sys.stdout.write(f"{_plural(len(scripts), 'script')}: {passed} passed, {len(scripts) - passed} failed\n")
    if EXIT_CONFIG in codes:
        return EXIT_CONFIG
    if EXIT_INTERNAL in codes:
        return EXIT_INTERNAL
    return EXIT_FAIL if EXIT_FAIL in codes or incomplete else EXIT_OK


def _test_one(path: str, args, real):
    """Runs one script; (exit code, (machine, result) for coverage or None)."""
    from fswkit.autocode.project import load_script, source_of
    from fswkit.run.script import run

    diags = Diagnostics()
    script = load_script(path, diags, args.sm, args.sv, real=real)
    if script is None:
        _print_diags(diags)
        return EXIT_CONFIG, None
    _print_diags(diags)  # warnings only
    sources: dict[str, object] = {}

    def line_of(p: str, n: int) -> str:
        if p not in sources:
            sources[p] = source_of(p)
        return sources[p].line(n)

    trace = None
    if args.trace:  # written beside its path and renamed into place once whole
        from fswkit.outputs import OutputError, Replacement, check
        try:
            check(args.trace, [path, script.machine.path, script.machine.sv.path], what="trace")
            trace = Replacement(args.trace)
        except OutputError as e:
            sys.stderr.write(f"fsw test: {e}\n")
            return EXIT_FAIL, None
    ok = False
    try:
        if args.native:
            from fswkit.run import native
            try:
                code, report = native.run(script, real, line_of, trace_path=trace and trace.path)
            except native.NativeError as e:
                sys.stderr.write(f"fsw test: {e}\n")
                return EXIT_INTERNAL, None
            except OSError as e:
                sys.stderr.write(f"fsw test: {e.filename or ''}: {e.strerror or e}\n")
                return EXIT_FAIL, None
            ok = True
            sys.stdout.write(report)
            sys.stdout.flush()
            return (EXIT_OK if code == 0 else EXIT_FAIL), None
        try:
            result = run(script, real, trace_path=trace and trace.path, source_line=line_of, cover=args.coverage)
        except OSError as e:
            sys.stderr.write(f"fsw test: cannot write trace {args.trace}: {e.strerror or e}\n")
            return EXIT_FAIL, None
        ok = True
        sys.stdout.write(result.report())
        sys.stdout.flush()
        return (EXIT_OK if result.passed else EXIT_FAIL), (script.machine, result)
    finally:
        if trace is not None:
            trace.finish(ok)


def _report_coverage(coverage: dict) -> bool:
    """Prints, per machine, the states and transitions the scripts reached
    and each one they missed; True when something was missed."""
    from fswkit.autocode.check import gotos

    missed_any = False
    for key in sorted(coverage):
        m, taken, visited = coverage[key]
        name = os.path.basename(m.path)
        moves = []
        for st in m.states:
            for label in ("entry", "step", "exit"):
                for g in gotos(getattr(st, label)):
                    moves.append((st, g))
        hit = sum(1 for _, g in moves if (g.line, g.col) in taken)
        sys.stdout.write(f"coverage of {name}: {len(visited)}/{len(m.states)} states, "
                         f"{hit}/{len(moves)} transitions\n")
        for st in m.states:
            if st.index not in visited:
                missed_any = True
                sys.stdout.write(f"  {name}:{st.line}: state {st.name} never entered\n")
        for st, g in moves:
            if (g.line, g.col) not in taken:
                missed_any = True
                sys.stdout.write(f"  {name}:{g.line}:{g.col}: transition {st.name} -> "
                                 f"{m.states[g.state].name} never taken\n")
    return missed_any


# ---- fsw graph / fsw skeleton ---------------------------------------------------------

def _machine_or_exit(args):
    from fswkit.autocode.project import load_machine

    diags = Diagnostics()
    m = load_machine(args.machine, diags, args.sv)
    _print_diags(diags)
    return m


def _write(text: str, out: str | None, command: str, inputs=()) -> int:
    from fswkit.outputs import OutputError, write_text

    try:
        write_text(out, text, inputs)
    except OutputError as e:
        sys.stderr.write(f"fsw {command}: {e}\n")
        return EXIT_FAIL
    return EXIT_OK


def cmd_graph(args) -> int:
    from fswkit.autocode.emit.graph import to_dot, to_mermaid

    m = _machine_or_exit(args)
    if m is None:
        return EXIT_CONFIG
    return _write(to_mermaid(m) if args.format == "mermaid" else to_dot(m), args.output, "graph",
                  (args.machine, m.sv.path))  # the state vector's as found beside the machine too


def cmd_skeleton(args) -> int:
    from fswkit.new.script import skeleton

    m = _machine_or_exit(args)
    if m is None:
        return EXIT_CONFIG
    return _write(skeleton(m, delta_t=args.delta_t), args.output, "skeleton", (args.machine, m.sv.path))


# ---- fsw gen / fsw build ---------------------------------------------------------------

def _load_app(args, command: str):
    from fswkit.target.build import BuildError, load

    diags = Diagnostics()
    try:
        app = load(args.project, diags, args.board)
    except BuildError as e:
        sys.stderr.write(f"fsw {command}: {e}\n")
        return None
    _print_diags(diags)
    return app


def _generate(app, out: str, command: str):
    from fswkit.autocode.emit.app import GenError, emit_app
    from fswkit.target.build import write_files

    try:
        files = emit_app(app)
    except GenError as e:
        sys.stderr.write(f"fsw {command}: {e}\n")
        return None
    try:
        write_files(files, out)
    except OSError as e:
        sys.stderr.write(f"fsw {command}: cannot write {e.filename or out}: {e.strerror or e}\n")
        return None
    return files


def cmd_gen(args) -> int:
    import contextlib

    from fswkit.target.build import BuildError, build_lock, default_out

    app = _load_app(args, "gen")
    if app is None:
        return EXIT_CONFIG
    if args.sketch:
        from fswkit.new.sketch import export
        return export(app, args.sketch)
    out = args.out or os.path.join(default_out(app), "gen")
    try:
        # the default folder is the build's own: not rewritten while a build compiles it
        with build_lock(os.path.dirname(out), "gen") if not args.out else contextlib.nullcontext():
            files = _generate(app, out, "gen")
    except (BuildError, OSError) as e:
        sys.stderr.write(f"fsw gen: {e.strerror if isinstance(e, OSError) and e.strerror else e}\n")
        return EXIT_FAIL
    if files is None:
        return EXIT_FAIL
    sys.stderr.write(f"fsw gen: {len(files)} files in {out}\n")
    return EXIT_OK


def cmd_build(args) -> int:
    from fswkit.target.build import BuildError, build_lock, default_out

    app = _load_app(args, "build")
    if app is None:
        return EXIT_CONFIG
    out = args.out or default_out(app)
    try:
        with build_lock(out, "build"):
            return _build_locked(app, out)
    except BuildError as e:
        sys.stderr.write(f"fsw build: {e}\n")
        return EXIT_FAIL
    except OSError as e:
        sys.stderr.write(f"fsw build: cannot write {e.filename or out}: {e.strerror or e}\n")
        return EXIT_FAIL


def _build_locked(app, out: str) -> int:
    """`fsw build` once it holds its folder."""
    from fswkit.target.build import elf_size, explain_failure, make, size_of, size_report

    if _generate(app, os.path.join(out, "gen"), "build") is None:
        return EXIT_FAIL
    artifact, proc = make(app, out)
    if proc.returncode != 0:
        too_big, message = explain_failure(app, out, proc)
        sys.stderr.write(f"fsw build: {message}\n")
        return EXIT_FAIL if too_big else EXIT_INTERNAL
    b = app.board
    print(f"fsw build: {os.path.basename(app.path)} for {b.name} ({b.mcu})")
    if not b.is_avr:
        print(f"  {artifact}")
        return EXIT_OK
    flash, ram = elf_size(artifact)
    size = size_of(app, flash, ram)
    if not size.fits:
        sys.stderr.write(f"fsw build: {size_report(app, artifact, size)}\n")
        return EXIT_FAIL
    print(size.table())
    print(f"  {artifact}\n  {artifact[:-4]}.hex")
    return EXIT_OK


# ---- fsw sim ------------------------------------------------------------------------------

def cmd_sim(args) -> int:
    if args.plant is not None:
        from fswkit.plant.run import main as plant_main

        return plant_main(args)
    if args.params is not None or args.fault is not None or args.seed is not None:
        sys.stderr.write("fsw sim: --params, --seed and --fault need --plant rocket|tank\n")
        return EXIT_CONFIG
    from fswkit.sim.command import main as sim_main

    return sim_main(args)


# ---- fsw flash / fsw ports / fsw new ------------------------------------------------------

def _port_or_only(port: str | None, command: str) -> str | None:
    """The port named, else the only candidate (said on standard error);
    None after a message when there is none or several."""
    from fswkit.target.ports import PortError, default_port

    try:
        device, listing = default_port(port, command)
    except PortError as e:
        sys.stderr.write(f"fsw {command}: {e}\n")
        return None
    if port is None:
        sys.stderr.write(f"fsw {command}: using {listing.label() if listing else device}, "
                         "the only serial port found\n")
    return device


def cmd_flash(args) -> int:
    from fswkit.target.flash import main as flash_main

    return flash_main(args)


def cmd_ports(args) -> int:
    from fswkit.target.ports import PortError, format_table, list_ports

    try:
        ports = list_ports(include_all=args.all)
    except PortError as e:
        sys.stderr.write(f"fsw ports: {e}\n")
        return EXIT_FAIL
    if not ports:
        sys.stderr.write("fsw ports: no serial port found" + ("" if args.all else " (connect a board by USB; "
                         "--all lists built-in ports too)") + "\n")
        return EXIT_FAIL
    sys.stdout.write(format_table(ports))
    return EXIT_OK


def cmd_new(args) -> int:
    from fswkit.new.project import main as new_main

    return new_main(args)


# ---- the serial link: fsw monitor / cmd / log2csv / replay / plot ----------------------

def _link_layout(project: str, command: str, configs: list | None = None):
    """The link layout of a project's configs and the baud rate its firmware
    runs the link at (the application's `baud`, or the default it gets), or
    None after a message; the configs' paths are added to `configs`."""
    from fswkit.target.build import BuildError, load
    from fswkit.link.layout import from_app

    diags = Diagnostics()
    try:
        app = load(project, diags)
    except BuildError as e:
        sys.stderr.write(f"fsw {command}: {e}\n")
        return None
    _print_diags(diags)
    if app is None:
        return None
    if configs is not None:
        configs += [app.path, app.sv.path] + [m.path for m in app.machines] + [c.path for c in app.channels]
    return from_app(app), app.baud


def _link_baud(asked: int | None, app_baud: int, command: str) -> int:
    """The rate to open a project's port at: the application's, unless
    `--baud` asks for another (honoured, with a warning)."""
    if asked is None:
        return app_baud
    if asked != app_baud:
        sys.stderr.write(f"fsw {command}: warning: --baud {asked}: the application runs its link at "
                         f"{app_baud} baud\n")
    return asked


def _ground(command: str, fn, *a) -> int:
    from fswkit.link.layout import LayoutError
    from fswkit.link.log import LogError
    from fswkit.link.port import PortError
    from fswkit.ground.monitor import GroundError
    from fswkit.outputs import OutputError

    try:
        return fn(*a)
    except (GroundError, PortError, LogError, LayoutError, OutputError) as e:
        sys.stderr.write(f"fsw {command}: {e}\n")
        return EXIT_FAIL


def cmd_monitor(args) -> int:
    from fswkit.ground.monitor import monitor

    from fswkit.outputs import OutputError, check

    configs: list[str] = []
    link = _link_layout(args.project, "monitor", configs)
    if link is None:
        return EXIT_CONFIG
    layout, app_baud = link
    port = _port_or_only(args.port, "monitor")
    if port is None:
        return EXIT_FAIL
    if args.log is not None:  # --force replaces an old recording, never a config or the port itself
        try:
            check(args.log, configs + [port], force=True, what="log")
        except OutputError as e:
            sys.stderr.write(f"fsw monitor: {e}\n")
            return EXIT_FAIL
    baud = _link_baud(args.baud, app_baud, "monitor")
    return _ground("monitor", monitor, layout, args.project, port, baud, args.log, args.headless,
                   args.ignore_schema, args.duration, args.frames, args.force)


def cmd_cmd(args) -> int:
    from fswkit.ground.monitor import command

    link = _link_layout(args.project, "cmd")
    if link is None:
        return EXIT_CONFIG
    layout, app_baud = link
    baud = _link_baud(args.baud, app_baud, "cmd")
    return _ground("cmd", command, layout, args.project, args.port, baud, args.what, args.args,
                   args.ignore_schema)


def cmd_log2csv(args) -> int:
    from fswkit.ground.monitor import log2csv
    from fswkit.outputs import output

    def run() -> int:
        with output(args.output, [args.log], newline="", what="CSV") as f:
            return log2csv(args.log, f, args.ignore_schema)

    return _ground("log2csv", run)


def cmd_replay(args) -> int:
    from fswkit.ground.monitor import replay

    return _ground("replay", replay, args.log, args.headless, args.speed, args.ignore_schema)


def cmd_plot(args) -> int:
    from fswkit.ground.monitor import plot

    return _ground("plot", plot, args.log, args.element, args.output, args.ignore_schema)


def _replay_speed(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, found {text!r}")
    if value != 0 and not 1e-3 <= value <= 1e6:
        raise argparse.ArgumentTypeError(f"expected 0 (as fast as possible) or a speed from 0.001 to 1000000, "
                                         f"found {text}")
    return value


def _nonneg_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, found {text!r}")
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"expected a number >= 0, found {text}")
    return value


# ---- entry point -------------------------------------------------------------------

def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive whole number, found {text!r}")
    if value <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive whole number, found {value}")
    return value


def _int_upto(hi: int, what: str):
    """An argparse type: a positive whole number of at most `hi` (what its use can hold)."""
    def parse(text: str) -> int:
        value = _positive_int(text)
        if value > hi:
            raise argparse.ArgumentTypeError(f"expected {what} of at most {hi:,}, found {text}")
        return value
    return parse


_baud = _int_upto(10_000_000, "a serial speed")  # what a UART or a USB serial adapter makes
_delta_t = _int_upto(2**64 - 1, "a time step")  # the script's U64 `delta_t`


def _nonneg_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0, found {text!r}")
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0, found {value}")
    return value


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="fsw", description="fswkit: flight software from configs.")
    p.add_argument("--version", action="version", version=f"fsw {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    c = sub.add_parser("check", help="check configs (.sv .sm .ss) or folders of them")
    c.add_argument("paths", nargs="+", metavar="PATH")
    c.add_argument("--strict", action="store_true", help="warnings fail the check too")
    c.add_argument("--sv", help="the state vector config to check machines against")
    c.add_argument("--sm", help="the state machine config to check scripts against")
    c.set_defaults(func=cmd_check)

    t = sub.add_parser("test", help="run a state script against its machine")
    t.add_argument("script", metavar="SCRIPT.ss", nargs="+",
                   help="state scripts, or folders standing for every .ss in them")
    t.add_argument("--sm", help="the machine (default: the .sm beside the script)")
    t.add_argument("--sv", help="the state vector (default: the .sv beside the machine)")
    t.add_argument("--real", choices=("f64", "f32"), default=None,
                   help="evaluation type R: binary64 (hosts, default) or binary32 (AVR boards)")
    t.add_argument("--board", help="run with this board's evaluation type (e.g. uno: binary32)")
    t.add_argument("--native", action="store_true",
                   help="run the generated C++ compiled for this host instead of the interpreter")
    t.add_argument("--trace", metavar="FILE.csv", help="write every element after every step")
    t.add_argument("--coverage", action="store_true",
                   help="report the states and transitions the scripts never reached, and fail if any")
    t.set_defaults(func=cmd_test)

    g = sub.add_parser("graph", help="a machine as Graphviz DOT or Mermaid")
    g.add_argument("machine", metavar="MACHINE.sm")
    g.add_argument("--format", choices=("dot", "mermaid"), default="dot")
    g.add_argument("--sv", help="the state vector (default: the .sv beside the machine)")
    g.add_argument("-o", "--output", help="write here instead of standard output")
    g.set_defaults(func=cmd_graph)

    gn = sub.add_parser("gen", help="generate an application's C++ from its configs")
    gn.add_argument("project", metavar="PROJECT", help="a folder with one .app, or the .app file")
    gn.add_argument("--board", help="build for this board instead of the one the .app names")
    gn_out = gn.add_mutually_exclusive_group()
    gn_out.add_argument("--out", help="where to write (default PROJECT/build/BOARD/gen)")
    gn_out.add_argument("--sketch", metavar="DIR", help="write an Arduino sketch folder for arduino-cli instead")
    gn.set_defaults(func=cmd_gen)

    b = sub.add_parser("build", help="build an application's firmware (.elf/.hex, or a host executable)")
    b.add_argument("project", metavar="PROJECT", help="a folder with one .app, or the .app file")
    b.add_argument("--board", help="build for this board instead of the one the .app names")
    b.add_argument("--out", help="build folder (default PROJECT/build/BOARD)")
    b.set_defaults(func=cmd_build)

    sm = sub.add_parser("sim", help="build and run the firmware on a simulated board, UART0 on a pty")
    sm.add_argument("project", metavar="PROJECT", help="a folder with one .app, the .app file, or a firmware .elf")
    sm.add_argument("--board", help="simulate this board (uno, mega2560, ...) instead of the one the .app names")
    sm.add_argument("--duration", type=float, metavar="SECONDS", help="stop after this much simulated time")
    sm.add_argument("--fast", action="store_true", help="run as fast as the simulator can, not in real time")
    sm.add_argument("--analog", action="append", metavar="PIN=VOLTS", help="an analog input's voltage, e.g. A0=3.2")
    sm.add_argument("--link", metavar="PATH", help="also make PATH a symbolic link to the serial port")
    sm.add_argument("--out", help="build folder (default PROJECT/build/BOARD); with --plant, the folder the "
                    "flight's log, CSV, plot and summary go to (default PROJECT/build/BOARD/PLANT-flight)")
    sm.add_argument("--plant", choices=("rocket", "tank"),
                    help="fly the firmware in closed loop against this plant model (docs/sim.md)")
    sm.add_argument("--params", metavar="FILE.toml", help="with --plant: the plant's parameters "
                    "(default PROJECT/plant.toml)")
    sm.add_argument("--seed", type=_nonneg_int, metavar="N", help="with --plant: the sensor noise's seed (default 1)")
    sm.add_argument("--fault", choices=("stuck-baro", "pinned-accel", "pinned-baro"),
                    help="with --plant rocket: a sensor fault (stuck-baro: the barometer freezes at ignition; "
                    "pinned-accel, pinned-baro: reads 5 V from boot, the motor is not lit)")
    sm.set_defaults(func=cmd_sim)

    fl = sub.add_parser("flash", help="build the firmware and upload it to a board (avrdude or PlatformIO)")
    fl.add_argument("project", metavar="PROJECT", help="a folder with one .app, or the .app file")
    fl.add_argument("--port", help="the board's serial port (default: the only serial port connected)")
    fl.add_argument("--board", help="flash for this board instead of the one the .app names")
    fl.add_argument("--via", choices=("avrdude", "pio"), default="avrdude",
                    help="upload with avrdude (default) or with `pio run -t upload`")
    fl.add_argument("--out", help="build folder (default PROJECT/build/BOARD)")
    fl.add_argument("--force", action="store_true", help="flash even when the port's USB IDs say another board")
    fl.add_argument("-v", "--verbose", action="store_true", help="show avrdude's output as it runs")
    fl.set_defaults(func=cmd_flash)

    po = sub.add_parser("ports", help="list serial ports, with the board each one seems to be")
    po.add_argument("--all", action="store_true", help="also ports without USB IDs (built-in UARTs)")
    po.set_defaults(func=cmd_ports)

    nw = sub.add_parser("new", help="scaffold a new project that builds as it stands")
    nw.add_argument("name", metavar="NAME", help="the project's folder; its name names the files and machine")
    nw.add_argument("--board", default="uno", help="the board it runs on (default uno)")
    nw.set_defaults(func=cmd_new)

    s = sub.add_parser("skeleton", help="a state-script skeleton that visits every state")
    s.add_argument("machine", metavar="MACHINE.sm")
    s.add_argument("--sv", help="the state vector (default: the .sv beside the machine)")
    s.add_argument("--delta-t", type=_delta_t, default=10, help="time step of the script (default 10)")
    s.add_argument("-o", "--output", help="write here instead of standard output")
    s.set_defaults(func=cmd_skeleton)

    m = sub.add_parser("monitor", help="decode a target's telemetry live (docs/telemetry.md)")
    m.add_argument("project", metavar="PROJECT", help="the project the firmware was built from (folder or .app)")
    m.add_argument("--port", help="serial device (/dev/ttyACM0, a pty) or pyserial URL "
                   "(default: the only serial port connected)")
    m.add_argument("--baud", type=_baud, help="link speed (default: the application's `baud`)")
    m.add_argument("--log", metavar="FILE", help="record every byte of the link to FILE (a new file)")
    m.add_argument("--force", action="store_true", help="let --log replace an existing FILE")
    m.add_argument("--headless", action="store_true", help="print decoded frames as lines, no live view")
    m.add_argument("--ignore-schema", action="store_true", help="decode even when the schema hash differs")
    m.add_argument("--duration", type=_nonneg_float, metavar="S", help="stop after S seconds")
    m.add_argument("--frames", type=_positive_int, metavar="N", help="stop after N frames")
    m.set_defaults(func=cmd_monitor)

    cm = sub.add_parser("cmd", help="send a command over the uplink and wait for its acknowledgement")
    cm.add_argument("what", choices=("set", "mode", "ping", "hello", "snapshot"), metavar="COMMAND",
                    help="set ELEMENT VALUE | mode TASK disabled|safed|enabled | ping | hello | snapshot")
    cm.add_argument("args", nargs="*", metavar="ARG")
    cm.add_argument("--port", required=True, help="serial device or pyserial URL")
    cm.add_argument("-p", "--project", default=".", help="the project the firmware was built from (default .)")
    cm.add_argument("--baud", type=_baud, help="link speed (default: the application's `baud`)")
    cm.add_argument("--ignore-schema", action="store_true", help="send even when the schema hash differs")
    # `set x -3.4028235e38`, `-inf`, `-0x7f`: a value, not an unknown option (argparse
    # takes only `-5` and `-.5` for numbers); no option of `cmd` starts with a digit, `.`, inf or nan
    cm._negative_number_matcher = re.compile(r"^-(\d|\.\d|inf|nan)", re.IGNORECASE)
    cm.set_defaults(func=cmd_cmd)

    lc = sub.add_parser("log2csv", help="a link log as CSV: one row per sample")
    lc.add_argument("log", metavar="LOG")
    lc.add_argument("-o", "--output", metavar="FILE", help="write here instead of standard output")
    lc.add_argument("--ignore-schema", action="store_true")
    lc.set_defaults(func=cmd_log2csv)

    rp = sub.add_parser("replay", help="the monitor's view of a link log")
    rp.add_argument("log", metavar="LOG")
    rp.add_argument("--headless", action="store_true", help="print decoded frames as lines")
    rp.add_argument("--speed", type=_replay_speed, default=1.0,
                    help="1 = as recorded, 2 twice as fast (0.001 to 1000000), 0 = as fast as possible")
    rp.add_argument("--ignore-schema", action="store_true")
    rp.set_defaults(func=cmd_replay)

    pl = sub.add_parser("plot", help="time series of elements from a link log, state transitions marked")
    pl.add_argument("log", metavar="LOG")
    pl.add_argument("-e", "--element", nargs="+", required=True, metavar="ELEMENT")
    pl.add_argument("-o", "--output", required=True, metavar="OUT.png")
    pl.add_argument("--ignore-schema", action="store_true")
    pl.set_defaults(func=cmd_plot)
    return p


def _quiet_stdout() -> None:
    from fswkit.outputs import discard_stdout

    discard_stdout()


def _stdout_failed() -> bool:
    try:
        sys.stdout.flush()
    except OSError:
        return True
    except ValueError:  # closed
        return False
    return False


def _empty_option(p: argparse.ArgumentParser, args) -> str | None:
    """The long name of an option given as an empty string (a path, a port,
    a board), or None."""
    sub = next(a for a in p._actions if isinstance(a, argparse._SubParsersAction)).choices.get(args.command)
    for action in sub._actions if sub is not None else ():
        if action.option_strings and getattr(args, action.dest, None) == "":
            return max(action.option_strings, key=len)
    return None


def main(argv: list[str] | None = None) -> int:
    from fswkit import outputs
    from fswkit.outputs import Stream

    p = parser()
    args = p.parse_args(argv)
    empty = _empty_option(p, args)
    if empty is not None:  # `--trace ""` is no trace, `--out ""` not the default folder
        sys.stderr.write(f"fsw {args.command}: {empty}: an empty string names nothing: give a path or name, "
                         "or leave the option out\n")
        return EXIT_CONFIG
    # every print of every command: a failed write says it was standard output
    saved = sys.stdout
    out = sys.stdout = Stream(saved, "standard output")
    outputs.stopped_by = None
    try:
        # SIGTERM and SIGHUP stop a command as Ctrl-C does (its temporary files removed,
        # its outputs whole or as they were), with status 128 + the signal's number
        try:
            with outputs.stopped_by_signals():
                code = _main(args, out)
        except outputs.Stopped:  # the signal came as the command returned
            code = EXIT_FAIL
        return 128 + outputs.stopped_by if outputs.stopped_by else code
    finally:
        if sys.stdout is out:
            sys.stdout = saved


def _main(args, out) -> int:
    from fswkit.outputs import OutputError

    try:
        code = args.func(args)
        if out.failed:  # the command stopped at it and said so
            _quiet_stdout()
            return code or EXIT_FAIL
        sys.stdout.flush()  # a full or closed standard output fails here, not after exit
        return code
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:  # the reader went away (`fsw ... | head`): not a failure
        _quiet_stdout()
        return EXIT_OK
    except OutputError as e:
        sys.stderr.write(f"fsw {args.command}: {e}\n")
        _quiet_stdout()
        return EXIT_FAIL
    except OSError as e:  # an input or output the command could not use: its system error
        if out.failed or _stdout_failed():
            sys.stderr.write(f"fsw {args.command}: cannot write standard output: {e.strerror or e}\n")
            _quiet_stdout()
        else:
            where = f"{e.filename}: " if e.filename else ""
            sys.stderr.write(f"fsw {args.command}: {where}{e.strerror or e}\n")
        return EXIT_FAIL
    except RecursionError:
        sys.stderr.write("fsw: input nested too deeply to process\n")
        return EXIT_INTERNAL
    except Exception as e:  # a bug of the kit, never the user's input: no traceback
        if os.environ.get("FSW_DEBUG"):
            raise
        sys.stderr.write(f"fsw: internal error: {type(e).__name__}: {e}\n"
                         "  (this is a bug in fswkit; run with FSW_DEBUG=1 for details)\n")
        return EXIT_INTERNAL

