"""`fsw sim`: builds a project, runs its firmware on the simulated board
(fswkit.sim.board), bridges UART0 to a pseudo-terminal or a plant."""

from __future__ import annotations

import os
import sys
import time

from fswkit.autocode.board import Board
from fswkit.autocode.diagnostics import read_head
from fswkit.sim.board import SimBoard, SimError, link_problem, sim_board

# ---- fsw sim ----------------------------------------------------------------------------

def _say(text: str) -> None:
    sys.stderr.write(f"fsw sim: {text}\n")
    sys.stderr.flush()


def _is_elf(path: str) -> bool:
    try:
        return read_head(path, 4) == b"\x7fELF"
    except OSError:
        return False


def _build(args) -> tuple[str, Board] | int:
    """Generates and builds the project for its (or --board's) board; the ELF
    and board, or an exit status after saying why."""
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.emit.app import GenError, emit_app
    from fswkit.target.build import (BuildError, build_lock, default_out, elf_size, explain_failure, load, make,
                              size_of, size_report, write_files)

    diags = Diagnostics()
    try:
        app = load(args.project, diags, args.board)
    except BuildError as e:
        _say(str(e))
        return 2
    if diags.items:
        sys.stderr.write(diags.render() + "\n")
    if app is None:
        return 2
    try:
        board = sim_board(app.board)
    except SimError as e:
        _say(str(e))
        return 2
    out = args.out or default_out(app)
    try:
        with build_lock(out, "sim"):  # one build of a folder at a time (fsw build, fsw flash, fsw sim)
            write_files(emit_app(app), os.path.join(out, "gen"))
            elf, proc = make(app, out)
            if proc.returncode != 0:
                too_big, message = explain_failure(app, out, proc)
                _say(message)
                return 1 if too_big else 3
            flash, ram = elf_size(elf)
            if flash > board.flash or ram > board.ram:
                _say(size_report(app, elf, size_of(app, flash, ram)))
                return 1
    except GenError as e:
        _say(str(e))
        return 1
    except BuildError as e:
        _say(str(e))
        return 1
    except OSError as e:
        _say(f"cannot write {e.filename or out}: {e.strerror or e}")
        return 1
    _say(f"built {elf} for {board.name} ({flash:,} B flash, {ram:,} B RAM)")
    return elf, board


def _analog_args(items: list[str], board: Board) -> dict[str, float] | str:
    """--analog PIN=VOLTS settings, or what is wrong with one."""
    out = {}
    for item in items:
        pin, sep, volts = item.partition("=")
        pin = pin.strip()
        if not sep:
            return f"--analog {item}: expected PIN=VOLTS, e.g. A0=3.2"
        if pin not in board.analog_pins:
            return f"--analog {item}: board `{board.name}` has no analog input `{pin}` " \
                   f"(it has {', '.join(board.analog_pins)})"
        try:
            v = float(volts)
        except ValueError:
            return f"--analog {item}: `{volts}` is not a number of volts"
        if not 0.0 <= v <= board.adc_vref:
            return f"--analog {item}: volts must be between 0 and {board.adc_vref:g}"
        out[pin] = v
    return out


def main(args) -> int:
    """`fsw sim PROJECT|FW.elf`: build, start with UART0 on a pty, print the
    pty's path on standard output, run until Ctrl-C or --duration."""
    if args.duration is not None and not 0 < args.duration < 1e9:
        _say("--duration must be a positive number of simulated seconds")
        return 2
    if args.link is not None and link_problem(args.link) is not None:
        _say(link_problem(args.link))
        return 2
    if _is_elf(args.project) or args.project.endswith(".elf"):
        if args.board is None:
            _say(f"{args.project}: a firmware ELF needs --board (the board it was built for, e.g. uno)")
            return 2
        try:
            board = sim_board(args.board)
        except SimError as e:
            _say(str(e))
            return 2
        elf = args.project
    else:
        built = _build(args)
        if isinstance(built, int):
            return built
        elf, board = built
    analog = _analog_args(args.analog or [], board)
    if isinstance(analog, str):
        _say(analog)
        return 2
    try:
        b = SimBoard(elf, board, uart="pty", analog=analog, link=args.link)
    except SimError as e:
        _say(str(e))
        return 1
    with b:
        sys.stdout.write(f"{b.port}\n")
        sys.stdout.flush()
        pace = "as fast as it can" if args.fast else "in real time"
        end = f"for {args.duration:g} simulated s" if args.duration else "until Ctrl-C"
        link = f" (and {args.link})" if args.link else ""
        _say(f"{board.name} ({b.mcu} at {b.f_cpu / 1e6:g} MHz) runs {pace} {end}; UART0 is {b.port}{link}")
        t0 = time.monotonic()
        try:
            r = b.go(until=args.duration, realtime=not args.fast)
        except SimError as e:
            _say(str(e))
            return 1
        wall = time.monotonic() - t0
        why = {"target": "duration reached", "interrupted": "stopped", "done": "the firmware stopped itself",
               "crashed": "the firmware crashed", "sim-limit": "simulated-time limit",
               "wall-limit": "wall-clock limit"}.get(r.stop, r.stop)
        _say(f"{why} at {r.time:.6f} s simulated ({r.cycle:,} cycles) after {wall:.2f} s")
        dropped = int(b.info().get("dropped", "0"))
        if dropped:
            _say(f"{dropped:,} UART bytes were sent while no program had the port open")
        try:
            ram = b.ram_usage()
            _say(f"stack high-water {ram.stack:,} B; RAM {ram.static:,} B static + {ram.stack:,} B stack = "
                 f"{ram.total:,} of {ram.ram:,} B")
        except SimError as e:
            _say(f"stack not measured: {e}")
    return 1 if r.stop == "crashed" else 0
