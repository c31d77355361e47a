"""The application config (spec §7): ties a state vector, machines and I/O
tables to a board, orders the tasks of the executor, and names the
telemetry streams and the elements the ground may write.

`load_app` takes a .app file through the stages every config language goes
through: the lexer and the parser (appsyntax.py: a tree of rows with their
positions), the checker (appcheck.py, section by section; iotables.py for
the channel tables it names), then the model (model.py: `Application`,
`Task`, `Stream`, `Channel`) and the limits of the generated tables
(limits.py).

    [application]
    board uno
    rate  100                 # executor cycles per second
    [configs]
    state_vector tank.sv
    machine      tank.sm
    io           tank.aio
    [time]
    source clock              # clock | cycle
    unit   ms                 # ms | us
    [tasks]
    sense    inputs          rate=100
    control  machine tank    rate=100  mode=controlMode
    act      outputs         rate=100
    [telemetry]
    Sensors  rate=10
    [uplink]
    valveOpen
"""

from __future__ import annotations

from .appcheck import Parts, check_app, complete
from .appsyntax import parse_app
from .board import load_board
from .collect import fewer_collections
from .diagnostics import APP, Diagnostics, read_source
from .limits import check_limits
from .model import TASK_KINDS, TASK_MODES, Application, Channel, Stream, Task

__all__ = ["TASK_KINDS", "TASK_MODES", "Application", "Channel", "Stream", "Task", "application", "load_app"]


@fewer_collections()
def load_app(path: str, diags: Diagnostics, board_override: str | None = None,
             instead: dict[str, str] | None = None) -> Application | None:
    """The checked application with its state vector, machines and tables;
    None with every error in `diags`. `instead`: {machine name: a file to
    read that machine from} (appcheck.check_app)."""
    src = read_source(path, diags, APP)
    if src is None:
        return None
    before = diags.error_count
    tree = parse_app(src, diags)
    parts = check_app(tree, diags, board_override, load_board, instead)
    if parts is None or not complete(parts, src, diags, before):
        return None
    app = application(path, parts)
    return app if check_limits(app, src, diags, parts.sv_tok, parts.machine_toks) else None


def application(path: str, parts: Parts) -> Application:
    """The model of a checked, complete application."""
    return Application(path, parts.name, parts.board, parts.rate, parts.baud, parts.sv, tuple(parts.machines),
                       tuple(parts.channels), tuple(parts.tasks), parts.time_element, parts.time_source,
                       parts.time_unit, tuple(parts.streams), tuple(parts.writable), parts.reset_cause,
                       parts.budget.get("flash"), parts.budget.get("ram"), parts.log, tuple(parts.pyro or ()),
                       tuple(parts.sensors or ()), parts.reload)
