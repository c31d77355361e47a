"""Each machine as straight-line C++ over the runtime: `<name>.gen.h` and
`<name>.gen.cpp`.

Generation is a pure function: it returns `{relative path: text}` and only
the CLI writes files. Output is byte-reproducible: no timestamps, sorted
iteration, stable names. Generated code is tables and straight-line user
logic; every algorithm lives in the hand-written runtime (firmware/src)."""

from __future__ import annotations

import re

from .. import model as M
from ..check import model_children, stmt_exprs
from ..cnames import enumerator
from ..evaluate import NotConstant, evaluate, local_values
from ..numeric import Real, to_type
from ..unparse import model_expr
from .common import (banner, basename, c_ident, parens, real_check, real_literal, value_bytes, version_check,
                     window_type)
from .expr import ExprEmitter, sum_key
from .fastpaths import no_reads


def _packed(vs, values) -> tuple[dict[int, int], int, bytes]:
    """Variables laid end to end, little-endian like elements: (offset by
    var index, bytes in all, their initial bytes)."""
    offsets: dict[int, int] = {}
    size = 0
    for v in vs:
        offsets[v.index] = size
        size += v.type.size
    return offsets, size, b"".join(value_bytes(v.type, values[v.index]) for v in vs)


_LEAVES = (M.Ref, M.Const)  # (most of an expression's nodes: nothing under them)


def _rolls(e: M.Expr) -> list[M.Roll]:
    """Every window read in an expression, nested ones included."""
    out, todo = [], [e]
    while todo:
        n = todo.pop()
        if type(n) in _LEAVES:
            continue
        if isinstance(n, M.Roll):
            out.append(n)
        todo.extend(model_children(n))
    return out


def window_needs(m: M.Machine) -> tuple[dict[int, int], dict[int, int]] | None:
    """For each state (index), the windows its step must sample, as a bit
    set: those a state it can still reach reads (itself included), and for
    each window (index) its bit. In any other state no step can read a
    window again (a state is left only by a transition; a reset and a
    resume start the windows from empty), so its samples there are never
    seen (spec 4.6 step 3 made unobservable). None when some window's
    argument reads another window (then every state samples every window,
    as the spec words it).

    Linear in the machine's size (`still_read`): a 2,000-state ring with
    4,000 windows in well under a second, where a reachability search from
    each state and a set of states for each window took 2.7 s."""
    if any(_rolls(w.arg) for w in m.windows):
        return None
    if not m.windows:  # nothing to sample (and no graph to build)
        return {st.index: 0 for st in m.states}, {}
    bit = {w.index: 1 << k for k, w in enumerate(m.windows)}
    reads: dict[int, int] = {}  # state -> the windows its blocks read
    succ: dict[int, list[int]] = {}
    for st in m.states:  # (gotos, stmt_exprs and _rolls in one walk of the state's statements)
        targets: set[int] = set()
        exprs = []
        stmts = [*st.entry, *st.step, *st.exit]
        while stmts:
            x = stmts.pop()
            t = type(x)
            if t is M.Assign:
                exprs.append(x.expr)
            elif t is M.Goto:
                targets.add(x.state)
            elif t is M.If:
                exprs.append(x.cond)
                stmts += x.then
                stmts += x.orelse
        mask = 0
        while exprs:
            e = exprs.pop()
            t = type(e)
            if t in _LEAVES:
                continue
            if t is M.Roll:
                mask |= bit[e.window]
            exprs += model_children(e)
        succ[st.index] = sorted(targets)
        reads[st.index] = mask
    return still_read(succ, reads), bit


def still_read(succ: dict[int, list[int]], reads: dict[int, int]) -> dict[int, int]:
    """For each node of the graph `succ` (node -> its successors), the
    union of `reads` (node -> a bit set) over the nodes reachable from it,
    itself included: the same for every node of a strongly connected
    component, worked out over the components' graph (networkx's
    condensation, a DAG) from the ones that lead nowhere else back."""
    import networkx as nx

    g = nx.DiGraph()
    g.add_nodes_from(succ)
    g.add_edges_from((s, t) for s, ts in succ.items() for t in ts)
    dag = nx.condensation(g)
    need: dict[int, int] = {}  # component -> the union
    for c in reversed(list(nx.topological_sort(dag))):
        mask = 0
        for s in dag.nodes[c]["members"]:
            mask |= reads[s]
        for d in dag.successors(c):
            mask |= need[d]
        need[c] = mask
    return {s: need[c] for s, c in dag.graph["mapping"].items()}


# roll_min, roll_max and roll_range of one argument over one N up to this
# share one ring of the last N samples (fsw::RollMinMaxN) when it keeps more
# than one extreme: a read scans the N samples (at most 16 key comparisons
# of binary32 samples on AVR, no float routine).
SHARED_EXTREMES_MAX_N = 16


def shared_extremes(m: M.Machine, ex: ExprEmitter) -> dict[int, tuple[int, str]]:
    """The windows kept in one ring with others (fsw::RollMinMaxN): for
    each, (the index of the window that holds the ring, which is the first
    of them, and its read: `least()`, `greatest()` or `range()`). The windows of
    roll_min, roll_max and roll_range of one argument (of no window of its
    own) and one N of at most SHARED_EXTREMES_MAX_N, two of them or more,
    or a roll_range alone (two extremes of its own): the same values bit
    for bit, in 4N + 2 bytes (binary32 R, N <= 255) where a RollMinN and a
    RollMaxN take 10N + 8."""
    groups: dict[tuple[str, int], list] = {}
    for w in m.windows:
        if w.func in ("min", "max", "range") and w.size <= SHARED_EXTREMES_MAX_N and not _rolls(w.arg):
            groups.setdefault((ex.value(w.arg), w.size), []).append(w)
    out: dict[int, tuple[int, str]] = {}
    for ws in groups.values():
        if len(ws) >= 2 or ws[0].func == "range":
            for w in ws:
                out[w.index] = (ws[0].index, {"min": "least()", "max": "greatest()", "range": "range()"}[w.func])
    return out


def declared_windows(m: M.Machine, ex: ExprEmitter, shared: dict | None = None) -> list[tuple[M.Window, str]]:
    """The windows a machine's code declares, with their types: each of its
    own, and one ring for those kept together (`shared`: shared_extremes,
    worked out here when not given)."""
    if shared is None:
        shared = shared_extremes(m, ex)
    out = []
    for w in m.windows:
        if w.index not in shared:
            out.append((w, window_type(w)))
        elif shared[w.index][0] == w.index:
            out.append((w, f"fsw::RollMinMaxN<{w.size}>"))
    return out


def windows_watched(m: M.Machine) -> bool:
    """Whether a kept machine's rolling windows are a watched span of the
    flight's save (fsw::ResumeWatch, docs/safety.md): copied only while
    they change. True when some state samples none of them (window_needs):
    there they keep their bytes, cycle after cycle (the rocket's mission,
    from its coast on). Its code then sets `win_changed` at every push and
    at its reset."""
    return bool(m.windows) and _watched(window_needs(m))


def _watched(needs) -> bool:
    """windows_watched of a machine with windows, from its window_needs."""
    return needs is not None and any(mask == 0 for mask in needs[0].values())


def stored_locals(m: M.Machine, real: Real, scriptable: bool = False) -> list:
    """The locals a machine keeps in memory (its `loc` array): those that
    change, and every one in a scriptable build; parameters are apart."""
    ex = ExprEmitter(m, real, scriptable)
    params = [] if scriptable else [v for v in m.vars if v.param is not None]
    return [v for v in m.vars if v.kind == M.LOCAL and v.index not in ex.consts and v not in params]


def cached_sums(m: M.Machine, real: Real, scriptable: bool = False) -> list[tuple[tuple, M.Arith, set[int]]]:
    """The sums a machine keeps in slots of their own after its locals, in
    the order first read: `x + c`, `x - c` or `c - x` (expr.sum_key) that a
    .step reads, of an F32 local x that no .step writes (its .entry or .exit
    blocks may: once a state), with R binary32. A slot holds the sum of x's
    stored value and c, worked out at each write of x and in the locals'
    initial bytes; a step reads it where it added (`still + STILL_BAND`, the
    rocket's mission in Descent: two float routines a step less). Not in a
    scriptable build, where a script writes locals. (sum_key, the first
    expression, the indexes of the states whose .step reads it) each."""
    if scriptable or real.bits != 32:
        return []
    ex = ExprEmitter(m, real, scriptable)
    stored = {v.index for v in stored_locals(m, real, scriptable)}
    in_step: set[int] = set()
    for st in m.states:
        in_step |= _assigned(st.step)
    found: dict[tuple, M.Arith] = {}
    readers: dict[tuple, set[int]] = {}

    def visit(e, state: int) -> None:
        t = type(e)
        if t in _LEAVES or t is M.Roll:  # (a window's argument is the window's sampling, not the step's)
            return
        if t is M.Arith:
            key = sum_key(e, ex.known)
            if key is not None and key[1] in stored and key[1] not in in_step:
                v = m.vars[key[1]]
                if v.type.kind == "float" and v.type.size == 4:
                    found.setdefault(key, e)
                    readers.setdefault(key, set()).add(state)
                    return
        for c in model_children(e):
            visit(c, state)

    for st in m.states:
        for e in stmt_exprs(st.step):
            visit(e, st.index)
    return [(key, e, readers[key]) for key, e in found.items()]


def _entered_before_read(m: M.Machine, var: int, readers: set[int]) -> bool:
    """Whether every state in `readers` (those whose .step reads a sum of
    `var`: only a .step reads its slot, cached_sums) writes `var` at the top
    level of its .entry: a state's first step runs its .entry first, so the
    slot is worked out before any read of it and its initial bytes are
    never read."""
    return all(any(isinstance(st, M.Assign) and st.var == var for st in m.states[i].entry) for i in readers)


# The bytes of the state vector, the locals or the parameters a machine's
# state functions access directly (not through an out-of-line call) from
# which they take that area through a pointer register.
BY_POINTER_BYTES = 8
_DIRECT = re.compile(r"(?:store_bool|read_bool|load_bool|read_[UI](\d+)|write_[UI](\d+)|load<u?int(\d+)_t>|"
                     r"store<u?int(\d+)_t>)\((sv|loc|prm) \+ ")  # (at a word's start: _direct_bytes)
_WORD = re.compile(r"\w")


def _direct_bytes(text: str) -> dict[str, int]:
    """For each area (sv, loc, prm), the bytes of it that the lines of
    state functions in `text` read or write directly: a bool or an integer,
    not through a call. One search of all the lines at once (no access
    spans two lines); an access is a whole word (`\\b` in the pattern
    would make the search try every position: three times slower)."""
    n: dict[str, int] = {}
    word = _WORD.match
    for m in _DIRECT.finditer(text):
        at = m.start()
        if at and word(text, at - 1):
            continue
        a, b, c, d, area = m.groups()
        bits = a or b or c or d
        n[area] = n.get(area, 0) + (int(bits) // 8 if bits else 1)
    return n


def emit_machine(m: M.Machine, real: Real, scriptable: bool = False,
                 ns: str = "fsw_gen", leave: bool = False, kept: bool = False) -> dict[str, str]:
    """`<name>.gen.h` and `<name>.gen.cpp` for one machine. `scriptable`
    keeps every local in memory, for a state script that writes locals;
    otherwise locals that never change are folded into the code. `ns` is
    the outer namespace (the state vector's, see emit_sv). `leave` adds
    leave(), the current state's .exit, for a machine that an uploaded
    image may take over from (`[reload]`, docs/reload.md). `kept` puts
    the rolling windows in one object, `win`, declared in the header, that
    the resume keeps with the locals (docs/safety.md)."""
    name = c_ident(m.name)
    src = basename(m.path)
    wp = "win.w" if kept and m.windows else "w"  # how the code names window i: f"{wp}{i}"
    ex = ExprEmitter(m, real, scriptable, windows=wp)
    shared = shared_extremes(m, ex)
    declared = declared_windows(m, ex, shared)
    needs = window_needs(m) if m.windows else None  # (a machine without windows samples none)
    watched = wp != "w" and _watched(needs)
    ex.window_reads = {i: f"{holder}.{read}" for i, (holder, read) in shared.items()}

    served: dict[int, list[M.Window]] = {}  # holder -> the windows it serves, in file order
    for x in m.windows:
        if x.index in shared:
            served.setdefault(shared[x.index][0], []).append(x)

    def what(w: M.Window) -> str:  # the roll_* calls a declared window serves
        return ", ".join(f"{src}:{x.line} roll_{x.func}" for x in served.get(w.index) or [w])

    values = local_values(m, real)
    params = [] if scriptable else [v for v in m.vars if v.param is not None]
    stored = [v for v in m.vars if v.kind == M.LOCAL and v.index not in ex.consts and v not in params]
    offsets, size, init_bytes = _packed(stored, values)
    sums = cached_sums(m, real, scriptable)
    step_sums: dict[tuple, str] = {}  # what the .step functions read of them
    for k, (key, node, readers) in enumerate(sums):
        x = m.vars[key[1]]
        if _entered_before_read(m, x.index, readers):
            value = 0.0  # never read before a write of x: 0, and the locals stay in .bss where they were
        else:
            # the sum of x's initial value as stored (an F32: never a NaN) and c
            start = real.read(x.type, values[x.index])
            value = evaluate(node, real, lambda i: start if i == x.index else ex.consts[i])
        init_bytes += value_bytes(x.type, to_type(x.type, value))
        step_sums[key] = f"fsw::read_F32(loc + C_{k})"
        ex.sum_writes.setdefault(x.index, []).append((f"C_{k}", node))
    sum_offsets = [size + 4 * k for k in range(len(sums))]
    size += 4 * len(sums)
    poff, psize, param_bytes = _packed(params, values)
    assert m.states[0].id == 1, "a zero fsw::Machine starts in state 1"
    guard = f"{ns.upper()}_{name.upper()}_H"
    h = [banner([m.path, m.sv.path], m.sv), f"#ifndef {guard}", f"#define {guard}", "",
         '#include "fswkit.h"', "", f"namespace {ns} {{", f"namespace {name} {{", "",
         f"// State ids of {src}, in file order.", "enum : uint32_t {"]
    for st in m.states:
        h.append(f"    S_{st.name} = {st.id},")
    h += ["};", f"static const uint32_t kStates = {len(m.states)};", "",
          "extern fsw::Machine machine;  // state, entry time, T"]
    if stored:
        h.append("// Locals kept in memory, packed little-endian like elements.")
        h.append("enum : uint16_t {")
        for v in stored:
            h.append(f"    {enumerator('L_', v.name)} = {offsets[v.index]},  // {v.type.name}")
        for k, (key, node, _) in enumerate(sums):
            h.append(f"    C_{k} = {sum_offsets[k]},  // F32: {model_expr(node, m)} ({src}:{node.line}), "
                     f"worked out where {m.vars[key[1]].name} is written")
        h.append("};")
        h.append(f"static const uint16_t kLocSize = {size};")
        h.append("extern uint8_t loc[kLocSize];")
    if params:
        h.append("// Parameters (docs/parameters.md): the ground changes them, the parameter")
        h.append("// store keeps them in EEPROM; the machine only reads them. Defaults until boot.")
        h.append("enum : uint16_t {")
        for v in params:
            h.append(f"    {enumerator('P_', v.name)} = {poff[v.index]},  // {v.type.name}")
        h.append("};")
        h.append(f"static const uint16_t kPrmSize = {psize};")
        h.append("extern uint8_t prm[kPrmSize];")
    if wp != "w":
        h.append("// Its rolling windows, kept across a reset in flight with its locals (docs/safety.md).")
        h.append("struct Windows {")
        for w, wtype in declared:
            h.append(f"    {wtype} w{w.index};  // {what(w)}")
        h.append("};")
        h.append("extern Windows win;")
        if watched:
            h.append("extern uint8_t win_changed;  // set when a window changes: the flight's save copies them again")
    h.append("")
    h.append("// One step (spec 4.6). kErrTime when G did not increase: nothing changed.")
    h.append("FSW_MUST_CHECK fsw::Result step();")
    h.append("// Back to the state before the first step, starting in `initial`.")
    h.append("void reset(uint32_t initial);")
    if leave:
        h.append("// The current state's .exit, when it was entered and not yet left: an")
        h.append("// uploaded machine takes over from this one (docs/reload.md).")
        h.append("void leave();")
    h += ["", f"}}  // namespace {name}", f"}}  // namespace {ns}", "", f"#endif  // {guard}", ""]

    c = [banner([m.path, m.sv.path], m.sv), f'#include "{name}.gen.h"', '#include "sv.gen.h"', "",
         version_check(f"{name}.gen.cpp"), real_check(src, real),
         f"namespace {ns} {{", f"namespace {name} {{", "",
         "fsw::Machine machine;  // zero: before the first step in the first state (fsw::machine_begin)"]
    if stored:
        c.append(f"uint8_t loc[kLocSize] = {{{', '.join(str(b) for b in init_bytes)}}};")
    if params:
        c.append(f"uint8_t prm[kPrmSize] = {{{', '.join(str(b) for b in param_bytes)}}};")
    if wp != "w":
        c.append("Windows win;  // every window empty")
    if watched:
        c.append("uint8_t win_changed;  // fsw::ResumeWatch: the save copies the windows while they change")
    c += ["", "namespace {", ""]
    if wp == "w":
        for w, wtype in declared:
            c.append(f"{wtype} w{w.index};  // {what(w)}")
        if m.windows:
            c.append("")
    if stored:
        c.append(f"const uint8_t kLocInit[kLocSize] = {{{', '.join(str(b) for b in init_bytes)}}};")
        c.append("")
    # A state id as entry and step code return it: the narrowest type that
    # holds them all (an 8-bit MCU passes and tests it in fewer instructions).
    sid = "uint8_t" if len(m.states) < 0x100 else "uint16_t" if len(m.states) < 0x10000 else "uint32_t"
    bodies = []
    for st in m.states:
        for label in ("entry", "step", "exit"):
            stmts = getattr(st, label)
            if not stmts:
                continue
            body: list[str] = []
            held = _Held() if real.bits == 32 else None
            ex.held = {}
            ex.cached = step_sums if label == "step" else {}
            _block(stmts, ex, "    ", body, src, m, label != "exit", held)
            keep = held.worth(body) if held is not None else set()
            if held is not None and len(keep) < len(held.decls):  # again, holding only where it paid
                body, ex.held = [], {}
                _block(stmts, ex, "    ", body, src, m, label != "exit", _Held(keep))
            ex.held = {}
            ex.cached = {}
            # T is the same for the whole step: one call for it where the
            # function tests it twice or more
            t32 = "fsw::machine_T32(machine)"
            text = "\n".join(body)  # (its lines, one text from here on)
            if text.count(t32) >= 2:
                text = "    const uint32_t t32 = " + t32 + ";  // T, saturated to 32 bits\n" + text.replace(t32, "t32")
            bodies.append((st, label, text))
    # The state vector and the locals each reach the state functions as an
    # argument (`svp`, `locp`), which step() took through fsw::by_pointer,
    # when they read or write enough of its bytes directly (not through an
    # out-of-line call: bools, integers): inlined into step(), they then
    # address those bytes through a pointer register, 2 bytes of flash a
    # byte where the absolute address took 4 (66 B of the rocket's mission;
    # an access as fast, but the registers kept cost its step 3.5 us a
    # cycle on the demo flight, 64.1 -> 67.6 us). With fewer the pointer
    # register's keeping costs more than it saves (the rocket's nav: 6 B).
    # Not the parameters: the AVR has three pointer registers, and a third
    # area kept in one cost the whole rocket's mission 118 B more than it
    # saved.
    areas = []
    called = any(st.entry or st.step for st in m.states)  # (else step() calls no state function)
    direct = _direct_bytes("\n".join(text for _, _, text in bodies)) if called else {}
    for area, whole in (("sv", "sv"), ("loc", "loc")) if called else ():
        if direct.get(area, 0) >= BY_POINTER_BYTES:
            areas.append((area + "p", whole))
            # `area + ` where no name ends in it (another name than the area's: no shadowing it); the
            # pattern starts with the area's name, which the search looks for before trying a match
            used = re.compile(rf"{area}(?<![\w.:]{area}) \+ ")
            bodies = [(st, label, used.sub(f"{area}p + ", text)) for st, label, text in bodies]
    actuals = ", ".join(a for a, _ in areas)
    for st, label, body in bodies:
        ret = "void" if label == "exit" else sid
        # (unnamed where the function does not use it: no unused-parameter warning)
        formals = ", ".join(f"uint8_t* const {a}" if f"{a} + " in body else "uint8_t* const" for a, _ in areas)
        c.append(f"// [{st.name}] .{label}")
        c.append(f"{ret} s{st.id}_{label}({formals}) {{")
        c.append(body)
        if label != "exit":
            c.append("    return 0;")
        c.append("}")
        c.append("")
    c.append("}  // namespace")
    c.append("")
    g, s = m.vars[m.g], m.vars[m.s]
    c.append("fsw::Result step() {")
    for a, whole in areas:
        c.append(f"    uint8_t* const {a} = fsw::by_pointer({whole});")
    if m.sv.lock:
        c.append("    uint64_t g;")
        c.append(f"    {{ fsw::SvGuard<true> lock; g = fsw::load<uint64_t>(sv + E_{g.name}); }}")
        c.append("    if (fsw::machine_begin_step(machine, g) != fsw::kOk) return fsw::kErrTime;")
        c.append("    if (machine.entering != 0) {")
        c.append(f"        fsw::SvGuard<true> lock; fsw::store<uint32_t>(sv + E_{s.name}, machine.state);")
        c.append("    }")
    else:
        c.append(f"    if (fsw::machine_begin(machine, sv + E_{g.name}, sv + E_{s.name}) != fsw::kOk) "
                 "return fsw::kErrTime;")
    # Windows over the same argument take one read of it (an element read is
    # a call on AVR), pushed where the first of them was. An argument reads
    # only windows of lower index (inner calls get theirs first), and equal
    # arguments read the same ones, so every window still sees its argument
    # after the windows it reads were pushed.
    # A group is sampled only in the states where one of its windows may
    # still be read (window_needs); elsewhere its pushes are skipped.
    c.append("    const uint32_t state = machine.state;  // (read once: nothing changes it before the transition)")
    args: dict[str, list] = {}
    for w in m.windows:
        args.setdefault(ex.value(w.arg), []).append(w)
    every = frozenset(st.index for st in m.states)
    for k, (arg, ws) in enumerate(args.items()):
        if needs is None:
            where = every
        else:
            group = 0
            for w in ws:
                group |= needs[1][w.index]
            where = frozenset(i for i, mask in needs[0].items() if mask & group)
        pad = "    "
        if where != every:
            names = ", ".join(m.states[i].name for i in sorted(where))
            c.append(f"    switch (state) {{  // sampled where still read: {names}")
            for i in sorted(where):
                c.append(f"    case S_{m.states[i].name}:")
            c.append("    {")
            pad = "        "
        pushed = [w for w in ws if shared.get(w.index, (w.index,))[0] == w.index]  # (one push a ring)
        if len(pushed) == 1:
            c.append(f"{pad}{wp}{pushed[0].index}.push({arg});  // {src}:{pushed[0].line}")
        else:
            c.append(f"{pad}const fsw::Real x{k} = {arg};")
            for w in pushed:
                c.append(f"{pad}{wp}{w.index}.push(x{k});  // {src}:{w.line}")
        if watched:
            c.append(f"{pad}win_changed = 1;")
        if where != every:
            c += ["        break;", "    }", "    default:", "        break;", "    }"]
    moves = any(st.entry or st.step for st in m.states)  # else nothing can transition
    if moves:
        c.append(f"    {sid} next = 0;")
    c.append("    switch (state) {")
    for st in m.states:
        c.append(f"    case S_{st.name}:")
        if st.entry:
            c.append(f"        if (machine.entering != 0) next = s{st.id}_entry({actuals});")
        if st.step:
            c.append(f"        if (next == 0) next = s{st.id}_step({actuals});" if st.entry
                     else f"        next = s{st.id}_step({actuals});")
        if st.exit and (st.entry or st.step):
            c.append(f"        if (next != 0) s{st.id}_exit({actuals});")
        c.append("        break;")
    c.append("    default:")
    c.append("        break;")
    c.append("    }")
    if moves:
        # One transition for every state (its .exit, if any, ran above).
        c.append("    if (next != 0) fsw::machine_transition(machine, next);")
    c.append("    return fsw::kOk;")
    c.append("}")
    c.append("")
    c.append("void reset(uint32_t initial) {")
    c.append("    fsw::machine_reset(machine, initial);")
    if stored:
        c.append("    memcpy(loc, kLocInit, sizeof loc);")
    for w, _ in declared:
        c.append(f"    memset(&{wp}{w.index}, 0, sizeof {wp}{w.index});")
    if watched:
        c.append("    win_changed = 1;")
    c.append("}")
    if leave:
        c += ["", "void leave() {",
              "    if (machine.started == 0 || machine.pending != 0) return;  // no state entered, or it was left",
              "    switch (machine.state) {"]
        for st in m.states:
            if st.exit:
                c.append(f"    case S_{st.name}: s{st.id}_exit({', '.join(whole for _, whole in areas)}); break;")
        c += ["    default: break;", "    }", "}"]
    c += ["", f"}}  // namespace {name}", f"}}  // namespace {ns}", ""]
    return {f"{name}.gen.h": "\n".join(h), f"{name}.gen.cpp": "\n".join(c)}


def _reads(e: M.Expr, out: set[int]) -> set[int]:
    """The variables an expression reads, added to `out` (a window's argument
    is not read where its value is: the window was sampled before the
    state's code)."""
    t = type(e)
    if t is M.Ref:
        out.add(e.var)
    elif t is M.Arith or t is M.Cmp or t is M.Logic:
        _reads(e.left, out)
        _reads(e.right, out)
    elif t is M.Neg or t is M.Not:
        _reads(e.operand, out)
    elif t is M.ChainCmp:
        for o in e.operands:
            _reads(o, out)
    return out


def _assigned(stmts) -> set[int]:
    """Every variable a statement list assigns, nested ones included."""
    out = set()
    for st in stmts:
        if isinstance(st, M.Assign):
            out.add(st.var)
        elif isinstance(st, M.If):
            out |= _assigned(st.then) | _assigned(st.orelse)
    return out


def _stored_constant(m: M.Machine, real: Real, st: M.Assign) -> str | None:
    """The literal of what an assignment of literals alone stores (and its
    variable then reads), or None: not such an assignment, or a NaN (stored
    as +0, read as +0: left to the bytes)."""
    try:
        x = evaluate(st.expr, real, no_reads)
    except NotConstant:
        return None
    value = real.read(m.vars[st.var].type, to_type(m.vars[st.var].type, x))
    return None if value != value else real_literal(value, real)


class _Held:
    """The C++ locals of one state function that hold an F32 variable's
    value between its statements (ExprEmitter.held): one read, or one
    assignment's store, that later statements read instead of the bytes
    (on AVR each read is a call). A first emission holds at every read and
    every assignment (`allowed` None); `worth` then tells where a local
    paid: a read read twice or more, a store read again at all; the
    function is emitted again holding only there (`allowed` those)."""

    def __init__(self, allowed: set | None = None):
        self.allowed = allowed
        self.decls: list[tuple[int, str, str, tuple]] = []  # (line, name, kind, where: the statement and variable)

    def take(self, out: list[str], kind: str, where: tuple) -> str | None:
        """A name for a local at the next line of `out`, or None where it did not pay."""
        if self.allowed is not None and where not in self.allowed:
            return None
        name = f"f{len(self.decls)}"
        self.decls.append((len(out), name, kind, where))
        return name

    def worth(self, out: list[str]) -> set:
        keep = set()
        for at, name, kind, where in self.decls:
            word = re.compile(rf"\b{name}\b")
            uses = sum(len(word.findall(line)) for line in out[at + 1:])
            if uses >= (2 if kind == "read" else 1):
                keep.add(where)
        return keep


def _block(stmts, ex: ExprEmitter, indent: str, out: list[str], src: str, m: M.Machine,
           can_transition: bool, held: _Held | None = None) -> None:
    """The C++ of a statement list. With `held` (binary32 R), the F32
    variables a statement reads are read once into locals before it, and
    an assignment's stored value is kept in one, for the statements after
    it in the same block (and the blocks inside them) to read: the same
    values bit for bit (a statement's expressions have no side effects,
    and nothing but the statements writes a machine's variables while its
    step runs), with fewer calls."""
    for st in stmts:
        t = type(st)
        if held is not None and t in (M.Assign, M.If):
            for i in sorted(_reads(st.expr if t is M.Assign else st.cond, set())):
                if i in ex.held or not ex.holdable(i):
                    continue
                plain = ex.read(i)
                name = held.take(out, "read", (id(st), i, "read"))
                if name is not None:
                    out.append(f"{indent}const fsw::Real {name} = {plain};")
                    ex.held[i] = name
        if t is M.Assign:
            line = ex.assign(st.var, st.expr)
            if held is not None and ex.holdable(st.var):
                ex.held.pop(st.var, None)
                plain = f"{indent}{line}  // {src}:{st.line}"
                prefix = f"fsw::write_F32({ex.ptr(m.vars[st.var])}, "
                name = None
                if line.startswith(prefix) and line.endswith(");"):
                    name = held.take(out, "write", (id(st), st.var, "write"))
                if name is not None:
                    out.append(f"{indent}const fsw::Real {name} = fsw::write_F32_read("
                               f"{line[len('fsw::write_F32('):-2]});  // {src}:{st.line}")
                    ex.held[st.var] = name
                else:
                    stored = _stored_constant(m, ex.real, st)
                    if stored is not None:  # a constant store: its value is a literal
                        ex.held[st.var] = stored
                    out.append(plain)
            else:
                out.append(f"{indent}{line}  // {src}:{st.line}")
            # the sums kept in slots of their own, from the value just stored (cached_sums)
            for slot, node in ex.sum_writes.get(st.var, ()):
                cached, ex.cached = ex.cached, {}
                out.append(f"{indent}fsw::write_F32(loc + {slot}, {ex.value(node)});  // {src}:{st.line}")
                ex.cached = cached
        elif t is M.Goto:
            out.append(f"{indent}return S_{m.states[st.state].name};  // {src}:{st.line}")
            return
        else:
            out.append(f"{indent}if {parens(ex.cond(st.cond))} {{  // {src}:{st.line}")
            before = dict(ex.held)
            _block(st.then, ex, indent + "    ", out, src, m, can_transition, held)
            if st.orelse:
                ex.held = dict(before)
                out.append(f"{indent}}} else {{")
                _block(st.orelse, ex, indent + "    ", out, src, m, can_transition, held)
            out.append(f"{indent}}}")
            # after the branches: what neither assigns (a local of theirs is out of scope)
            changed = _assigned(st.then) | _assigned(st.orelse)
            ex.held = {i: n for i, n in before.items() if i not in changed}
