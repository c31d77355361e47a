"""`fsw web PROJECT --port P`: the web ground station on a target's serial
port (fswkit.web; docs/ground.md)."""

from __future__ import annotations

import sys

from fswkit.cli.common import EXIT_CONFIG, EXIT_FAIL, EXIT_OK, port_or_only


def _parameters(project: str):
    """(the application's parameter table, its link's transmit buffer size)."""
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.params import app_parameters
    from fswkit.autocode.schema import link_plan
    from fswkit.target.build import load

    app = load(project, Diagnostics())
    return (app_parameters(app), link_plan(app).tx_cap) if app is not None else ((), 0)


def cmd_web(args) -> int:
    from fswkit.cli.ground import _link_baud, _link_layout
    from fswkit.link.port import PortError, open_port
    from fswkit.web.app import AssetsMissing, create_app, serve, uplot_dir
    from fswkit.web.source import LiveSource

    link = _link_layout(args.project, "web")
    if link is None:
        return EXIT_CONFIG
    layout, app_baud = link
    port_name = port_or_only(args.port, "web")
    if port_name is None:
        return EXIT_FAIL
    try:
        uplot_dir()
    except AssetsMissing as e:
        sys.stderr.write(f"fsw web: {e}\n")
        return EXIT_FAIL
    baud = _link_baud(args.baud, app_baud, "web")
    try:
        port = open_port(port_name, baud)
    except PortError as e:
        sys.stderr.write(f"fsw web: {e}\n")
        return EXIT_FAIL
    params, tx_cap = _parameters(args.project)
    app = create_app(LiveSource(layout, port, ignore_schema=args.ignore_schema, params=params, tx_cap=tx_cap,
                                baud=baud), title=f"fsw web {args.project}")

    def ready(url: str) -> None:
        sys.stdout.write(f"{url}\n")
        sys.stdout.flush()
        sys.stderr.write(f"fsw web: the ground station of {args.project} on {port_name} at {baud} baud: open {url} "
                         "(Ctrl-C ends it)\n")

    try:
        serve(app, host=args.host, port=args.http_port, on_ready=ready)
    except KeyboardInterrupt:
        pass
    except OSError as e:
        sys.stderr.write(f"fsw web: cannot serve on {args.host}:{args.http_port}: {e.strerror or e}\n")
        return EXIT_FAIL
    finally:
        port.close()
    return EXIT_OK
