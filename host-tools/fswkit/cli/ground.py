"""The ground's commands over the serial link: `fsw monitor`, `fsw cmd`,
`fsw log2csv`, `fsw replay`, `fsw plot` (fswkit.ground.monitor and .logs, on the
link's layout of the project's configs), and `fsw archive list|export` on a
ground station's archive (fswkit.ground.archive)."""

from __future__ import annotations

import sys
from functools import partial

from fswkit.autocode.diagnostics import Diagnostics
from fswkit.cli.common import EXIT_CONFIG, EXIT_FAIL, config_paths, port_or_only, print_diags


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
    print_diags(diags)
    if app is None:
        return None
    if configs is not None:
        configs += config_paths(app)
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
    from fswkit.ground.archive import ArchiveError
    from fswkit.ground.monitor import GroundError
    from fswkit.outputs import OutputError
    from fswkit.usage import UsageError

    try:
        return fn(*a)
    except UsageError as e:  # a name or a value on the command line that names nothing: before any port or output
        sys.stderr.write(f"fsw {command}: {e}\n")
        return EXIT_CONFIG
    except (GroundError, PortError, LogError, LayoutError, OutputError, ArchiveError) as e:
        sys.stderr.write(f"fsw {command}: {e}\n")
        return EXIT_FAIL


def cmd_monitor(args) -> int:
    from fswkit.ground.monitor import monitor
    from fswkit.ground.view import spark_elements
    from fswkit.outputs import OutputError, check
    from fswkit.usage import UsageError

    if args.log == "-":  # `-` is standard output elsewhere; here that carries the view, and a log is binary
        sys.stderr.write("fsw monitor: --log -: a link log is written to a file, never to standard output: "
                         "name a file\n")
        return EXIT_CONFIG
    configs: list[str] = []
    link = _link_layout(args.project, "monitor", configs)
    if link is None:
        return EXIT_CONFIG
    layout, app_baud = link
    try:  # a name that is no element is a wrong command line, said before a port is looked for
        spark_elements(layout, args.spark)
    except UsageError as e:
        sys.stderr.write(f"fsw monitor: {e}\n")
        return EXIT_CONFIG
    port = port_or_only(args.port, "monitor")
    if port is None:
        return EXIT_FAIL
    if args.log is not None:  # --force replaces an old log, never a config, the port itself or an archive
        try:
            check(args.log, configs + [port], force=True, log=True, what="log")
        except OutputError as e:
            sys.stderr.write(f"fsw monitor: {e}\n")
            return EXIT_FAIL
    baud = _link_baud(args.baud, app_baud, "monitor")
    return _ground("monitor", partial(monitor, spark=tuple(args.spark)), layout, args.project, port, baud,
                   args.log, args.headless, args.ignore_schema, args.duration, args.frames, args.force)


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
    from fswkit.ground.logs import log2csv
    from fswkit.outputs import output

    def run() -> int:
        with output(args.output, [args.log], newline="", force=args.force, ask=True, what="CSV") as f:
            return log2csv(args.log, f, args.ignore_schema, args.session)

    return _ground("log2csv", run)


def cmd_replay(args) -> int:
    from fswkit.ground.logs import replay

    return _ground("replay", partial(replay, spark=tuple(args.spark)), args.log, args.headless, args.speed,
                   args.ignore_schema, args.session)


def cmd_plot(args) -> int:
    from fswkit.ground.logs import plot

    return _ground("plot", partial(plot, force=args.force), args.log, args.element, args.output, args.ignore_schema,
                   args.session)


def cmd_archive_list(args) -> int:
    from fswkit.ground.archive import sessions, sessions_text

    def run() -> int:
        rows = sessions(args.archive)
        if not rows:
            sys.stderr.write(f"fsw archive list: {args.archive}: no sessions yet\n")
            return 0
        sys.stdout.write(sessions_text(rows))
        return 0

    return _ground("archive list", run)


def cmd_archive_export(args) -> int:
    from fswkit.ground.logs import export

    def run() -> int:
        rows, session = export(args.archive, args.output, session=args.session, t_from=args.t_from,
                                t_to=args.t_to, force=args.force, ignore_schema=args.ignore_schema)
        sys.stderr.write(f"fsw archive export: {args.output}: {rows} rows of session {session}\n")
        return 0

    return _ground("archive export", run)
