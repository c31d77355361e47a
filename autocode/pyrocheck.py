"""Pyro channels (docs/safety.md): the `[pyro]` section of the application
config, checked, and the build-time proof that no machine can fire a
channel unarmed or outside the states it may fire in.

    [pyro]
    # output  settings
    drogue    arm=armSwitch  pulse=1  machine=mission  armed=Armed  fire=Apogee
    main      arm=armSwitch  continuity=mainSense min=0.5  pulse=1  machine=mission  armed=Armed  fire=Main

The proof works on a machine's state graph (`machine_graph`): its
transitions, each with the guards around it, and its assignments to
elements. A guard or an assigned value is decided where it is a
compile-time constant in binary64 and in binary32 alike (literals, and
locals that nothing writes and no parameter feeds); everything else is
possibly true. A statement after a transition, under a guard that is
always false, or in the `.step` of a state whose `.entry` always
transitions never runs and counts for nothing. For each channel:

- the states reached from the initial state without entering an armed
  state (`unarmed`, a breadth-first search, linear in states and
  transitions) never set its element true, and the initial state is not
  an armed state;
- every transition from one of those states into an armed state is
  guarded by the channel's arming inputs (`requires`), so the machine is
  never in an armed state unless each input read true when it entered;
- no state outside the channel's fire states sets it true;
- no other machine, and not the ground ([uplink]), writes it.

`pyro_report` lists, for every channel, every state and transition that
can fire it, with the arming path to it. Every problem is reported where
it is written: a `[pyro]` row's at its token, a firing at its assignment
in the `.sm`, with the path that reaches it unarmed."""

from __future__ import annotations

import math
import os
from collections import deque
from dataclasses import dataclass
from fractions import Fraction

from . import model as M
from .check import assignments
from .diagnostics import APP, SM
from .evaluate import NotConstant, compare, evaluate, local_values
from .lexer import ID, NUM
from .numeric import F32MODE, F64MODE, exact_literal, truthy
from .parser import show

KEYS = ("arm", "continuity", "min", "pulse", "machine", "armed", "fire")
REQUIRED = ("arm", "pulse", "machine", "armed", "fire")
LISTS = ("arm", "armed", "fire")  # keys that take a comma-separated list
PULSE_MIN, PULSE_MAX = Fraction(1, 100), Fraction(10)  # seconds
MAX_PULSE_RUNS = 0xFFFF  # fsw_io.h PyroGate::left: runs of the outputs task a pulse lasts
PATH_SHOWN = 8  # states a path in a diagnostic shows before it is cut


# ---- the state graph ------------------------------------------------------------

Cond = tuple  # (guard expression, the branch taken: True under `if`, False under `else`)


@dataclass(frozen=True)
class Edge:
    """A transition that can run: from state `src` to `dst` (indices), under `conds`."""
    src: int
    dst: int
    goto: M.Goto
    block: str  # "entry" or "step"
    conds: tuple[Cond, ...]


@dataclass(frozen=True)
class Write:
    """An assignment to an element that can run."""
    state: int  # index
    block: str  # "entry", "step" or "exit"
    assign: M.Assign
    fires: bool  # False: the value is a constant false (a bool element stays false)


@dataclass(frozen=True)
class Graph:
    machine: M.Machine
    edges: tuple[tuple[Edge, ...], ...]  # by source state index, in source order
    writes: dict[int, tuple[Write, ...]]  # by var index, in source order
    folder: "Folder"  # the machine's constants


class Folder:
    """Decides expressions whose value is known at compile time, in binary64
    and binary32 alike (a board computes in one, the host tools in the
    other): literals, and locals that no statement assigns and no parameter
    feeds (a parameter changes from the ground, docs/parameters.md)."""

    def __init__(self, m: M.Machine, assigned: set[int]):
        self.m = m
        varying: set[int] = set(assigned)
        for v in m.vars:  # in declaration order: an initial value reads earlier locals only
            if v.kind != M.LOCAL:
                varying.add(v.index)
            elif v.param is not None or (v.init is not None and _reads(v.init) & varying):
                varying.add(v.index)
        self.const = {v.index for v in m.vars if v.index not in varying}
        self.values = []
        for real in (F64MODE, F32MODE):
            try:
                vals = local_values(m, real)
            except (NotConstant, ArithmeticError, ValueError):
                vals = {}
            self.values.append((real, vals))

    def values_of(self, e: M.Expr) -> list[float] | None:
        """The value of `e` in each evaluation type, or None."""
        out = []
        for real, vals in self.values:
            def read(i, real=real, vals=vals):
                if i in self.const and i in vals:
                    return real.read(self.m.vars[i].type, vals[i])
                raise NotConstant(None)
            try:
                out.append(evaluate(e, real, read))
            except (NotConstant, ArithmeticError, ValueError):
                return None
        return out

    def truth(self, e: M.Expr) -> bool | None:
        """True or False when `e` is a constant that is true (or false) in
        both evaluation types; None otherwise."""
        vals = self.values_of(e)
        if vals is None:
            return None
        t = {truthy(x) for x in vals}
        return t.pop() if len(t) == 1 else None


def _reads(e: M.Expr) -> set[int]:
    out: set[int] = set()
    todo = [e]
    while todo:
        n = todo.pop()
        if type(n) is M.Ref:
            out.add(n.var)
        elif type(n) in (M.Neg, M.Not):
            todo.append(n.operand)
        elif type(n) in (M.Arith, M.Cmp, M.Logic):
            todo += (n.left, n.right)
        elif type(n) is M.ChainCmp:
            todo += n.operands
        elif type(n) is M.Roll:
            todo.append(n.arg)
    return out


def _assigned(m: M.Machine) -> set[int]:
    out: set[int] = set()
    todo = [s for st in m.states for s in (*st.entry, *st.step, *st.exit)]
    while todo:
        s = todo.pop()
        if type(s) is M.Assign:
            out.add(s.var)
        elif type(s) is M.If:
            todo += (*s.then, *s.orelse)
    return out


def machine_graph(m: M.Machine) -> Graph:
    """The transitions and element assignments of `m` that can run, in
    source order (linear in the machine's statements)."""
    folder = Folder(m, _assigned(m))
    edges: list[tuple[Edge, ...]] = []
    writes: dict[int, list[Write]] = {}
    for st in m.states:
        out: list[Edge] = []
        exits: list[Write] = []

        def scan(stmts, block: str, conds: tuple, sink) -> bool:
            """Records what `stmts` can run; True when they always transition."""
            for s in stmts:
                t = type(s)
                if t is M.Assign:
                    if m.vars[s.var].kind == M.ELEMENT:
                        sink.append(Write(st.index, block, s, folder.truth(s.expr) is not False))
                elif t is M.Goto:
                    out.append(Edge(st.index, s.state, s, block, conds))
                    return True  # the block stops here
                else:
                    c = folder.truth(s.cond)
                    if c is None:
                        a = scan(s.then, block, conds + ((s.cond, True),), sink)
                        b = scan(s.orelse, block, conds + ((s.cond, False),), sink)
                        if a and b:
                            return True
                    elif scan(s.then if c else s.orelse, block, conds, sink):
                        return True
            return False

        found: list[Write] = []
        if not scan(st.entry, "entry", (), found):  # `.step` runs when `.entry` did not transition
            scan(st.step, "step", (), found)
        if out:  # `.exit` runs only on a transition
            scan(st.exit, "exit", (), exits)
        for w in found + exits:
            writes.setdefault(w.assign.var, []).append(w)
        edges.append(tuple(out))
    return Graph(m, tuple(edges), {k: tuple(v) for k, v in writes.items()}, folder)


def search(g: Graph, blocked: frozenset[int] = frozenset()) -> dict[int, Edge | None]:
    """The states reached from the initial state without entering a state of
    `blocked` (indices), breadth first: each with the edge its first path
    takes into it (None for the initial state). Empty when the initial state
    is blocked. Linear in states + transitions."""
    if 0 in blocked or not g.edges:
        return {}
    seen: dict[int, Edge | None] = {0: None}
    todo = deque([0])
    while todo:
        for e in g.edges[todo.popleft()]:
            if e.dst not in seen and e.dst not in blocked:
                seen[e.dst] = e
                todo.append(e.dst)
    return seen


def unarmed(g: Graph, armed: frozenset[int]) -> dict[int, Edge | None]:
    """The states reached without passing through an armed state (indices)."""
    return search(g, armed)


def path(parents: dict[int, Edge | None], s: int) -> list[int]:
    """The states of the path `search` found to `s`, from the initial state."""
    out = [s]
    while parents[out[-1]] is not None:
        out.append(parents[out[-1]].src)
    return out[::-1]


def path_text(m: M.Machine, states: list[int]) -> str:
    """`Safe -> Abort -> Apogee`; a path of more than PATH_SHOWN states
    shows its first and last three."""
    names = [m.states[i].name for i in states]
    if len(names) > PATH_SHOWN:
        names = names[:3] + [f"... ({len(names) - 6:,} more)"] + names[-3:]
    return " -> ".join(names)


def requires(conds: tuple, a: int, folder: Folder) -> bool:
    """Whether taking the branches `conds` implies that variable `a` (a bool)
    is true: some guard on the way is `a`, `a and ...`, `not (not a or
    ...)`, `a == true`, `a != false`, ... Sound, not complete: a guard it
    cannot read counts as not requiring `a`."""
    return any(_implies(e, pol, a, folder) for e, pol in conds)


def _implies(e: M.Expr, pol: bool, a: int, folder: Folder) -> bool:
    """Whether `truthy(e) == pol` implies that bool variable `a` is true."""
    t = type(e)
    if t is M.Ref:
        return pol and e.var == a
    if t is M.Not:
        return _implies(e.operand, not pol, a, folder)
    if t is M.Logic:
        left, right = _implies(e.left, pol, a, folder), _implies(e.right, pol, a, folder)
        return (left or right) if (e.op == "and") == pol else (left and right)
    if t is M.Cmp:
        for ref, other, first in ((e.left, e.right, True), (e.right, e.left, False)):
            if type(ref) is not M.Ref or ref.var != a:
                continue
            vals = folder.values_of(other)
            if vals is None:
                continue
            # `a` reads 0 or 1: if the comparison with `a` false cannot give `pol`, `a` is true
            if all(compare(e.op, 0.0, c) != pol if first else compare(e.op, c, 0.0) != pol for c in vals):
                return True
    return False


def element_var(m: M.Machine, name: str) -> M.Var | None:
    """The machine's variable for the state vector element `name`: the one
    declared under that element name, not one whose `@alias` is `name` (a
    machine may call another element so: `bool led @alias armSwitch` is
    the LED, whatever it is called)."""
    return next((v for v in m.vars if v.kind == M.ELEMENT and v.name == name), None)


def _alias_note(m: M.Machine, name: str) -> str:
    """` (in machine `m`, `name` is an alias of element `x`, not the input)`
    when the machine calls another element `name`, else nothing."""
    v = m.var(name)
    if v is None or v.name == name:
        return ""
    return f" (in machine `{m.name}`, `{name}` is an alias of element `{v.name}`, not the input)"


# ---- the [pyro] section ---------------------------------------------------------

def check_pyro(rows, sv: M.StateVector, tasks: list[M.Task], machines: list[M.Machine], machine_srcs: dict,
               channels: list[M.Channel], uplink, r, task_rows=(), board=None,
               refused_outputs: set[str] = frozenset()) -> list[M.PyroChannel]:
    """The checked channels of the `[pyro]` rows, and the proof for each
    (every problem reported through `r`, appcheck's Report). `uplink`: the
    [uplink] rows, of which none may name a pyro channel; `task_rows`: the
    [tasks] rows (an `outputs` task refused for its own reason is no missing
    one); `board`: whose bootloader may drive a pin at a reset;
    `refused_outputs`: elements whose `o` row a table refused (said there)."""
    if not rows:
        return []
    outputs = [t for t in tasks if t.kind == "outputs"]
    if not outputs and not any(t.kind is not None and t.kind.text == "outputs" for t in task_rows):
        r.err(rows[0].element, "pyro channels need an `outputs` task in [tasks]: nothing would drive their pins")
    if outputs:
        _no_mode(max(outputs, key=lambda t: t.rate), rows, task_rows, r)
    tables = _Tables(channels, refused_outputs)
    declared: dict[str, int] = {}  # element name -> its row's line
    out: list[M.PyroChannel] = []
    owners: dict[str, tuple[int, int]] = {}  # element name -> (its machine, its row's line)
    for row in rows:
        ch, midx = _row(row, sv, outputs, machines, tables, declared, r, board)
        if midx is not None and row.element.text in declared and declared[row.element.text] == row.element.line:
            owners.setdefault(row.element.text, (midx, row.element.line))
        if ch is not None:
            out.append(ch)
    _other_writers(owners, machines, machine_srcs, r)
    app = os.path.basename(r.src.path)
    for u in uplink:  # (a row refused because no .dio row drives its element is no channel to name)
        if u.element.text in declared and u.element.text in tables.outputs:
            r.err(u.element, f"element `{u.element.text}` is pyro channel `{u.element.text}` (line "
                             f"{declared[u.element.text]}): the ground cannot write it (a SET over the uplink "
                             "would drive the charge whatever the arming and the machine's state)")
    _prove(out, machines, machine_srcs, app, r, {row.element.line: row.element.col for row in rows})
    return out


def _no_mode(task: M.Task, rows, task_rows, r) -> None:
    """The outputs task that drives the pyro pins (the first of the fastest,
    autocode/emit/app.py `pyro_task`) ends their pulses: it runs at every
    one of its cycles (a disabled or safed task runs no step, and a pin high
    then would stay high; the target refuses a MODE that would stop it), so
    it takes no `mode=`."""
    if task.mode is None:
        return
    row = next((t for t in task_rows if t.name.text == task.name), None)
    at = next((o.key for o in row.options.items if o.key.text == "mode"), row.name) if row is not None else None
    names = ", ".join(dict.fromkeys(p.element.text for p in rows))
    message = (f"task `{task.name}` drives the pyro channels ({names}) and counts their pulses down: it cannot "
               f"have a mode (it runs always: `fsw cmd mode {task.name} disabled` in a pulse would leave the charge's "
               "pin high, and the target refuses it); drop its `mode=`")
    if at is not None:
        r.err(at, message)
    else:
        r.diags.error(r.src, APP, task.line, 1, message)


class _Tables:
    """The I/O channels by element: digital outputs, digital and analog inputs."""

    def __init__(self, channels: list[M.Channel], refused_outputs=frozenset()):
        self.refused_outputs = refused_outputs  # elements of `o` rows their table refused
        self.outputs: dict[str, list[M.Channel]] = {}
        self.digital_in: dict[str, M.Channel] = {}
        self.analog_in: dict[str, M.Channel] = {}
        for c in channels:
            if c.direction == "o" and not c.analog:
                self.outputs.setdefault(c.element.name, []).append(c)
            elif c.direction == "i":
                (self.analog_in if c.analog else self.digital_in)[c.element.name] = c


def _where(c: M.Channel) -> str:
    return f"{os.path.basename(c.path)}:{c.line}"


def _row(row, sv, outputs, machines, tables: _Tables, declared: dict[str, int], r, board=None):
    """(the channel of a `[pyro]` row or None, the index of its machine or None)."""
    before = r.diags.error_count
    et = row.element
    if et.kind != ID:
        r.err(et, f"expected the pyro channel's output element, found {show(et)}")
        return None, None
    settings = {}
    for s in row.settings:
        k = s.key.text
        if k not in KEYS:
            r.err(s.key, f"unknown pyro setting `{k}`: expected one of {', '.join(KEYS)}")
        elif k in settings:
            r.err(s.key, f"`{k}=` given twice")
        else:
            settings[k] = s
    if row.stray is not None:
        r.err(row.stray.tok, row.stray.message)
    output = _output(et, sv, tables, declared, r)
    if output is not None and board is not None and output.pin_number in board.boot_driven:
        # the bootloader runs before the firmware: no gate holds the pin low then
        r.err(et, f"pyro channel `{et.text}` is on pin {output.pin} ({_where(output)}), which the {board.name}'s "
                  f"bootloader drives high at every reset, before the firmware and its gate run "
                  f"({board.boot_driven[output.pin_number]}): the charge would fire; wire it to another pin")
        output = None
    missing = [k for k in REQUIRED if k not in settings]
    if missing and row.stray is None:  # a malformed row: what follows its stray token is not read
        r.err(et, f"pyro channel `{et.text}` needs " + ", ".join(f"`{k}=`" for k in missing))
    for k, s in settings.items():
        if k not in LISTS and len(s.values) > 1:
            r.err(s.values[1], f"`{k}=` takes one value")
    arm = _arm(settings.get("arm"), sv, tables, r)
    continuity, cmin = _continuity(settings.get("continuity"), settings.get("min"), sv, tables, r)
    pulse = _pulse(settings.get("pulse"), outputs, r)
    midx = _machine(settings.get("machine"), machines, r)
    m = machines[midx] if midx is not None else None
    armed = _states(settings.get("armed"), m, r)
    fire = _states(settings.get("fire"), m, r)
    if m is not None and armed and m.states[0].id in armed:
        tok = next(t for t in settings["armed"].values if t.text == m.states[0].name)
        r.err(tok, f"state `{tok.text}` is the initial state of machine `{m.name}`: it cannot be an armed state "
                   "(the machine would start armed, without an arming input ever read)")
    if r.diags.error_count != before or output is None or m is None:
        return None, midx
    return M.PyroChannel(output, arm, continuity, cmin, pulse, midx, armed, fire, et.line), midx


def _output(et, sv, tables: _Tables, declared: dict[str, int], r) -> M.Channel | None:
    name = et.text
    e = sv.find(name)
    if e is None:
        problem = f"unknown element `{name}`"
    elif name in declared:
        problem = f"pyro channel `{name}` is declared twice (first on line {declared[name]})"
    elif name not in tables.outputs and name in tables.refused_outputs:  # its row's own error said it
        problem = None
    elif name not in tables.outputs:
        problem = (f"`{name}` is not a digital output: a pyro channel is a bool element that an `o` row of a "
                   ".dio table drives")
    elif len(tables.outputs[name]) > 1:
        first, second = tables.outputs[name][:2]
        problem = (f"`{name}` drives two pins ({_where(first)} and {_where(second)}): a pyro channel is one "
                   "output")
    elif name in tables.digital_in or name in tables.analog_in:
        c = tables.digital_in.get(name) or tables.analog_in[name]
        problem = (f"`{name}` is also read from a pin, by input channel {_where(c)}: a pyro channel's element "
                   "is written by its machine alone")
    else:
        declared[name] = et.line
        return tables.outputs[name][0]
    if e is not None and name not in declared:
        declared[name] = et.line
    if problem is not None:
        r.err(et, problem)
    return None


def _arm(s, sv, tables: _Tables, r) -> tuple[M.Channel, ...]:
    if s is None:
        return ()
    out: list[M.Channel] = []
    seen: set[str] = set()
    for t in s.values:
        if t.text in seen:
            r.err(t, f"`{s.key.text}=` lists `{t.text}` twice")
        elif sv.find(t.text) is None or t.kind != ID:
            r.err(t, f"unknown element `{t.text}`")
        elif t.text not in tables.digital_in:
            r.err(t, f"arming input `{t.text}` is not a digital input: an arming input is a bool element that an "
                     "`i` row of a .dio table reads (the flyer's switch), so that the ground cannot set it")
        else:
            out.append(tables.digital_in[t.text])
        seen.add(t.text)
    return tuple(out)


def _continuity(s, smin, sv, tables: _Tables, r) -> tuple[M.Channel | None, Fraction | None]:
    chan = None
    if s is not None:
        t = s.values[0]
        if sv.find(t.text) is None or t.kind != ID:
            r.err(t, f"unknown element `{t.text}`")
        elif t.text not in tables.analog_in:
            r.err(t, f"continuity input `{t.text}` is not an analog input: it is an element that an `i` row of an "
                     ".aio table reads (the igniter, through its sense resistor)")
        else:
            chan = tables.analog_in[t.text]
        if smin is None:
            r.err(s.key, "`continuity=` needs `min=`, the reading at or above which the igniter is intact")
    q = None
    if smin is not None:
        t = smin.values[0]
        q = exact_literal(t.text) if t.kind == NUM else None
        if q is None or abs(q) > 10**9:
            r.err(t, "`min=` takes a number: the continuity input's reading, in its element's units, at or above "
                     "which the igniter is intact")
            q = None
        elif smin.negative:
            q = -q
        if s is None:
            r.err(smin.key, "`min=` is the continuity input's threshold: it needs `continuity=`")
    return chan, q


def _pulse(s, outputs: list[M.Task], r) -> Fraction:
    if s is None:
        return Fraction(1)
    t = s.values[0]
    q = exact_literal(t.text) if t.kind == NUM and not s.negative else None
    if q is None or not PULSE_MIN <= q <= PULSE_MAX:
        shown = ("-" if s.negative else "") + (t.text if len(t.text) <= 40 else t.text[:37] + "...")
        r.err(t, f"`pulse=` takes the seconds the channel stays fired: a number from {float(PULSE_MIN):g} to "
                 f"{float(PULSE_MAX):g}, found `{shown}`")
        return Fraction(1)
    if outputs:
        fastest = max(outputs, key=lambda task: task.rate)
        if q < 1 / fastest.rate:
            r.err(t, f"a pulse of {t.text} s is shorter than a period of the fastest `outputs` task, `{fastest.name}` "
                     f"({float(1 / fastest.rate):g} s), which drives the pin and ends the pulse")
        elif math.ceil(q * fastest.rate) > MAX_PULSE_RUNS:  # the gate counts the pulse down in 16 bits
            r.err(t, f"a pulse of {t.text} s is {math.ceil(q * fastest.rate):,} runs of the fastest `outputs` task, "
                     f"`{fastest.name}` ({_hz(fastest.rate)} Hz), which counts the pulse down: at most "
                     f"{MAX_PULSE_RUNS:,} runs, {float(Fraction(MAX_PULSE_RUNS) / fastest.rate):g} s at that rate")
    return q


def _hz(rate: Fraction) -> str:
    return str(rate.numerator) if rate.denominator == 1 else f"{float(rate):g}"


def _machine(s, machines: list[M.Machine], r) -> int | None:
    if s is None:
        return None
    names = [m.name for m in machines]
    t = s.values[0]
    if t.text not in names or t.kind != ID:
        r.err(t, f"`machine=` takes the name of a machine from [configs] ({', '.join(names) or 'none'})")
        return None
    return names.index(t.text)


def _states(s, m: M.Machine | None, r) -> tuple[int, ...]:
    if s is None or m is None:
        return ()
    by_name = {st.name: st.id for st in m.states}
    out: list[int] = []
    for t in s.values:
        if t.text not in by_name or t.kind != ID:
            r.err(t, f"machine `{m.name}` has no state `{t.text}` (states: {', '.join(by_name)})")
        elif by_name[t.text] in out:
            r.err(t, f"`{s.key.text}=` lists `{t.text}` twice")
        else:
            out.append(by_name[t.text])
    return tuple(out)


def _other_writers(owners: dict[str, tuple[int, int]], machines, machine_srcs, r) -> None:
    """A pyro element is written by its channel's machine alone: each other
    machine's first assignment to it is refused where it is written."""
    for i, m in enumerate(machines):
        seen: set[str] = set()
        for a in assignments(m):
            v = m.vars[a.var]
            if v.kind != M.ELEMENT or v.name not in owners or v.name in seen or owners[v.name][0] == i:
                continue
            seen.add(v.name)
            mine, line = owners[v.name]
            r.diags.error(machine_srcs[m.name], SM, a.line, a.col,
                          f"element `{v.name}` is pyro channel `{v.name}` ({os.path.basename(r.src.path)}:{line}), "
                          f"written by machine `{machines[mine].name}` alone: machine `{m.name}` cannot write it "
                          "(a second writer could fire the charge, or cut its pulse short, in any of its own states)")


# ---- the proof ------------------------------------------------------------------

def _names(items) -> str:
    return ", ".join(items)


def _prove(chans: list[M.PyroChannel], machines, machine_srcs, app: str, r, cols: dict[int, int]) -> None:
    graphs: dict[int, Graph] = {}
    guards: dict[tuple, list] = {}  # (machine, goto line, col) -> [edge, missing inputs, channel names]
    for ch in chans:
        m = machines[ch.machine]
        if ch.machine not in graphs:
            graphs[ch.machine] = machine_graph(m)
        g = graphs[ch.machine]
        msrc = machine_srcs[m.name]
        armed = frozenset(i - 1 for i in ch.armed)
        fire = frozenset(i - 1 for i in ch.fire)
        parents = unarmed(g, armed)
        name = ch.element.name
        where = f"{app}:{ch.line}"
        var = element_var(m, name)
        for w in (g.writes.get(var.index, ()) if var is not None and var.kind == M.ELEMENT else ()):
            if not w.fires:
                continue
            st = m.states[w.state]
            outside, reached = w.state not in fire, w.state in parents
            if not outside and not reached:
                continue
            a = w.assign
            fires_in = _names(m.states[i].name for i in sorted(fire))
            armed_in = _names(m.states[i].name for i in sorted(armed))
            way = path_text(m, path(parents, w.state)) if reached else ""
            if outside and reached:
                r.diags.error(msrc, SM, a.line, a.col,
                              f"pyro channel `{name}` ({where}) can fire here, in state `{st.name}`, which is not one "
                              f"of its fire states ({fires_in}) and is reached without passing through an armed "
                              f"state ({armed_in}): {way}")
            elif outside:
                r.diags.error(msrc, SM, a.line, a.col,
                              f"pyro channel `{name}` ({where}) can fire here, in state `{st.name}`, which is not one "
                              f"of its fire states ({fires_in})")
            else:
                r.diags.error(msrc, SM, a.line, a.col,
                              f"pyro channel `{name}` ({where}) can fire here, in state `{st.name}`, which is reached "
                              f"without passing through an armed state ({armed_in}): {way}")
        everywhere = search(g)
        if not any(w.fires and w.state in everywhere
                   for w in (g.writes.get(var.index, ()) if var is not None else ())):
            r.diags.warning(r.src, APP, ch.line, cols.get(ch.line, 1),
                            f"pyro channel `{name}` never fires: no state of machine `{m.name}` that its initial state "
                            f"leads to sets `{name}` true")
        arm_vars = []
        for c in ch.arm:
            v = element_var(m, c.element.name)
            arm_vars.append((c.element.name, v.index if v is not None else None))
        for s in parents:
            for e in g.edges[s]:
                if e.dst not in armed:
                    continue
                cont = ch.continuity.element.name if ch.continuity is not None else None
                cv = element_var(m, cont) if cont is not None else None
                if cont is not None and (cv is None or not any(cv.index in _reads(c) for c, _ in e.conds)):
                    # arming without a look at the igniter: warned once per transition and channel
                    r.diags.warning(msrc, SM, e.goto.line, e.goto.col,
                                    f"transition from `{m.states[e.src].name}` into armed state "
                                    f"`{m.states[e.dst].name}` arms pyro channel `{name}` ({where}) without reading "
                                    f"its continuity input `{cont}`: an open igniter would be armed (guard it, e.g. "
                                    f"`... and {cont} >= {_decimal(ch.continuity_min)}`, docs/safety.md)")
                missing = [n for n, i in arm_vars if i is None or not requires(e.conds, i, g.folder)]
                if not missing:
                    continue
                key = (ch.machine, e.goto.line, e.goto.col)
                entry = guards.setdefault(key, [e, [], []])
                entry[1] += [n for n in missing if n not in entry[1]]
                entry[2].append(f"`{name}` ({where})")
    for (midx, _, _), (e, missing, chs) in sorted(guards.items(), key=lambda kv: kv[0]):
        m = machines[midx]
        need = " and ".join(f"`{n}`" for n in missing) + "".join(_alias_note(m, n) for n in missing)
        what = "pyro channel" if len(chs) == 1 else "pyro channels"
        r.diags.error(machine_srcs[m.name], SM, e.goto.line, e.goto.col,
                      f"transition from `{m.states[e.src].name}`, reached unarmed, into armed state "
                      f"`{m.states[e.dst].name}` does not require {need}, which arms {what} {_names(chs)}: "
                      f"guard it with the input, e.g. `{' and '.join(missing)}: -> {m.states[e.dst].name}`")


# ---- the report -----------------------------------------------------------------

def pyro_report(app: M.Application) -> str:
    """For every pyro channel of a checked application: its wiring, the
    states reached unarmed, the arming transitions, and every state and
    transition that can fire it with the shortest path to it (`fsw check
    --pyro-report`; docs/safety.md). Deterministic: source order throughout."""
    from .unparse import model_expr

    name = os.path.basename(app.path)
    if not app.pyro:
        return f"{name}: no pyro channels ([pyro] declares them: docs/safety.md)\n"
    lines = [f"{name}: {len(app.pyro)} pyro channel{'s' if len(app.pyro) != 1 else ''}"]
    graphs: dict[int, Graph] = {}
    for ch in app.pyro:
        m = app.machines[ch.machine]
        if ch.machine not in graphs:
            graphs[ch.machine] = machine_graph(m)
        g = graphs[ch.machine]
        sm = os.path.basename(m.path)
        armed = frozenset(i - 1 for i in ch.armed)
        parents = unarmed(g, armed)
        everywhere = search(g)
        states = lambda ids: ", ".join(m.states[i - 1].name for i in ids)  # noqa: E731
        out = ch.output
        lines += ["", f"pyro channel {ch.element.name} ({name}:{ch.line})",
                  f"  output:      pin {out.pin} ({_where(out)}), pulse {_decimal(ch.pulse)} s",
                  "  arming:      " + " and ".join(f"{c.element.name} (pin {c.pin}, {_where(c)})" for c in ch.arm)
                  + " reading true",
                  "  continuity:  " + (f"{ch.continuity.element.name} (pin {ch.continuity.pin}, "
                                       f"{_where(ch.continuity)}) at least {_decimal(ch.continuity_min)}"
                                       if ch.continuity is not None else "none declared"),
                  f"  machine:     {m.name}; armed states {states(ch.armed)}; fire states {states(ch.fire)}",
                  "  unarmed:     " + ", ".join(m.states[s].name for s in sorted(parents))
                  + " (reached without an armed state: none sets it true)"]
        arming = [e for s in sorted(parents) for e in g.edges[s] if e.dst in armed]
        lines.append("  arming transitions (each requires " + " and ".join(c.element.name for c in ch.arm) + "):")
        lines += [f"    {m.states[e.src].name} -> {m.states[e.dst].name}  {sm}:{e.goto.line}" for e in arming] \
            or ["    none"]
        var = element_var(m, ch.element.name)
        fires = [w for w in g.writes.get(var.index, ()) if w.fires] if var is not None else []
        live = [w for w in fires if w.state in everywhere]
        lines.append("  states that can fire it:")
        by_state: dict[int, list[Write]] = {}
        for w in live:
            by_state.setdefault(w.state, []).append(w)
        for s in sorted(by_state):
            for w in by_state[s]:
                a = w.assign
                lines.append(f"    {m.states[s].name}  .{w.block}  {sm}:{a.line}  "
                             f"{m.vars[a.var].name} = {model_expr(a.expr, m)}")
            lines.append(f"      arming path: {' -> '.join(m.states[i].name for i in path(everywhere, s))}")
        if not by_state:
            lines.append("    none: the channel never fires")
        dead = sorted({w.state for w in fires if w.state not in everywhere})
        if dead:
            lines.append("    (never reached, so never fire it: " + ", ".join(m.states[s].name for s in dead) + ")")
        lines.append("  transitions that can fire it:")
        entering = {s for s, ws in by_state.items() if any(w.block != "exit" for w in ws)}
        leaving = {s for s, ws in by_state.items() if any(w.block == "exit" for w in ws)}
        rows = []
        for s in sorted(everywhere):
            for e in g.edges[s]:
                why = []
                if e.src in leaving:
                    why.append(f"leaves {m.states[e.src].name}: .exit")
                if e.dst in entering:
                    why.append(f"enters {m.states[e.dst].name}")
                if why:
                    rows.append(f"    {m.states[e.src].name} -> {m.states[e.dst].name}  {sm}:{e.goto.line}  "
                                f"({'; '.join(why)})")
        lines += rows or ["    none"]
    return "\n".join(lines) + "\n"


def _decimal(q: Fraction) -> str:
    """A whole number as such (`1`), any other to 6 significant digits."""
    if q.denominator == 1:
        return str(q.numerator)
    f = float(q)
    return f"{f:.6g}"
