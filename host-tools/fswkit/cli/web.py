"""`fsw ground PROJECT --port P` (and its older name, `fsw web`): the
ground station on a target's serial port: one process owns the port,
archives the session, serves the local clients and the web page
(fswkit.ground.station, fswkit.web; docs/ground.md)."""

from __future__ import annotations

import os
import signal
import sys
import threading

from fswkit.cli.common import EXIT_CONFIG, EXIT_FAIL, EXIT_OK, port_or_only

ARCHIVE = "ground-archive.sqlite"  # in the project's folder, unless --archive names another


def _parameters(project: str):
    """(the application's parameter table, its link's transmit buffer size,
    the name of its [reload] machine or None)."""
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.params import app_parameters
    from fswkit.autocode.schema import link_plan
    from fswkit.target.build import load

    app = load(project, Diagnostics())
    if app is None:
        return (), 0, None
    reload = app.machines[app.reload.machine].name if getattr(app, "reload", None) is not None else None
    return app_parameters(app), link_plan(app).tx_cap, reload


def archive_path(args) -> str | None:
    if args.no_archive:
        return None
    if args.archive:
        return args.archive
    base = args.project if os.path.isdir(args.project) else os.path.dirname(os.path.abspath(args.project))
    return os.path.join(base, ARCHIVE)


def _reason(e: OSError) -> str:
    """The system's reason for a socket that could not be served on, in its
    own words (socket.create_server adds its bind's address as a tuple)."""
    if isinstance(e.errno, int) and e.errno > 0:  # a name that does not resolve has a negative one (EAI_*)
        return os.strerror(e.errno)
    return e.strerror or str(e)


def cmd_ground(args) -> int:
    from fswkit.cli.ground import _link_layout
    from fswkit.web.app import AssetsMissing, listen, uplot_dir

    name = args.command
    link = _link_layout(args.project, name)
    if link is None:
        return EXIT_CONFIG
    layout, app_baud = link
    port_name = port_or_only(args.port, name)
    if port_name is None:
        return EXIT_FAIL
    sock = None
    if not args.no_web:
        try:
            uplot_dir()
            sock = listen(args.host, args.http_port)  # before the port and the archive are touched
        except AssetsMissing as e:
            sys.stderr.write(f"fsw {name}: {e}\n")
            return EXIT_FAIL
        except OSError as e:
            sys.stderr.write(f"fsw {name}: cannot serve on {args.host}:{args.http_port}: {_reason(e)}\n")
            return EXIT_FAIL
    try:
        return _station(args, name, layout, app_baud, port_name, sock)
    finally:
        if sock is not None:
            sock.close()


def _station(args, name: str, layout, app_baud: int, port_name: str, sock) -> int:
    """The station on `port_name` until the user ends it, serving the web
    page on `sock` (None: no web page)."""
    from fswkit.cli.ground import _link_baud
    from fswkit.ground.archive import Archive, ArchiveError
    from fswkit.ground.station import Station
    from fswkit.link.port import PortError
    from fswkit.web.app import create_app, exposure, serve
    from fswkit.web.source import LiveSource

    baud = _link_baud(args.baud, app_baud, name)
    path = archive_path(args)
    try:
        archive = Archive(path) if path else None
    except ArchiveError as e:
        sys.stderr.write(f"fsw {name}: {e}\n")
        return EXIT_FAIL
    station = Station(layout, args.project, port_name, baud, archive=archive, ignore_schema=args.ignore_schema)
    station.notes(lambda text, up: sys.stderr.write(f"fsw {name}: {port_name}: {text}\n"))
    try:
        station.start()
    except (PortError, ArchiveError) as e:  # ArchiveError: the session could not begin (a lock, a full disk)
        sys.stderr.write(f"fsw {name}: {e}\n")
        if archive is not None:
            archive.abandon()
        return EXIT_FAIL
    said = f"the ground station of {args.project} on {port_name} at {baud} baud" + (
        f", archiving into {path}" if path else "")
    try:
        if sock is None:
            sys.stderr.write(f"fsw {name}: {said}; `fsw monitor`, `fsw cmd`, `fsw param` and `fsw dump` on "
                             f"{port_name} go through it (Ctrl-C ends it)\n")
            stop = threading.Event()
            for sig in (signal.SIGTERM, signal.SIGHUP):
                signal.signal(sig, lambda *_: stop.set())
            while not stop.wait(0.5):
                pass
            return EXIT_OK
        params, tx_cap, reload_machine = _parameters(args.project)
        app = create_app(LiveSource(station, params=params, tx_cap=tx_cap, baud=baud, reload_machine=reload_machine),
                         title=f"fsw ground {args.project}", host=args.host)

        def ready(url: str) -> None:
            sys.stdout.write(f"{url}\n")
            sys.stdout.flush()
            sys.stderr.write(f"fsw {name}: {said}: open {url} (Ctrl-C ends it)\n")
            warning = exposure(args.host, sock.getsockname()[1])
            if warning:
                sys.stderr.write(f"fsw {name}: warning: {warning}\n")

        try:
            serve(app, host=args.host, port=args.http_port, on_ready=ready, sock=sock)
        except OSError as e:
            sys.stderr.write(f"fsw {name}: cannot serve on {args.host}:{args.http_port}: {_reason(e)}\n")
            return EXIT_FAIL
        return EXIT_OK
    except KeyboardInterrupt:
        return EXIT_OK
    finally:
        station.stop()


cmd_web = cmd_ground
