"""The application config's checker (spec §7): a parsed .app
(appsyntax.AppFile) resolved against its board, its state vector, its
machines and channel tables, section by section. Every problem is reported
where it is written; what passes becomes `Parts`, which app.py assembles
into the model's `Application`.

The sections are checked in the order each needs the others: [application]
(the board, the rate), [configs] (the files it names, read and checked),
[time], [tasks], [telemetry], [uplink] (with the reset cause and the one
writer of each element), [budget], [log] (logcheck.py), [pyro]
(pyrocheck.py: the channels, and the proof that no machine fires one
unarmed)."""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, replace
from fractions import Fraction

from . import model as M
from .appsyntax import AppFile, ConfigFile, Options, Problem, Setting, StreamRow, TaskRow, WritableRow, parse_table
from .board import Board, BoardError
from .buses import SS_WHY, spi_ss
from .check import assignments, check_literals, check_sm, check_sv, machine_exprs
from .cnames import machine_clashes, machine_ident
from .diagnostics import APP, SM, Diagnostics, Source, read_source
from .iotables import check_channels
from .lexer import ID, NUM, Tok
from .logcheck import check_log
from .sensors import SensorState, check_sensor_table, sensor_name
from .limits import U8_COUNT, hz
from .model import TASK_KINDS, TASK_MODES, Task
from .numeric import REALS, exact_literal
from .parser import parse_sm, parse_sv, show
from .types import U8

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")  # a name, as the lexer reads one
SETTINGS = ("name", "board", "rate", "baud", "reset_cause")
TASK_SETTINGS = ("rate", "mode", "start", "overruns", "worst_us")
TASK_STATS = (("overruns", "U16"), ("worst_us", "U32"))  # executor counters a task may keep, and their types


@dataclass
class Parts:
    """What the checker resolved: the model's pieces, and the [configs]
    tokens the limits are reported at (limits.check_limits)."""
    name: str
    board: Board | None
    rate: int
    baud: int
    sv: M.StateVector
    machines: list[M.Machine]
    channels: list[M.Channel]
    time_source: str
    time_unit: str
    time_element: M.Element | None
    tasks: list[Task]
    streams: list[M.Stream]
    writable: list[M.Element]
    reset_cause: M.Element | None
    budget: dict[str, int]
    sv_tok: Tok
    machine_toks: dict[str, Tok]  # by the machine's file name, without its extension
    log: M.Log | None = None
    pyro: list[M.PyroChannel] | None = None
    sensors: list[M.Sensor] | None = None  # `.sns` tables' parts (sensors.py)
    reload: M.Reload | None = None  # [reload] (reloadcheck.py)


class Report:
    """Reports about one .app file."""

    def __init__(self, src: Source, diags: Diagnostics):
        self.src, self.diags = src, diags

    def err(self, tok: Tok, msg: str) -> None:
        self.diags.error(self.src, APP, tok.line, tok.col, msg)

    def at(self, line: int, col: int, msg: str) -> None:
        self.diags.error(self.src, APP, line, col, msg)

    def warn(self, tok: Tok, msg: str) -> None:
        self.diags.warning(self.src, APP, tok.line, tok.col, msg)


def check_app(f: AppFile, diags: Diagnostics, board_override: str | None, load_board,
              instead: dict[str, str] | None = None) -> Parts | None:
    """The parts of the application in `f`; None when it has no state vector
    to check the rest against. `load_board(name)` gives a board or raises
    BoardError. `instead`: {machine name: a file to read that machine from}
    (the application with an uploaded machine in place of its generated
    one, `fsw machine upload`)."""
    r = Report(f.src, diags)
    settings = _settings(f.application, r)
    name = settings["name"].text if "name" in settings else os.path.splitext(os.path.basename(f.src.path))[0]
    board_tok = settings.get("board") if board_override is None else None
    board = _board(board_override or (settings["board"].text if "board" in settings else None), board_tok,
                   load_board, r)
    rate = _rate(settings["rate"], r) if "rate" in settings else 100
    baud = _baud(settings.get("baud"), board, board_tok, r)

    sv_file, machine_files, io_files = _configs(f.configs, r)
    if sv_file is None:
        r.at(1, 1, "missing `state_vector` in [configs]")
        return None
    sv_src = read_source(sv_file.path, diags, APP)
    if sv_src is None:
        return None
    sv = check_sv(parse_sv(sv_src, diags), sv_src, diags)
    machines, machine_srcs = _machines(machine_files, sv, board, r, instead or {})
    _parameters(machines, machine_files, board, r)
    channels, sensors, refused_outputs = _channels(io_files, sv, board, r) if board is not None else ([], [], set())

    time_source, time_unit = _time(f.time, r)
    time_element = _time_element(machines, sv, r)
    if time_source == "cycle" and time_unit == "ms" and 1000 % rate != 0:
        r.at(1, 1, f"`source cycle` with `unit ms` needs a rate that divides 1000 "
                   f"(one cycle must be a whole number of ms); rate is {rate}")

    tasks, task_opts = _tasks(f.tasks, sv, rate, machines, machine_files, r)
    # a task row refused for its own reason is no missing task, and a row of an unknown kind may be the one
    unknown = any(row.kind is None or row.kind.text not in TASK_KINDS for row in f.tasks)
    has = lambda kind: unknown or any(row.kind.text == kind for row in f.tasks)  # noqa: E731
    if not has("uplink"):
        _parameters_unreachable(machines, machine_files, r)
    if sensors and not has("inputs"):
        tok = next(c.file for c in io_files if c.path.endswith(".sns"))
        r.err(tok, "the sensor parts are read by the `inputs` task: add one to [tasks] (e.g. `sense inputs rate=100`)")
    pyro_names = {row.element.text for row in f.pyro}
    _channel_tasks(channels, io_files, has, pyro_names, r)
    _clock_steps(tasks, board, time_source, time_unit, r)
    streams = _telemetry(f.telemetry, sv, tasks, r)
    writable = _uplink(f.uplink, sv, tasks, machines, channels, settings.get("reset_cause"), r, sensors)
    reset_cause = _reset_cause(settings.get("reset_cause"), sv, r)
    _one_writer(r, channels, tasks, task_opts, settings.get("reset_cause"), reset_cause, machines, machine_srcs,
                pyro_names, sensors)
    budget = _budget(f.budget, board, r)
    log = check_log(f.log, sv, tasks, machines, board, r, channels=channels, sensors=sensors,
                    written="log" in f.sections)
    pyro, reload = [], None
    if f.pyro:  # the proofs' module is imported for an application that has pyro channels only
        from .pyrocheck import check_pyro
        pyro = check_pyro(f.pyro, sv, tasks, machines, machine_srcs, channels, f.uplink, r, f.tasks, board,
                          refused_outputs)
    if f.reload:
        from .reloadcheck import check_reload
        reload = check_reload(f.reload, tasks, machines, board, log, r)
    return Parts(name, board, rate, baud, sv, machines, channels, time_source, time_unit, time_element, tasks,
                 streams, writable, reset_cause, budget, sv_file.file,
                 {os.path.splitext(os.path.basename(c.path))[0]: c.file for c in machine_files}, log, pyro, sensors,
                 reload)


def complete(parts: Parts, src: Source, diags: Diagnostics, before: int) -> bool:
    """True when the checked parts make an application: no error since
    `before` (the error count when the file was read), a board and a time
    element. An application without a machine, and no other error, says so."""
    if diags.error_count != before or parts.board is None or parts.time_element is None:
        if parts.time_element is None and not parts.machines and diags.error_count == before:
            diags.error(src, APP, 1, 1, "an application needs at least one `machine` in [configs]")
        return False
    return True


def positive(tok: Tok, r: Report, what: str) -> Fraction | None:
    """The exact value of a positive number of at most 10^9; None, reported,
    when `tok` is none."""
    q = exact_literal(tok.text) if tok.kind == NUM else None
    if q is not None and 0 < q <= 10**9:
        return q
    text = tok.text if len(tok.text) <= 40 else tok.text[:37] + "..."
    big = q > 10**9 if q is not None else tok.kind == NUM and float(tok.text) > 1  # None: beyond 10^±4000
    if q is None and tok.kind == NUM and not big:  # positive, but too long or too small to take exactly
        r.err(tok, f"{what} is beyond the numbers the tools take (at most 4,000 "
                   f"significant digits, from 1e-4000 to 1e4000), found `{text}`")
    else:
        limit = " no greater than 1,000,000,000" if big else ""
        r.err(tok, f"{what} must be a positive number{limit}, found `{text}`")
    return None


def options(opts: Options, r: Report) -> dict[str, tuple[Tok, Tok]]:
    """The `key=value` options of a row: {key: (key token, value token)}, a
    key given twice reported (its last value kept), then what ended them."""
    out: dict[str, tuple[Tok, Tok]] = {}
    for o in opts.items:
        if o.key.text in out:
            r.err(o.key, f"`{o.key.text}=` given twice")
        out[o.key.text] = (o.key, o.value)
    if opts.stray is not None:
        r.err(opts.stray.tok, opts.stray.message)
    return out


# ---- [application] --------------------------------------------------------------

def _settings(rows: tuple[Setting, ...], r: Report) -> dict[str, Tok]:
    """{setting: its value token} of the settings that have one value."""
    out: dict[str, Tok] = {}
    for s in rows:
        if s.key.text not in SETTINGS:
            r.err(s.key, f"unknown setting `{s.key.text}`: expected `name`, `board`, `rate`, `baud` "
                         "or `reset_cause`")
        elif len(s.values) != 1:
            r.err(s.values[1] if len(s.values) > 1 else s.key, f"`{s.key.text}` takes one value")
        else:
            out[s.key.text] = s.values[0]
    return out


def _board(name: str | None, tok: Tok | None, load_board, r: Report) -> Board | None:
    """The named board; a board that is not known is reported at `tok` (at
    1:1 when the name comes from the command line)."""
    if name is None:
        r.at(1, 1, "missing `board` in [application]")
        return None
    try:
        return load_board(name)
    except BoardError as e:
        line, col = (tok.line, tok.col) if tok is not None else (1, 1)
        r.at(line, col, str(e))
        return None


def _rate(tok: Tok, r: Report) -> int:
    q = positive(tok, r, "`rate`")
    if q is None:
        return 100
    if q.denominator != 1 or 1000000 % q != 0:
        r.err(tok, "`rate` must be a whole number of cycles per second that divides "
                   "1000000 (a whole number of microseconds per cycle)")
    elif q > 100000:
        r.err(tok, f"`rate` is at most 100000 cycles per second (10 us a cycle), found {tok.text}")
    else:
        return int(q)
    return 100


def _baud(tok: Tok | None, board: Board | None, board_tok: Tok | None, r: Report) -> int:
    """The link's baud rate (115200 unless set), which the board's UART must
    make; a default it cannot make is reported at the board's line."""
    if tok is None:
        problem = baud_problem(board, 115200) if board is not None else None
        if problem is not None:
            line, col = (board_tok.line, board_tok.col) if board_tok is not None else (1, 1)
            r.at(line, col, f"{problem}; `baud` is not set, so it is the default: set `baud` in [application]")
        return 115200
    q = positive(tok, r, "`baud`")
    if q is None:
        return 115200
    if q.denominator != 1:
        near = round(q)
        made = uart_rate(board, near) if board is not None and near > 0 else None
        r.err(tok, f"`baud` must be a whole number of bits per second, found `{tok.text}`"
                   + (f" (for {near} the {board.name}'s UART makes {float(made):,.0f} baud, {_percent(made, near)})"
                      if made is not None else ""))
        return 115200
    problem = baud_problem(board, int(q)) if board is not None else None
    if problem is not None:
        r.err(tok, problem)
    return int(q)


# ---- [configs] ------------------------------------------------------------------

def _configs(rows: tuple[ConfigFile, ...], r: Report):
    """(the state vector's entry or None, the machines', the I/O tables')."""
    sv_file = None
    machine_files, io_files = [], []
    for c in rows:
        if c.kind.text not in ("state_vector", "machine", "io"):
            r.err(c.kind, f"unknown config kind `{c.kind.text}`: expected `state_vector`, `machine` or `io`")
        elif c.file is None:
            r.err(c.kind, f"`{c.kind.text}` takes a file name")
        elif c.kind.text == "state_vector":
            if sv_file is not None:
                r.err(c.kind, "only one `state_vector` per application")
            sv_file = c
        else:
            (machine_files if c.kind.text == "machine" else io_files).append(c)
    return sv_file, machine_files, io_files


def _machines(files: list[ConfigFile], sv: M.StateVector, board: Board | None, r: Report,
              instead: dict[str, str]):
    """(the machines, {machine name: its source}) of the `machine` files
    that read, check and have names the generated code can take; a machine
    named in `instead` is read from that file, under its own name."""
    machines: list[M.Machine] = []
    srcs: dict[str, Source] = {}  # where a machine's writes are reported
    for c in files:
        name = os.path.splitext(os.path.basename(c.path))[0]
        msrc = read_source(instead.get(name, c.path), r.diags, APP)
        if msrc is None:
            continue
        m = check_sm(parse_sm(msrc, r.diags), msrc, sv, r.diags)
        if m is None:
            continue
        if name in instead:
            m = replace(m, name=name)
        if board is not None:  # an error, and the machine still known to the rest of the file
            check_literals(machine_exprs(m), REALS[board.real], msrc, r.diags, SM, f"the {board.name}'s")
        problem = _machine_name_problem(m, c, machines)
        if problem is not None:
            r.err(c.file, problem)
            continue
        srcs[m.name] = msrc
        machines.append(m)
    return machines, srcs


def _parameters(machines: list[M.Machine], files: list[ConfigFile], board: Board | None, r: Report) -> None:
    """The machines' parameters as one table (docs/parameters.md): names
    unique across the application (the ground addresses them by name), at
    most 255, and two banks that fit the board's EEPROM."""
    from .params import HEADER, MAX_PARAMS

    by_file = {os.path.splitext(os.path.basename(c.path))[0]: c.file for c in files}
    seen: dict[str, str] = {}
    count = size = 0
    last = None  # the `machine` line of the last machine with parameters
    for m in machines:
        tok = by_file.get(m.name)
        for v in m.vars:
            if v.param is None:
                continue
            last = tok
            if v.name in seen:
                r.err(tok, f"parameter `{v.name}` of machine `{m.name}` has the name of a parameter of machine "
                           f"`{seen[v.name]}`: the ground addresses parameters by name, rename one")
            seen.setdefault(v.name, m.name)
            count += 1
            size += v.type.size
    if count > MAX_PARAMS:
        r.err(last, f"the application has {count} parameters: at most {MAX_PARAMS}")
    if count and board is not None and 2 * (HEADER + size) > board.eeprom:
        r.err(last, f"the parameters' two EEPROM banks take {2 * (HEADER + size):,} B (2 x ({HEADER} + {size})) "
                    f"but the {board.name} has {board.eeprom:,} B of EEPROM")


def _parameters_unreachable(machines: list[M.Machine], files: list[ConfigFile], r: Report) -> None:
    """A warning at the first machine that declares parameters, when no
    `uplink` task receives the parameter commands."""
    by_file = {os.path.splitext(os.path.basename(c.path))[0]: c.file for c in files}
    m = next((m for m in machines if any(v.param is not None for v in m.vars)), None)
    if m is not None and by_file.get(m.name) is not None:
        r.warn(by_file[m.name], "parameters without an `uplink` task in [tasks]: the ground can neither read nor "
                                "change them; the firmware boots with what an earlier firmware of the same parameter "
                                "table saved in the EEPROM, else the defaults")


def _machine_name_problem(m: M.Machine, c: ConfigFile, machines: list[M.Machine]) -> str | None:
    if not _NAME.fullmatch(m.name):
        return (f"the machine in `{os.path.basename(c.path)}` is named `{m.name}` after its file, and "
                "[tasks] can only name a machine whose name is letters, digits and `_`, not starting "
                "with a digit: rename the file")
    if any(x.name == m.name for x in machines):
        return f"two machines are named `{m.name}`"
    clash = next((machines[i].name for i, j in machine_clashes([x.name for x in machines] + [m.name])
                  if j == len(machines)), None)
    if clash is not None:
        return (f"machines `{clash}` and `{m.name}` would generate the same C++ files "
                f"(`{machine_ident(m.name)}.gen.h`; file names that differ only in case are one file "
                "on some file systems): rename one")
    return None


def _channels(files: list[ConfigFile], sv: M.StateVector, board: Board,
              r: Report) -> tuple[list[M.Channel], list[M.Sensor], set[str]]:
    """The channels of the `.aio`/`.dio` tables and the parts of the `.sns`
    tables, in [configs] order: a pin or an input element is taken once
    across all of them; and the elements of the digital `o` rows refused
    (reported at the row: a pyro channel says nothing more of them)."""
    channels: list[M.Channel] = []
    sensors: list[M.Sensor] = []
    refused_outputs: set[str] = set()
    used_pins: dict = {}
    used_inputs: dict = {}
    state = SensorState()
    listed: dict[str, int] = {}  # a table's real path -> the line of its `io`
    for c in files:
        if not c.path.endswith((".aio", ".dio", ".sns")):
            r.err(c.file, "an I/O table is a `.aio` (analog), `.dio` (digital) or `.sns` (sensor parts) file")
            continue
        real = os.path.realpath(c.path)
        if real in listed:  # its rows would all clash with themselves
            r.err(c.file, f"`{os.path.basename(c.path)}` is already listed on line {listed[real]}: an I/O table "
                          "is listed once")
            continue
        listed[real] = c.file.line
        isrc = read_source(c.path, r.diags, APP)
        if isrc is None:
            continue
        if c.path.endswith(".sns"):
            sensors += check_sensor_table(isrc, sv, board, r.diags, channels, used_pins, used_inputs, state)
        else:
            refused = {}
            if state.spi is not None:  # an earlier table's SPI part took SS
                refused[spi_ss(board)] = (f"it is {SS_WHY} (the SPI part at {os.path.basename(state.spi[0])}:"
                                          f"{state.spi[1]}); move the channel to another pin")
            table = parse_table(isrc, c.path.endswith(".aio"), r.diags)
            taken = check_channels(table, sv, board, r.diags, used_pins, used_inputs, refused)
            channels += taken
            if not table.analog:
                kept = {ch.element.name for ch in taken}
                refused_outputs |= {row.element.text for row in table.rows
                                    if not isinstance(row, Problem) and row.direction.text == "o"} - kept
    return channels, sensors, refused_outputs


def _channel_tasks(channels: list[M.Channel], io_files: list[ConfigFile], has, pyro_names: set[str],
                   r: Report) -> None:
    """A channel table's `i` rows run in the `inputs` task and its `o` rows in
    the `outputs` task: without the task, a table that has such rows is
    reported at its `io` line (pyro channels report their own missing
    `outputs` task, pyrocheck.py). `has(kind)`: whether [tasks] has a row of
    that kind."""
    for direction, kind, verb, example in (("i", "inputs", "read", "sense inputs rate=100"),
                                           ("o", "outputs", "driven", "act outputs rate=100")):
        if has(kind):
            continue
        for c in io_files:
            rows = [ch for ch in channels if ch.path == c.path and ch.direction == direction
                    and ch.element.name not in pyro_names]
            if rows:
                first = rows[0]
                r.err(c.file, f"the {'input' if direction == 'i' else 'output'} channels of "
                              f"`{os.path.basename(c.path)}` (`{first.element.name}`, pin {first.pin}, line "
                              f"{first.line}{' and more' if len(rows) > 1 else ''}) are {verb} by the `{kind}` "
                              f"task, and [tasks] has none: add one (e.g. `{example}`)")


# ---- [time] ---------------------------------------------------------------------

def _time(rows: tuple[Setting, ...], r: Report) -> tuple[str, str]:
    """(source, unit)."""
    chosen = {"source": "clock", "unit": "ms"}
    for s in rows:
        allowed = {"source": ("clock", "cycle"), "unit": ("ms", "us")}.get(s.key.text)
        if allowed is None:
            r.err(s.key, f"unknown setting `{s.key.text}`: expected `source` or `unit`")
        elif len(s.values) != 1 or s.values[0].text not in allowed:
            r.err(s.values[0] if s.values else s.key, f"`{s.key.text}` is one of: {', '.join(allowed)}")
        else:
            chosen[s.key.text] = s.values[0].text
    return chosen["source"], chosen["unit"]


def _time_element(machines: list[M.Machine], sv: M.StateVector, r: Report) -> M.Element | None:
    """The element every machine's `G` is."""
    g_elems = {m.vars[m.g].name for m in machines}
    if len(g_elems) > 1:
        r.at(1, 1, "the machines disagree on `G`: " + ", ".join(sorted(g_elems))
             + " (every machine's `G` must be the same element)")
        return None
    return sv.find(g_elems.pop()) if g_elems else None


# ---- [tasks] --------------------------------------------------------------------

def _tasks(rows: tuple[TaskRow, ...], sv: M.StateVector, rate: int, machines: list[M.Machine],
           machine_files: list[ConfigFile], r: Report):
    """(the tasks, {task name: its options}); a machine that runs in no task
    is reported at its [configs] line."""
    machine_names = {m.name: i for i, m in enumerate(machines)}
    tasks: list[Task] = []
    task_opts: dict[str, dict] = {}  # by task name: its `key=value` tokens
    machine_lines: dict[int, int] = {}  # by machine: the line of the task that runs it
    link_tasks: dict[str, Task] = {}  # kinds that drive the one serial link: the first of each
    for row in rows:
        kind = _task_kind(row, tasks, link_tasks, r)
        if kind is None:
            continue
        midx = None
        if kind == "machine":
            midx = _task_machine(row, machine_names, machine_lines, r)
            if midx is None:
                continue
            machine_lines[midx] = row.name.line
        opts = options(row.options, r)
        task = _task(row, kind, midx, opts, sv, rate, r)
        if task is None:
            continue
        task_opts[task.name] = opts
        tasks.append(task)
        if kind in ("telemetry", "uplink", "recorder"):
            link_tasks[kind] = task
    for name, idx in machine_names.items():
        if idx not in machine_lines:
            tok = next(c.file for c in machine_files if os.path.splitext(os.path.basename(c.path))[0] == name)
            r.err(tok, f"machine `{name}` runs in no task: add `NAME machine {name}` to [tasks]")
    return tasks, task_opts


def _task_kind(row: TaskRow, tasks: list[Task], link_tasks: dict[str, Task], r: Report) -> str | None:
    """What the row's task runs, when its name and kind are good."""
    name = row.name
    earlier = next((t for t in tasks if t.name == name.text), None)
    if name.kind != ID:
        r.err(name, f"expected a task name, found {show(name)}")
    elif earlier is not None:
        r.err(name, f"reuse of task name `{name.text}` (previously used on line {earlier.line})")
    elif row.kind is None or row.kind.text not in TASK_KINDS:
        r.err(row.kind or name, f"expected what the task runs: one of {', '.join(TASK_KINDS)}")
    elif row.kind.text in link_tasks:
        first = link_tasks[row.kind.text]
        what = "keeps the flight record" if row.kind.text == "recorder" else "drives the serial link"
        r.err(row.kind, f"a second `{row.kind.text}` task: task `{first.name}` on line {first.line} already {what} "
                        f"(at most one `{row.kind.text}` task)")
    else:
        return row.kind.text
    return None


def _task_machine(row: TaskRow, machine_names: dict[str, int], machine_lines: dict[int, int],
                  r: Report) -> int | None:
    """The index of the machine a `machine` task runs."""
    mt = row.machine
    if mt is None:
        r.err(row.kind, "`machine` takes the name of a machine from [configs]")
    elif mt.text not in machine_names:
        r.err(mt, f"unknown machine `{mt.text}`"
                  + (f" (machines: {', '.join(machine_names)})" if machine_names else ""))
    elif machine_names[mt.text] in machine_lines:
        r.err(mt, f"machine `{mt.text}` already runs in task on line {machine_lines[machine_names[mt.text]]}")
    else:
        return machine_names[mt.text]
    return None


def _task(row: TaskRow, kind: str, midx: int | None, opts: dict, sv: M.StateVector, rate: int,
          r: Report) -> Task | None:
    """The task of a row whose name, kind and machine are good, when its
    settings are."""
    for k, (kt, _) in opts.items():
        if k not in TASK_SETTINGS:
            r.err(kt, f"unknown task setting `{k}`: expected `rate`, `mode`, `start`, "
                      "`overruns` or `worst_us`")
    stats = _task_stats(opts, sv, r)
    if stats is None:
        return None
    timing = _task_timing(opts, rate, r)
    if timing is None:
        return None
    mode = _task_mode(opts, sv, r)
    if mode is None:
        return None
    task_rate, divider = timing
    mode_el, start = mode
    return Task(row.name.text, kind, midx, task_rate, divider, mode_el, start, row.name.line,
                stats.get("overruns"), stats.get("worst_us"))


def _task_stats(opts: dict, sv: M.StateVector, r: Report) -> dict[str, M.Element] | None:
    """{`overruns`/`worst_us`: element}; None when one is refused (each is
    reported)."""
    out = {}
    bad = False
    for k, want in TASK_STATS:
        if k not in opts:
            continue
        et = opts[k][1]
        el = sv.find(et.text)
        if el is None:
            r.err(et, f"unknown element `{et.text}`")
            bad = True
        elif el.type.name != want:
            r.err(et, f"`{k}` needs a {want} element; `{et.text}` is {el.type}")
            bad = True
        else:
            out[k] = el
    return None if bad else out


def _task_timing(opts: dict, rate: int, r: Report) -> tuple[Fraction, int] | None:
    """(the task's rate, the executor cycles between its steps)."""
    if "rate" not in opts:
        return Fraction(rate), 1
    tok = opts["rate"][1]
    q = positive(tok, r, "`rate`")
    if q is None:
        return None
    divider = Fraction(rate) / q
    if divider.denominator != 1:
        r.err(tok, f"task rate {tok.text} Hz must divide the executor rate {rate} Hz")
        return None
    return q, int(divider)


def _task_mode(opts: dict, sv: M.StateVector, r: Report) -> tuple[M.Element | None, str] | None:
    """(the mode element or None, the mode at boot)."""
    mode_el = None
    if "mode" in opts:
        mt = opts["mode"][1]
        mode_el = sv.find(mt.text)
        if mode_el is None:
            r.err(mt, f"unknown element `{mt.text}`")
            return None
        if mode_el.type is not U8:
            r.err(mt, f"a task's mode element must be U8 (0 disabled, 1 safed, 2 enabled); "
                      f"`{mt.text}` is {mode_el.type}")
            return None
    if "start" not in opts:
        return mode_el, "enabled"
    st = opts["start"][1]
    if st.text not in TASK_MODES:
        r.err(st, "`start` is one of: enabled, safed, disabled")
        return None
    if mode_el is None:
        r.err(st, "`start` needs a `mode` element to hold the task's mode")
        return None
    return mode_el, st.text


def _clock_steps(tasks: list[Task], board: Board | None, time_source: str, time_unit: str, r: Report) -> None:
    """Every machine's task steps slower than `G` ticks.

    With `source clock`, G is the board's millis()/micros(), which advance
    in ticks of the timer that keeps them. On a board whose executor keeps
    its own timer (`executor.timer`: cycles start on its count, and the
    clock is its 0.5 us ticks) G moves on by the cycle's exact period. On
    any other AVR board the Arduino core's millis() moves on every 16,384
    CPU cycles (1.024 ms at 16 MHz, by 2 at 8 MHz), so a machine stepping
    faster than that sometimes sees G stand still, and a machine whose time
    does not increase is safed."""
    per_second = 1000 if time_unit == "ms" else 1000000
    tick_us = (Fraction(16384 * 1000000, board.f_cpu) if board is not None and board.f_cpu and
               not board.timer and time_source == "clock" and time_unit == "ms" else None)
    for t in tasks:
        if t.kind != "machine":
            continue
        if t.rate > per_second:
            r.at(t.line, 1, f"task `{t.name}` runs at {hz(t.rate)} Hz but `G` counts in {time_unit}: "
                            "`G` would not increase between its steps (use `unit us`)")
        elif time_source == "clock" and t.rate == per_second:
            r.at(t.line, 1, f"task `{t.name}` steps every 1 {time_unit} and `G` is the clock in {time_unit}: a "
                            f"cycle that starts late would step in the same {time_unit} as the one before, and "
                            "a machine whose time does not increase is safed (use `unit us`, `source cycle`, "
                            "or a slower rate)")
        elif tick_us is not None and Fraction(1000000) / t.rate < tick_us:
            r.at(t.line, 1,
                 f"task `{t.name}` steps every {float(Fraction(1000000) / t.rate):g} us, but with `source clock` "
                 f"and `unit ms` the {board.name}'s millis() moves on only every {float(tick_us):g} us: `G` "
                 f"would sometimes not increase between its steps (use `unit us`, `source cycle`, or a "
                 f"rate of at most {int(Fraction(1000000) / tick_us)} Hz)")


# ---- [telemetry] ----------------------------------------------------------------

def _telemetry(rows: tuple[StreamRow, ...], sv: M.StateVector, tasks: list[Task], r: Report) -> list[M.Stream]:
    tele = next((t for t in tasks if t.kind == "telemetry"), None)
    streams = []
    for row in rows:
        s = _stream(row, sv, tele, r)
        if s is not None:
            streams.append(s)
    return streams


def _stream(row: StreamRow, sv: M.StateVector, tele: Task | None, r: Report) -> M.Stream | None:
    rt = row.region
    region = next((x for x in sv.regions if x.name == rt.text), None)
    if region is None:
        r.err(rt, f"unknown region `{rt.text}`")
        return None
    opts = options(row.options, r)
    unknown = [kt for k, (kt, _) in opts.items() if k != "rate"]
    for kt in unknown:
        r.err(kt, f"unknown stream setting `{kt.text}`: a stream takes `rate=HZ`")
    if unknown:
        return None
    if "rate" not in opts:
        r.err(rt, f"region `{rt.text}` needs `rate=HZ`")
        return None
    tok = opts["rate"][1]
    q = positive(tok, r, "`rate`")
    if q is None:
        return None
    if tele is None:
        r.err(rt, "telemetry streams need a `telemetry` task in [tasks]")
        return None
    div = tele.rate / q
    if div.denominator != 1:
        r.err(tok, f"stream rate {tok.text} Hz must divide the telemetry task's rate {hz(tele.rate)} Hz")
        return None
    return M.Stream(region, q, int(div) * tele.divider, rt.line)


# ---- [uplink], the reset cause, one writer per element -----------------------------

def _uplink(rows: tuple[WritableRow, ...], sv: M.StateVector, tasks: list[Task], machines: list[M.Machine],
            channels: list[M.Channel], reset_tok: Tok | None, r: Report,
            sensors: list[M.Sensor] = ()) -> list[M.Element]:
    """The elements the ground may write: none that the executor, a machine's
    `G`/`S` or an input channel writes."""
    owners = {m.vars[m.g].name: f"`G` of machine `{m.name}`" for m in machines}
    owners.update({m.vars[m.s].name: f"`S` of machine `{m.name}`" for m in machines})
    for t in tasks:  # what the executor writes: modes change only by MODE
        for what, el in (("mode", t.mode), ("overruns", t.overruns), ("worst_us", t.worst_us)):
            if el is not None:
                owners.setdefault(el.name, f"the {what} of task `{t.name}`")
    if reset_tok is not None:
        owners.setdefault(reset_tok.text, "the reset cause")
    inputs = {c.element.name: f"input channel {c.path}:{c.line}" for c in channels if c.direction == "i"}
    for p in sensors:
        for el in _sensor_elements(p):
            inputs[el.name] = f"sensor {sensor_name(p)} {p.path}:{p.line}"
    if rows and not any(t.kind == "uplink" for t in tasks):  # once: the list is what is idle, not each line
        et = rows[0].element
        r.diags.warning(r.src, APP, et.line, et.col, "writable elements without an `uplink` task in [tasks]: "
                                                     "nothing receives commands, so none is ever written")
    writable: list[M.Element] = []
    for row in rows:
        et = row.element
        e = sv.find(et.text)
        if e is None:
            r.err(et, f"unknown element `{et.text}`")
        elif et.text in owners:
            r.err(et, f"element `{et.text}` is {owners[et.text]}: it cannot be written over the uplink")
        elif et.text in inputs:
            r.err(et, f"element `{et.text}` is written by {inputs[et.text]}: an uplink write would be lost")
        elif e in writable:
            r.err(et, f"element `{et.text}` is listed twice")
        elif len(writable) == U8_COUNT:
            r.err(et, f"element `{et.text}` is writable element {U8_COUNT + 1}: the uplink writes at most {U8_COUNT}")
        else:
            writable.append(e)
            if row.extra is not None:
                r.err(row.extra, f"unexpected {show(row.extra)}: one element per line")
    return writable


def _reset_cause(tok: Tok | None, sv: M.StateVector, r: Report) -> M.Element | None:
    if tok is None:
        return None
    el = sv.find(tok.text)
    if el is None:
        r.err(tok, f"unknown element `{tok.text}`")
    elif el.type is not U8:
        r.err(tok, f"`reset_cause` needs a U8 element; `{tok.text}` is {el.type}")
    return el


def _one_writer(r: Report, channels, tasks, task_opts, reset_tok, reset_el, machines, machine_srcs,
                pyro_names=frozenset(), sensors=()) -> None:
    """Every element has at most one writer among the input channels, the
    executor (each task's mode, overruns and worst_us; the reset cause) and
    the machines (their assignments and their own `S`); a second writer is
    reported where it is written, naming the first. (`G` is the executor's
    by construction: every machine declares it read-only. The uplink is no
    writer of this kind: see its own check. A second machine writing a
    `[pyro]` element, `pyro_names`, is the pyro check's to report, with its
    own reason.)"""
    writers: dict[str, str] = {}
    by_machine: set[str] = set()  # elements some machine writes

    def write(name: str, who: str, report) -> None:
        if name in writers:
            report(f"element `{name}` is already written by {writers[name]}: {who} cannot write it too")
        else:
            writers[name] = who

    for c in channels:
        if c.direction == "i":  # two input channels: the table checker's own error
            writers.setdefault(c.element.name, f"input channel {c.path}:{c.line}")
    for p in sensors:  # likewise: a part's element taken by an input is the sensor table's error
        for el in _sensor_elements(p):
            writers.setdefault(el.name, f"sensor {sensor_name(p)} ({os.path.basename(p.path)}:{p.line})")
    for t in tasks:
        for key, el in (("mode", t.mode), ("overruns", t.overruns), ("worst_us", t.worst_us)):
            if el is not None:
                tok = task_opts[t.name][key][1]
                write(el.name, f"the executor (the {key} of task `{t.name}`)", lambda msg, tok=tok: r.err(tok, msg))
    if reset_el is not None and reset_el.type is U8:
        write(reset_el.name, "the executor (the reset cause)", lambda msg: r.err(reset_tok, msg))
    for m in machines:
        msrc = machine_srcs[m.name]
        s = m.vars[m.s]
        write(s.name, f"machine `{m.name}` (its `S`)", lambda msg: r.diags.error(msrc, SM, s.line, 1, msg))
        seen = set()
        for a in assignments(m):
            v = m.vars[a.var]
            if v.kind != M.ELEMENT or v.name in seen:
                continue
            seen.add(v.name)
            if v.name in pyro_names and v.name in by_machine:
                continue
            by_machine.add(v.name)
            write(v.name, f"machine `{m.name}` ({os.path.basename(m.path)}:{a.line})",
                  lambda msg, a=a: r.diags.error(msrc, SM, a.line, a.col, msg))


def _sensor_elements(p: M.Sensor) -> list[M.Element]:
    """The elements a sensor part writes: its readings, fault and health."""
    return [el for _, el in p.outputs] + [el for el in (p.fault, p.health) if el is not None]


# ---- [budget] -------------------------------------------------------------------

def _budget(rows: tuple[Setting, ...], board: Board | None, r: Report) -> dict[str, int]:
    """{`flash`/`ram`: bytes at most}."""
    budget: dict[str, int] = {}
    for s in rows:
        q = _budget_value(s, budget, board, r)
        if q is not None:
            budget[s.key.text] = q
    return budget


def _budget_value(s: Setting, budget: dict[str, int], board: Board | None, r: Report) -> int | None:
    key = s.key.text
    if key not in ("flash", "ram"):
        r.err(s.key, f"unknown budget `{key}`: expected `flash` or `ram` (bytes)")
        return None
    if key in budget:
        r.err(s.key, f"`{key}` is given twice")
        return None
    if len(s.values) != 1:
        r.err(s.values[1] if len(s.values) > 1 else s.key, f"`{key}` takes one value, a number of bytes")
        return None
    tok = s.values[0]
    q = positive(tok, r, f"`{key}`")
    if q is None:
        return None
    if q.denominator != 1:
        r.err(tok, f"`{key}` is a whole number of bytes, found `{tok.text}`")
        return None
    # A board whose memory is 0 (the native host build) has no limit to hold a budget to.
    limit = None if board is None else (board.flash if key == "flash" else board.ram)
    if limit and q > limit:
        r.err(tok, f"a {key} budget of {int(q):,} B is more than the {board.name} has ({limit:,} B)")
        return None
    return int(q)


# ---- the serial link's baud rate ----------------------------------------------------

# The UART's error a serial link allows: 8N1 frames tolerate about 4.5 %
# between the two ends in all; half of it is the target's (the Arduino
# standard, 115200 baud from 16 MHz, is +2.12 %).
BAUD_TOLERANCE = Fraction(25, 1000)
UBRR_MAX = 4095  # the divisor register's 12 bits


def _ubrr(f_cpu: int, baud: int) -> int:
    """The divisor the runtime programs (psl_arduino_console.cpp, as the
    Arduino core: double speed, U2X), before it is cut to 16 bits; negative
    where the C expression underflows."""
    return (f_cpu // 4 // baud - 1) // 2


def uart_rate(board: Board, baud: int) -> Fraction | None:
    """The rate the board's UART makes when asked for `baud`; None without a
    UART clock (the host build) or outside the divisor's range."""
    if not board.f_cpu:
        return None
    ubrr = _ubrr(board.f_cpu, baud)
    if not 0 <= ubrr <= UBRR_MAX:
        return None
    return Fraction(board.f_cpu, 8 * (ubrr + 1))


def _percent(made: Fraction, baud: int) -> str:
    return f"{float(made / baud - 1) * 100:+.2f} %"


def baud_problem(board: Board, baud: int) -> str | None:
    """Why the board's UART cannot run at `baud` within BAUD_TOLERANCE, or
    None (as avr-libc's <util/setbaud.h> computes it, for the divisor the
    runtime uses)."""
    if not board.f_cpu:
        return None
    mhz = f"{board.f_cpu / 1e6:g} MHz, double speed"
    ubrr = _ubrr(board.f_cpu, baud)
    if ubrr < 0:
        fastest = Fraction(board.f_cpu, 8)
        return (f"`baud {baud}` is faster than the {board.name}'s UART can run ({mhz}): "
                f"the fastest it makes is {float(fastest):,.0f} baud, {_percent(fastest, baud)}")
    if ubrr > UBRR_MAX:
        slowest = Fraction(board.f_cpu, 8 * (UBRR_MAX + 1))
        return (f"`baud {baud}` is slower than the {board.name}'s UART can run ({mhz}, a 12-bit divisor): "
                f"the slowest it makes is {float(slowest):,.0f} baud, {_percent(slowest, baud)}")
    made = Fraction(board.f_cpu, 8 * (ubrr + 1))
    if abs(made / baud - 1) > BAUD_TOLERANCE:
        return (f"`baud {baud}`: the {board.name}'s UART makes {float(made):,.0f} baud ({mhz}, UBRR {ubrr}), "
                f"{_percent(made, baud)}, more than the ±{float(BAUD_TOLERANCE) * 100:g} % a serial link allows")
    return None
