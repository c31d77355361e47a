"""The application config (spec §7): ties a state vector, machines and I/O
tables to a board, orders the tasks of the executor, and names the
telemetry streams and the elements the ground may write.

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

import os
import re
from dataclasses import dataclass
from fractions import Fraction

from . import model as M
from .board import Board, BoardError, load_board
from .check import assignments, check_literals, check_sm, check_sv, machine_exprs
from .cnames import machine_clashes, machine_ident
from .diagnostics import APP, SM, Diagnostics, Source, read_source
from .iotables import Channel, check_table
from .limits import U8_COUNT, check_limits, hz
from .lexer import ID, NUM, OP, lex
from .numeric import REALS, exact_literal
from .parser import parse_sm, parse_sv, show, split_sections
from .types import U8

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")  # a name, as the lexer reads one
TASK_KINDS = ("inputs", "outputs", "machine", "telemetry", "uplink")
TASK_MODES = {"disabled": 0, "safed": 1, "enabled": 2}  # values of a task's U8 mode element


@dataclass(frozen=True)
class Task:
    name: str
    kind: str  # one of TASK_KINDS
    machine: int | None  # index into Application.machines for kind "machine"
    rate: Fraction  # Hz
    divider: int  # runs every `divider` executor cycles
    mode: M.Element | None  # U8: 0 disabled, 1 safed, 2 enabled
    start: str  # the mode at boot
    line: int
    overruns: M.Element | None = None  # U16: steps longer than the task's period
    worst_us: M.Element | None = None  # U32: the longest step, microseconds


@dataclass(frozen=True)
class Stream:
    region: M.Region
    rate: Fraction
    divider: int  # executor cycles between samples
    line: int


@dataclass(frozen=True)
class Application:
    path: str
    name: str
    board: Board
    rate: int  # executor cycles per second
    baud: int
    sv: M.StateVector
    machines: tuple[M.Machine, ...]
    channels: tuple[Channel, ...]
    tasks: tuple[Task, ...]
    time_element: M.Element
    time_source: str  # "clock" or "cycle"
    time_unit: str  # "ms" or "us"
    telemetry: tuple[Stream, ...]
    writable: tuple[M.Element, ...]
    reset_cause: M.Element | None = None  # U8: the MCU's reset cause at boot
    flash_budget: int | None = None  # [budget] flash: bytes of program memory at most
    ram_budget: int | None = None  # [budget] ram: data + bss + the stack's high-water mark


def _kv(toks, start, src, diags):
    """`key=value` pairs from toks[start:]; returns {key: (tok, value tok)}."""
    out = {}
    i = start
    while i < len(toks):
        t = toks[i]
        if (t.kind == ID and i + 2 < len(toks) and toks[i + 1].kind == OP and toks[i + 1].text == "="
                and toks[i + 2].kind in (ID, NUM)):
            if t.text in out:
                diags.error(src, APP, t.line, t.col, f"`{t.text}=` given twice")
            out[t.text] = (t, toks[i + 2])
            i += 3
        else:
            diags.error(src, APP, t.line, t.col, f"unexpected {show(t)}: expected `key=value`")
            return out
    return out


def _positive(tok, src, diags, what) -> Fraction | None:
    q = exact_literal(tok.text) if tok.kind == NUM else None
    if q is None or q <= 0 or q > 10**9:
        text = tok.text if len(tok.text) <= 40 else tok.text[:37] + "..."
        big = q > 10**9 if q is not None else tok.kind == NUM and float(tok.text) > 1  # None: beyond 10^±4000
        limit = " no greater than 1,000,000,000" if big else ""
        if q is None and tok.kind == NUM and not big:  # positive, but too long or too small to take exactly
            diags.error(src, APP, tok.line, tok.col, f"{what} is beyond the numbers the tools take (at most 4,000 "
                                                     f"significant digits, from 1e-4000 to 1e4000), found `{text}`")
            return None
        diags.error(src, APP, tok.line, tok.col, f"{what} must be a positive number{limit}, found `{text}`")
        return None
    return q


def load_app(path: str, diags: Diagnostics, board_override: str | None = None) -> Application | None:
    """The checked application with its state vector, machines and tables;
    None with every error in `diags`."""
    src = read_source(path, diags, APP)
    if src is None:
        return None
    before = diags.error_count
    err = lambda t, msg: diags.error(src, APP, t.line, t.col, msg)  # noqa: E731
    folder = os.path.dirname(path)
    lines = lex(src, diags, APP)
    pre, sections = split_sections(src, lines, diags, APP)
    for toks in pre:
        err(toks[0], f"unexpected {show(toks[0])} before the first section")
    known = ("application", "configs", "time", "tasks", "telemetry", "uplink", "budget")
    body: dict[str, list] = {}
    for header, rows in sections:
        if header.name == "<malformed>":
            continue
        if header.name not in known:
            diags.error(src, APP, header.line, header.col + 1,
                        f"unknown section `[{header.name}]`: expected one of "
                        + ", ".join(f"[{k}]" for k in known))
            continue
        if header.name in body:
            diags.error(src, APP, header.line, header.col + 1, f"duplicate section `[{header.name}]`")
            continue
        body[header.name] = rows

    # [application]
    settings: dict[str, object] = {}
    for toks in body.get("application", []):
        key = toks[0]
        if key.text not in ("name", "board", "rate", "baud", "reset_cause"):
            err(key, f"unknown setting `{key.text}`: expected `name`, `board`, `rate`, `baud` "
                     "or `reset_cause`")
            continue
        if len(toks) != 2:
            err(toks[min(2, len(toks) - 1)] if len(toks) > 2 else key, f"`{key.text}` takes one value")
            continue
        settings[key.text] = toks[1]
    name = settings["name"].text if "name" in settings else os.path.splitext(os.path.basename(path))[0]
    board = None
    board_tok = settings.get("board")
    board_name = board_override or (board_tok.text if board_tok is not None else None)
    if board_name is None:
        diags.error(src, APP, 1, 1, "missing `board` in [application]")
    else:
        try:
            board = load_board(board_name)
        except BoardError as e:
            if board_tok is not None and board_override is None:
                err(board_tok, str(e))
            else:
                diags.error(src, APP, 1, 1, str(e))
    rate = 100
    if "rate" in settings:
        q = _positive(settings["rate"], src, diags, "`rate`")
        if q is not None:
            if q.denominator != 1 or 1000000 % q != 0:
                err(settings["rate"], "`rate` must be a whole number of cycles per second that divides "
                                      "1000000 (a whole number of microseconds per cycle)")
            elif q > 100000:
                err(settings["rate"], f"`rate` is at most 100000 cycles per second (10 us a cycle), "
                                      f"found {settings['rate'].text}")
            else:
                rate = int(q)
    baud = 115200
    if "baud" in settings:
        bt = settings["baud"]
        q = _positive(bt, src, diags, "`baud`")
        if q is not None and q.denominator != 1:
            near = round(q)
            made = _uart_rate(board, near) if board is not None and near > 0 else None
            err(bt, f"`baud` must be a whole number of bits per second, found `{bt.text}`"
                    + (f" (for {near} the {board.name}'s UART makes {float(made):,.0f} baud, {_percent(made, near)})"
                       if made is not None else ""))
        elif q is not None:
            baud = int(q)
            problem = _baud_problem(board, baud) if board is not None else None
            if problem is not None:
                err(bt, problem)
    elif board is not None and _baud_problem(board, baud) is not None:
        at = board_tok if board_tok is not None and board_override is None else None
        diags.error(src, APP, at.line if at else 1, at.col if at else 1,
                    f"{_baud_problem(board, baud)}; `baud` is not set, so it is the default: set `baud` in "
                    "[application]")

    # [configs]
    sv_tok = None
    machine_toks, io_toks = [], []
    for toks in body.get("configs", []):
        key = toks[0]
        if key.text not in ("state_vector", "machine", "io"):
            err(key, f"unknown config kind `{key.text}`: expected `state_vector`, `machine` or `io`")
            continue
        if len(toks) < 2:
            err(key, f"`{key.text}` takes a file name")
            continue
        fname = src.line(key.line)[_col_index(src.line(key.line), toks[1].col):].split("#", 1)[0].strip()
        entry = (key, toks[1], os.path.join(folder, fname))
        if key.text == "state_vector":
            if sv_tok is not None:
                err(key, "only one `state_vector` per application")
            sv_tok = entry
        elif key.text == "machine":
            machine_toks.append(entry)
        else:
            io_toks.append(entry)
    if sv_tok is None:
        diags.error(src, APP, 1, 1, "missing `state_vector` in [configs]")
        return None
    sv_src = read_source(sv_tok[2], diags, APP)
    if sv_src is None:
        return None
    sv = check_sv(parse_sv(sv_src, diags), sv_src, diags)
    machines: list[M.Machine] = []
    machine_names: dict[str, int] = {}
    machine_srcs: dict[str, Source] = {}  # by machine name: where its writes are reported
    for key, tok, mpath in machine_toks:
        msrc = read_source(mpath, diags, APP)
        if msrc is None:
            continue
        m = check_sm(parse_sm(msrc, diags), msrc, sv, diags)
        if m is None:
            continue
        if board is not None:  # an error, and the machine still known to the rest of the file
            check_literals(machine_exprs(m), REALS[board.real], msrc, diags, SM, f"the {board.name}'s")
        if not _NAME.fullmatch(m.name):
            err(tok, f"the machine in `{os.path.basename(mpath)}` is named `{m.name}` after its file, and "
                     "[tasks] can only name a machine whose name is letters, digits and `_`, not starting "
                     "with a digit: rename the file")
            continue
        if m.name in machine_names:
            err(tok, f"two machines are named `{m.name}`")
            continue
        clash = next((machines[i].name for i, j in machine_clashes([x.name for x in machines] + [m.name])
                      if j == len(machines)), None)
        if clash is not None:
            err(tok, f"machines `{clash}` and `{m.name}` would generate the same C++ files "
                     f"(`{machine_ident(m.name)}.gen.h`; file names that differ only in case are one file "
                     "on some file systems): rename one")
            continue
        machine_names[m.name] = len(machines)
        machine_srcs[m.name] = msrc
        machines.append(m)
    channels: list[Channel] = []
    if board is not None:
        used_pins: dict = {}
        used_inputs: dict = {}
        for key, tok, ipath in io_toks:
            if not ipath.endswith((".aio", ".dio")):
                err(tok, "an I/O table is a `.aio` (analog) or `.dio` (digital) file")
                continue
            isrc = read_source(ipath, diags, APP)
            if isrc is None:
                continue
            channels += check_table(isrc, ipath.endswith(".aio"), sv, board, diags, used_pins, used_inputs)

    # [time]
    time_source, time_unit = "clock", "ms"
    for toks in body.get("time", []):
        key = toks[0]
        allowed = {"source": ("clock", "cycle"), "unit": ("ms", "us")}.get(key.text)
        if allowed is None:
            err(key, f"unknown setting `{key.text}`: expected `source` or `unit`")
        elif len(toks) != 2 or toks[1].text not in allowed:
            err(toks[1] if len(toks) > 1 else key, f"`{key.text}` is one of: {', '.join(allowed)}")
        elif key.text == "source":
            time_source = toks[1].text
        else:
            time_unit = toks[1].text
    g_elems = {m.vars[m.g].name for m in machines}
    time_element = None
    if len(g_elems) > 1:
        diags.error(src, APP, 1, 1, "the machines disagree on `G`: " + ", ".join(sorted(g_elems))
                    + " (every machine's `G` must be the same element)")
    elif g_elems:
        time_element = sv.find(g_elems.pop())
    if time_source == "cycle" and time_unit == "ms" and 1000 % rate != 0:
        diags.error(src, APP, 1, 1, f"`source cycle` with `unit ms` needs a rate that divides 1000 "
                                    f"(one cycle must be a whole number of ms); rate is {rate}")

    # [tasks]
    tasks: list[Task] = []
    task_lines: dict[str, int] = {}
    machine_tasks: dict[int, int] = {}
    link_tasks: dict[str, Task] = {}  # kinds that drive the one serial link: the first of each
    task_opts: dict[str, dict] = {}  # by task name: its `key=value` tokens
    for toks in body.get("tasks", []):
        tname = toks[0]
        if tname.kind != ID:
            err(tname, f"expected a task name, found {show(tname)}")
            continue
        if tname.text in task_lines:
            err(tname, f"reuse of task name `{tname.text}` (previously used on line {task_lines[tname.text]})")
            continue
        if len(toks) < 2 or toks[1].text not in TASK_KINDS:
            t = toks[1] if len(toks) > 1 else tname
            err(t, f"expected what the task runs: one of {', '.join(TASK_KINDS)}")
            continue
        kind = toks[1].text
        if kind in link_tasks:
            first = link_tasks[kind]
            err(toks[1], f"a second `{kind}` task: task `{first.name}` on line {first.line} already drives "
                         f"the serial link (at most one `{kind}` task)")
            continue
        i = 2
        midx = None
        if kind == "machine":
            if len(toks) < 3 or toks[2].kind != ID or (len(toks) > 3 and toks[3].text == "="):
                err(toks[1], "`machine` takes the name of a machine from [configs]")
                continue
            mt = toks[2]
            i = 3
            if mt.text not in machine_names:
                err(mt, f"unknown machine `{mt.text}`"
                        + (f" (machines: {', '.join(machine_names)})" if machine_names else ""))
                continue
            midx = machine_names[mt.text]
            if midx in machine_tasks:
                err(mt, f"machine `{mt.text}` already runs in task on line {machine_tasks[midx]}")
                continue
            machine_tasks[midx] = tname.line
        opts = _kv(toks, i, src, diags)
        for k, (kt, _) in opts.items():
            if k not in ("rate", "mode", "start", "overruns", "worst_us"):
                err(kt, f"unknown task setting `{k}`: expected `rate`, `mode`, `start`, "
                        "`overruns` or `worst_us`")
        stat_elems = {}
        bad_stat = False
        for k, want in (("overruns", "U16"), ("worst_us", "U32")):
            if k in opts:
                et = opts[k][1]
                el = sv.find(et.text)
                if el is None:
                    err(et, f"unknown element `{et.text}`")
                    bad_stat = True
                elif el.type.name != want:
                    err(et, f"`{k}` needs a {want} element; `{et.text}` is {el.type}")
                    bad_stat = True
                else:
                    stat_elems[k] = el
        if bad_stat:
            continue
        task_rate = Fraction(rate)
        if "rate" in opts:
            q = _positive(opts["rate"][1], src, diags, "`rate`")
            if q is None:
                continue
            task_rate = q
        divider = Fraction(rate) / task_rate
        if divider.denominator != 1:
            err(opts["rate"][1], f"task rate {opts['rate'][1].text} Hz must divide the executor rate {rate} Hz")
            continue
        mode_el = None
        if "mode" in opts:
            mt = opts["mode"][1]
            mode_el = sv.find(mt.text)
            if mode_el is None:
                err(mt, f"unknown element `{mt.text}`")
                continue
            if mode_el.type is not U8:
                err(mt, f"a task's mode element must be U8 (0 disabled, 1 safed, 2 enabled); "
                        f"`{mt.text}` is {mode_el.type}")
                continue
        start = "enabled"
        if "start" in opts:
            st = opts["start"][1]
            if st.text not in TASK_MODES:
                err(st, "`start` is one of: enabled, safed, disabled")
                continue
            if mode_el is None:
                err(st, "`start` needs a `mode` element to hold the task's mode")
                continue
            start = st.text
        task_lines[tname.text] = tname.line
        task_opts[tname.text] = opts
        tasks.append(Task(tname.text, kind, midx, task_rate, int(divider), mode_el, start, tname.line,
                          stat_elems.get("overruns"), stat_elems.get("worst_us")))
        if kind in ("telemetry", "uplink"):
            link_tasks[kind] = tasks[-1]
    for name_, idx in machine_names.items():
        if idx not in machine_tasks:
            tok = next(t for k, t, p in machine_toks if os.path.splitext(os.path.basename(p))[0] == name_)
            err(tok, f"machine `{name_}` runs in no task: add `NAME machine {name_}` to [tasks]")
    per_second = 1000 if time_unit == "ms" else 1000000
    # With `source clock`, G is the board's millis()/micros(), which advance
    # in ticks of the timer that keeps them: on an AVR Arduino core millis()
    # moves on every 16,384 CPU cycles (1.024 ms at 16 MHz, by 2 at 8 MHz),
    # so a machine stepping faster than that sometimes sees G stand still,
    # and a machine whose time does not increase is safed.
    tick_us = (Fraction(16384 * 1000000, board.f_cpu) if board is not None and board.f_cpu and
               time_source == "clock" and time_unit == "ms" else None)
    for t in tasks:
        if t.kind == "machine" and t.rate > per_second:
            diags.error(src, APP, t.line, 1, f"task `{t.name}` runs at {hz(t.rate)} Hz but `G` counts in {time_unit}: "
                                             "`G` would not increase between its steps (use `unit us`)")
        elif t.kind == "machine" and tick_us is not None and Fraction(1000000) / t.rate < tick_us:
            diags.error(src, APP, t.line, 1,
                        f"task `{t.name}` steps every {float(Fraction(1000000) / t.rate):g} us, but with `source clock` "
                        f"and `unit ms` the {board.name}'s millis() moves on only every {float(tick_us):g} us: `G` "
                        f"would sometimes not increase between its steps (use `unit us`, `source cycle`, or a "
                        f"rate of at most {int(Fraction(1000000) / tick_us)} Hz)")

    # [telemetry]
    streams: list[Stream] = []
    tele = next((t for t in tasks if t.kind == "telemetry"), None)
    for toks in body.get("telemetry", []):
        rt = toks[0]
        region = next((r for r in sv.regions if r.name == rt.text), None)
        if region is None:
            err(rt, f"unknown region `{rt.text}`")
            continue
        opts = _kv(toks, 1, src, diags)
        unknown = [kt for k, (kt, _) in opts.items() if k != "rate"]
        for kt in unknown:
            err(kt, f"unknown stream setting `{kt.text}`: a stream takes `rate=HZ`")
        if unknown:
            continue
        if "rate" not in opts:
            err(rt, f"region `{rt.text}` needs `rate=HZ`")
            continue
        q = _positive(opts["rate"][1], src, diags, "`rate`")
        if q is None:
            continue
        if tele is None:
            err(rt, "telemetry streams need a `telemetry` task in [tasks]")
            continue
        div = tele.rate / q
        if div.denominator != 1:
            err(opts["rate"][1], f"stream rate {opts['rate'][1].text} Hz must divide the telemetry "
                                 f"task's rate {hz(tele.rate)} Hz")
            continue
        streams.append(Stream(region, q, int(div) * tele.divider, rt.line))

    # [uplink]
    writable: list[M.Element] = []
    owners = {m.vars[m.g].name: f"`G` of machine `{m.name}`" for m in machines}
    owners.update({m.vars[m.s].name: f"`S` of machine `{m.name}`" for m in machines})
    for t in tasks:  # what the executor writes: modes change only by MODE
        for what, el in (("mode", t.mode), ("overruns", t.overruns), ("worst_us", t.worst_us)):
            if el is not None:
                owners.setdefault(el.name, f"the {what} of task `{t.name}`")
    if "reset_cause" in settings:
        owners.setdefault(settings["reset_cause"].text, "the reset cause")
    inputs = {c.element.name: f"input channel {c.path}:{c.line}" for c in channels if c.direction == "i"}
    uplink_task = next((t for t in tasks if t.kind == "uplink"), None)
    for n, toks in enumerate(body.get("uplink", [])):
        et = toks[0]
        e = sv.find(et.text)
        if uplink_task is None and n == 0:  # once: the list is what is idle, not each line
            diags.warning(src, APP, et.line, et.col, "writable elements without an `uplink` task in [tasks]: "
                                                     "nothing receives commands, so none is ever written")
        if e is None:
            err(et, f"unknown element `{et.text}`")
        elif et.text in owners:
            err(et, f"element `{et.text}` is {owners[et.text]}: it cannot be written over the uplink")
        elif et.text in inputs:
            err(et, f"element `{et.text}` is written by {inputs[et.text]}: an uplink write would be lost")
        elif e in writable:
            err(et, f"element `{et.text}` is listed twice")
        elif len(writable) == U8_COUNT:
            err(et, f"element `{et.text}` is writable element {U8_COUNT + 1}: the uplink writes at most {U8_COUNT}")
        else:
            writable.append(e)
            if len(toks) > 1:
                err(toks[1], f"unexpected {show(toks[1])}: one element per line")

    reset_cause = None
    if "reset_cause" in settings:
        rt = settings["reset_cause"]
        reset_cause = sv.find(rt.text)
        if reset_cause is None:
            err(rt, f"unknown element `{rt.text}`")
        elif reset_cause.type is not U8:
            err(rt, f"`reset_cause` needs a U8 element; `{rt.text}` is {reset_cause.type}")

    _one_writer(diags, src, err, channels, tasks, task_opts, settings.get("reset_cause"), reset_cause,
                machines, machine_srcs)

    # [budget]
    budget: dict[str, int] = {}
    for toks in body.get("budget", []):
        key = toks[0]
        if key.text not in ("flash", "ram"):
            err(key, f"unknown budget `{key.text}`: expected `flash` or `ram` (bytes)")
            continue
        if key.text in budget:
            err(key, f"`{key.text}` is given twice")
            continue
        if len(toks) != 2:
            err(toks[2] if len(toks) > 2 else key, f"`{key.text}` takes one value, a number of bytes")
            continue
        q = _positive(toks[1], src, diags, f"`{key.text}`")
        if q is None:
            continue
        if q.denominator != 1:
            err(toks[1], f"`{key.text}` is a whole number of bytes, found `{toks[1].text}`")
            continue
        # A board whose memory is 0 (the native host build) has no limit to hold a budget to.
        limit = None if board is None else (board.flash if key.text == "flash" else board.ram)
        if limit and q > limit:
            err(toks[1], f"a {key.text} budget of {int(q):,} B is more than the {board.name} has "
                         f"({limit:,} B)")
            continue
        budget[key.text] = int(q)

    if diags.error_count != before or board is None or time_element is None:
        if time_element is None and not machines and diags.error_count == before:
            diags.error(src, APP, 1, 1, "an application needs at least one `machine` in [configs]")
        return None
    app = Application(path, name, board, rate, baud, sv, tuple(machines), tuple(channels),
                      tuple(tasks), time_element, time_source, time_unit, tuple(streams), tuple(writable),
                      reset_cause, budget.get("flash"), budget.get("ram"))
    toks = {os.path.splitext(os.path.basename(p))[0]: t for _, t, p in machine_toks}
    return app if check_limits(app, src, diags, sv_tok[1], toks) else None


def _one_writer(diags, src, err, channels, tasks, task_opts, reset_tok, reset_el, machines, machine_srcs):
    """Every element has at most one writer among the input channels, the
    executor (each task's mode, overruns and worst_us; the reset cause) and
    the machines (their assignments and their own `S`); a second writer is
    reported where it is written, naming the first. (`G` is the executor's
    by construction: every machine declares it read-only. The uplink is no
    writer of this kind: see its own check.)"""
    writers: dict[str, str] = {}

    def write(name: str, who: str, report) -> None:
        if name in writers:
            report(f"element `{name}` is already written by {writers[name]}: {who} cannot write it too")
        else:
            writers[name] = who

    for c in channels:
        if c.direction == "i":  # two input channels: check_table's own error
            writers.setdefault(c.element.name, f"input channel {c.path}:{c.line}")
    for t in tasks:
        for key, el in (("mode", t.mode), ("overruns", t.overruns), ("worst_us", t.worst_us)):
            if el is not None:
                tok = task_opts[t.name][key][1]
                write(el.name, f"the executor (the {key} of task `{t.name}`)", lambda msg, tok=tok: err(tok, msg))
    if reset_el is not None and reset_el.type is U8:
        write(reset_el.name, "the executor (the reset cause)", lambda msg: err(reset_tok, msg))
    for m in machines:
        msrc = machine_srcs[m.name]
        s = m.vars[m.s]
        write(s.name, f"machine `{m.name}` (its `S`)", lambda msg: diags.error(msrc, SM, s.line, 1, msg))
        seen = set()
        for a in assignments(m):
            v = m.vars[a.var]
            if v.kind != M.ELEMENT or v.name in seen:
                continue
            seen.add(v.name)
            write(v.name, f"machine `{m.name}` ({os.path.basename(m.path)}:{a.line})",
                  lambda msg, a=a: diags.error(msrc, SM, a.line, a.col, msg))


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


def _uart_rate(board: Board, baud: int) -> Fraction | None:
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


def _baud_problem(board: Board, baud: int) -> str | None:
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


def _col_index(line: str, col: int) -> int:
    """The index in `line` of visual column `col`."""
    if "\t" not in line:
        return col - 1
    for i in range(len(line) + 1):
        if len(line[:i].expandtabs(8)) + 1 >= col:
            return i
    return len(line)
