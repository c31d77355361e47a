"""What the `fsw` commands share: exit statuses, diagnostics on standard
error, loading a project's application, the serial port to use, writing an
output file."""

from __future__ import annotations

import os
import sys

from fswkit.autocode.diagnostics import Diagnostics

EXIT_OK, EXIT_FAIL, EXIT_CONFIG, EXIT_INTERNAL = 0, 1, 2, 3


def print_diags(diags: Diagnostics) -> None:
    if diags.items:
        sys.stderr.write(diags.render() + "\n")


def plural(n: int, word: str) -> str:
    return f"{n} {word}{'' if n == 1 else 's'}"


def load_app(project: str, board: str | None, command: str):
    """The project's application for `board` (None: the one it names),
    its diagnostics printed; None after a message when it cannot be loaded."""
    from fswkit.target.build import BuildError, load

    diags = Diagnostics()
    try:
        app = load(project, diags, board)
    except BuildError as e:
        sys.stderr.write(f"fsw {command}: {e}\n")
        return None
    print_diags(diags)
    return app


def source_or_empty(path: str):
    """A machine's text for a diagnostic after the fact (as
    fswkit.autocode.project.source_of reads it); an empty one when the file
    can no longer be read: the diagnostic still names the file and line."""
    from fswkit.autocode.diagnostics import Source
    from fswkit.autocode.project import source_of

    try:
        return source_of(path)
    except OSError:
        return Source.from_text(path, "")


def config_paths(app) -> list[str]:
    """The files of a project's configs: inputs of every command on it,
    which no output of the command may replace."""
    return [app.path, app.sv.path] + [m.path for m in app.machines] + [c.path for c in app.channels]


def port_or_only(port: str | None, command: str) -> str | None:
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


def write_output(text: str, out: str | None, command: str, inputs=(), own: bool = False, force: bool = False) -> int:
    """`text` to `out` (standard output for None or "-"). `own`: the text
    names `fsw COMMAND` in its head line (outputs.OWN_HEADS), which gets the
    text's digest (outputs.stamped); a file there that is not such an output
    as the command wrote it (one the user wrote or edited) is replaced only
    with `force`."""
    from fswkit.outputs import OutputError, check, only_its_own, stamped, write_text

    try:
        if own:
            text = stamped(text, command)
            if out not in (None, "-"):
                check(out, inputs)  # an input, a recording, a folder: said as such first
            only_its_own(out, command, force)
        write_text(out, text, inputs)
    except OutputError as e:
        sys.stderr.write(f"fsw {command}: {e}\n")
        return EXIT_FAIL
    return EXIT_OK


def flown(fly, out: str) -> int:
    """Runs a flight or a replay that writes its files into `out` as one
    set, then prints its report; the exit status: 0 when its checks
    passed, 1 when one failed or the run could not finish, 128 + N when
    stopped by signal N."""
    from fswkit.link.log import LogError
    from fswkit.outputs import Stopped
    from fswkit.plant.cosim import CosimError
    from fswkit.plant.run import INCOMPLETE
    from fswkit.sim.command import say

    incomplete = (f"; its partial files are in {os.path.join(out, INCOMPLETE)}, and the files in {out} are "
                  "still the last finished run's")
    try:
        done = fly()
    except Stopped as e:
        say(f"stopped by {e}" + incomplete)
        return 128 + e.signum
    except KeyboardInterrupt:
        say("interrupted" + incomplete)
        raise
    except (CosimError, LogError) as e:  # LogError: the log could not be written (a full disk)
        say(str(e) + incomplete)
        return 1
    except OSError as e:
        say(f"cannot write {e.filename or out}: {e.strerror or e}" + incomplete)
        return 1
    sys.stdout.write(done.report.text())
    sys.stdout.flush()
    say("wrote " + ", ".join(done.files[k] for k in ("log", "csv", "png", "record", "summary") if k in done.files))
    return 0 if done.report.passed else 1


def folder_and_firmware(project: str, board: str | None, out: str):
    """Creates the output folder `out` and builds the project's firmware for
    the simulated board: (elf, board), or the exit status after saying why."""
    from fswkit.sim.command import build, say

    try:
        os.makedirs(out, exist_ok=True)
    except OSError as e:
        from fswkit.outputs import not_a_folder

        say(f"cannot create the output folder {out}: {not_a_folder(out) or e.strerror or e}")
        return 2
    return build(project, board)


def open_link(args, layout, baud: int, say):
    """A target's link on `args.port` for a command that talks to it (`fsw
    param`, `fsw dump`): through the ground station when one holds the
    port, else the port opened exclusively; a hello asked for and its
    schema checked against `args.project` (unless `args.ignore_schema`).
    The link (its `session` decoded, its `close()` never raising); None,
    said through `say`, when it cannot be had (the link is closed again)."""
    from fswkit.ground.client import StationRefused, connect
    from fswkit.ground.monitor import schema_message, summary
    from fswkit.link.client import LinkTimeout
    from fswkit.link.port import PortError
    from fswkit.link.session import Session

    session = Session(layout, ignore_schema=args.ignore_schema)
    try:
        ground = connect(args.port, baud, session, f"fsw {args.command}")
    except (PortError, StationRefused, OSError) as e:
        say(str(e))
        return None
    why = None
    try:
        ground.handshake(timeout=3.0)
        if not session.hello["schema_ok"] and not args.ignore_schema:
            why = schema_message(session, args.project)
    except LinkTimeout as e:
        why = f"{e}: is the firmware running on {args.port}, at {baud} baud?\n  " + summary(session)
    if why is not None:
        say(why)
        ground.close()
        return None
    return ground


def talk_on_link(args, layout, baud: int, say, talk, refusals: tuple) -> int:
    """`talk(ground)` over the target's link (`open_link`): its exit status.
    A refusal (one of the exception classes `refusals`) or a port that goes
    away is said through `say` (exit 1); the link is closed whatever happens."""
    from fswkit.link.port import port_errors

    ground = open_link(args, layout, baud, say)
    if ground is None:
        return EXIT_FAIL
    try:
        return talk(ground)
    except refusals as e:
        say(str(e))
        return EXIT_FAIL
    except BrokenPipeError:  # standard output's reader went away (`| head`): main's to take, not the port's
        raise
    except port_errors() as e:
        say(f"{args.port}: the port went away ({e})")
        return EXIT_FAIL
    finally:
        ground.close()


def real_of(args, command: str):
    """The evaluation type `--real` and `--board` name (a board's own; the two
    must agree; f64 when neither is given), or None after a message."""
    from fswkit.autocode.board import BoardError, load_board
    from fswkit.autocode.numeric import REALS

    name = args.real
    if args.board is not None:
        try:
            board = load_board(args.board)
        except BoardError as e:
            sys.stderr.write(f"fsw {command}: {e}\n")
            return None
        if name is not None and name != board.real:
            sys.stderr.write(f"fsw {command}: --real {name} contradicts board `{board.name}`, "
                             f"whose evaluation type is {board.real}\n")
            return None
        name = board.real
    return REALS[name or "f64"]
