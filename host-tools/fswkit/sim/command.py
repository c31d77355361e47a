"""The steps of `fsw sim` in the simulator's room (the command itself is
fswkit.cli.sim): build a project for a simulated board with the build
service, tell a firmware ELF from a project, read `--analog` settings."""

from __future__ import annotations

import sys

from fswkit.autocode.board import Board
from fswkit.autocode.diagnostics import read_head
from fswkit.autocode.numtext import decimal, integer
from fswkit.sim.board import SimError, sim_board


def say(text: str) -> None:
    sys.stderr.write(f"fsw sim: {text}\n")
    sys.stderr.flush()


def is_elf(path: str) -> bool:
    try:
        return read_head(path, 4) == b"\x7fELF"
    except OSError:
        return False


def build(project: str, board: str | None = None, out: str | None = None,
          before=None) -> tuple[str, Board] | int:
    """Builds the project for its (or `board`'s) board into `out` (None:
    its default build folder) with the build service, as `fsw build` does,
    [budget] included; the ELF and board, or an exit status after saying
    why. `before(board)`: what is wrong with the command for the board,
    said (status 2) before anything is built; None when nothing is."""
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import BuildError, check_out_folder, default_out, firmware, load

    diags = Diagnostics()
    try:
        if out:
            check_out_folder(out)
        app = load(project, diags, board)
    except BuildError as e:
        say(str(e))
        return 2
    if diags.items:
        sys.stderr.write(diags.render() + "\n")
    if app is None:
        return 2
    try:
        if not out:
            check_out_folder(default_out(app), default=True)
    except BuildError as e:
        say(str(e))
        return 2
    try:
        sim = sim_board(app.board)
    except SimError as e:
        say(str(e))
        return 2
    problem = before(sim) if before is not None else None
    if problem is not None:
        say(problem)
        return 2
    try:  # one build of a folder at a time (fsw build, fsw flash, fsw sim)
        built = firmware(app, out or default_out(app), command="sim")
    except BuildError as e:
        say(str(e))
        return e.code
    if not built.fits:
        say(built.report)
        return 1
    say(f"built {built.elf} for {sim.name} ({built.size.flash:,} B flash, {built.size.ram:,} B RAM)")
    return built.elf, sim


def analog_args(items: list[str], board: Board) -> dict[str, float] | str:
    """--analog PIN=VOLTS settings by the board's analog input names, or
    what is wrong with one. PIN is an input's name (`A0`) or the pin number
    the board gives it (`14` on an Uno), as the I/O tables take it."""
    out = {}
    for item in items:
        pin, sep, volts = item.partition("=")
        pin = pin.strip()
        if not sep:
            return f"--analog {item}: expected PIN=VOLTS, e.g. A0=3.2"
        number = integer(pin)
        if number is not None:
            pin = next((n for n, at in board.analog_pins.items() if at == number), pin)
        if pin not in board.analog_pins:
            return f"--analog {item}: board `{board.name}` has no analog input `{pin}` " \
                   f"(it has {', '.join(f'{n} ({number})' for n, number in board.analog_pins.items())})"
        v = decimal(volts.strip())
        if v is None:
            return f"--analog {item}: `{volts}` is not a number of volts"
        if not 0.0 <= v <= board.adc_vref:
            return f"--analog {item}: volts must be between 0 and {board.adc_vref:g}"
        out[pin] = v
    return out
