"""The checker: syntax tree to typed model, with every rule of the spec
(§3, §4, §5) and located errors; warnings for what is legal but almost
certainly a mistake (`fsw check`)."""

from __future__ import annotations

import math
import re
from fractions import Fraction

from . import memo
from . import model as M
from . import syntax as S
from .diagnostics import SM, SS, SV, Diagnostic, Diagnostics, Source, visual_col
from .evaluate import NotConstant, evaluate, local_values
from .lexer import KEYWORDS
from .numeric import F64MODE, exact_literal, truthy
from .types import TYPES, U32, U64

MAX_WINDOW = 100000
MAX_SV_SIZE = 65535  # bytes: the generated offsets and sizes are uint16_t
MAX_LOCALS_SIZE = 65535  # bytes of a machine's locals: the same
ROLL = {"roll_avg": "avg", "roll_median": "median", "roll_min": "min",
        "roll_max": "max", "roll_range": "range"}
DEFAULT_MAX_STEPS = 1000000


# ---- state vector -----------------------------------------------------------

def unknown_type(name: str) -> str:
    near = [t for t in TYPES if t.lower() == name.lower()]
    if near:
        return f"unknown type `{name}` (did you mean `{near[0]}`?)"
    return f"unknown type `{name}`: expected one of {' '.join(TYPES)}"


def check_sv(f: S.SvFile, src: Source, diags: Diagnostics) -> M.StateVector:
    return memo.run(("check_sv", id(f), src.path, src.text), (f,), diags, lambda d: _check_sv(f, src, d))


def _check_sv(f: S.SvFile, src: Source, diags: Diagnostics) -> M.StateVector:
    lang = SV
    lock = False
    seen: dict[str, int] = {}
    for o in f.options:
        if o.name in seen:
            diags.error(src, lang, o.line, o.col, f"duplicate option `{o.name}` (previously on line {seen[o.name]})")
            continue
        seen[o.name] = o.line
        if o.name == "lock" and not o.args:
            lock = True
        elif o.name == "lock":
            a = o.args[0]
            diags.error(src, lang, a.line, a.col, f"unexpected `{a.text}` after option `lock`")
        else:
            diags.error(src, lang, o.line, o.col, f"unknown option `{o.name}`: the only option is `lock`")
    regions: list[M.Region] = []
    elements: list[M.Element] = []
    region_lines: dict[str, int] = {}
    elem_lines: dict[str, int] = {}
    unreadable: set[str] = set()
    offset = 0
    for r in f.regions:
        h = r.header
        malformed = h.name == "<malformed>"  # already reported by the parser
        if malformed:
            pass
        elif h.name in KEYWORDS:  # spec §1: a keyword is never a name
            diags.error(src, lang, h.line, h.col + 1, f"`{h.name}` is a keyword and cannot name a region")
        elif h.name in region_lines:
            diags.error(src, lang, h.line, h.col + 1,
                        f"reuse of region name `{h.name}` (previously used on line {region_lines[h.name]})")
        else:
            region_lines[h.name] = h.line
        if not r.lines and not malformed:
            diags.error(src, lang, h.line, h.col + 1, f"empty region `{h.name}`")
        start = offset
        mine = []
        for d in r.elements:
            t = TYPES.get(d.type)
            if t is None:
                diags.error(src, lang, d.line, d.type_col, unknown_type(d.type))
                unreadable.add(d.name)
                continue
            if d.name in elem_lines:
                diags.error(src, lang, d.line, d.name_col,
                            f"reuse of element name `{d.name}` (previously used on line {elem_lines[d.name]})")
                continue
            elem_lines[d.name] = d.line
            e = M.Element(d.name, t, h.name, offset, d.line)
            if offset <= MAX_SV_SIZE < offset + t.size:
                diags.error(src, lang, d.line, d.name_col,
                            f"the state vector would grow past {MAX_SV_SIZE:,} B with `{d.name}` (ending at byte "
                            f"{offset + t.size:,}): element offsets and sizes are 16-bit")
            offset += t.size
            mine.append(e)
        elements.extend(mine)
        regions.append(M.Region(h.name, start, offset - start, tuple(mine), h.line))
    return M.StateVector(src.path, lock, tuple(regions), tuple(elements), offset,
                         frozenset(unreadable - set(elem_lines)))


# ---- expressions ------------------------------------------------------------

class Resolver:
    """Resolves names of a syntax expression to model variables."""

    def __init__(self, src: Source, diags: Diagnostics, lang: str, names: dict[str, int],
                 vars_: list[M.Var], windows: list[M.Window], size_value, silent: frozenset = frozenset()):
        self.src, self.diags, self.lang = src, diags, lang
        self.names = names
        self.silent = silent  # names whose malformed declaration was reported: not unknown again
        self.vars = vars_
        self.windows = windows
        self.size_value = size_value  # resolves a window size expression to a value
        self.used: set[int] = set()
        self.unknown = "unknown element `{}`"

    def error(self, line: int, col: int, msg: str) -> None:
        self.diags.error(self.src, self.lang, line, col, msg)

    def expr(self, e: S.Expr) -> M.Expr:
        t = type(e)
        if t is S.Num:
            return M.Const(e.text, e.line, e.col)
        if t is S.Bool:
            return M.Const("true" if e.value else "false", e.line, e.col)
        if t is S.Name:
            i = self.names.get(e.name)
            if i is None:
                if e.name not in self.silent:
                    self.error(e.line, e.col, self.unknown.format(e.name))
                return M.Const("0", e.line, e.col)
            self.used.add(i)
            return M.Ref(i, e.line, e.col)
        if t is S.Unary:
            inner = self.expr(e.operand)
            if e.op == "-":
                return M.Neg(inner, e.line, e.col)
            return M.Not(inner, e.line, e.col)
        if t is S.Binary:
            left, right = self.expr(e.left), self.expr(e.right)
            if e.op in ("+", "-", "*", "/"):
                return M.Arith(e.op, left, right, e.line, e.col)
            if e.op in ("and", "or"):
                return M.Logic(e.op, left, right, e.line, e.col)
            return M.Cmp(e.op, left, right, e.line, e.col)
        if t is S.Chain:
            return M.ChainCmp(tuple(self.expr(o) for o in e.operands), e.ops, e.line, e.col)
        if t is S.Call:
            return self.call(e)
        raise TypeError(t)

    def call(self, e: S.Call) -> M.Expr:
        func = ROLL.get(e.func)
        if func is None:
            self.error(e.line, e.col, f"unknown function `{e.func}`")
            for a in e.args:
                self.expr(a)
            return M.Const("0", e.line, e.col)
        if len(e.args) != 2:
            self.error(e.line, e.col, f"`{e.func}` takes 2 arguments (a value and a window size), "
                                      f"found {len(e.args)}")
            for a in e.args:
                self.expr(a)
            return M.Const("0", e.line, e.col)
        arg = self.expr(e.args[0])  # inner calls get their windows first
        size = self.window_size(e.args[1])
        if size is None:
            return M.Const("0", e.line, e.col)
        w = M.Window(len(self.windows), func, size, arg, e.line, e.col)
        self.windows.append(w)
        return M.Roll(func, arg, size, w.index, e.line, e.col)

    def window_size(self, e: S.Expr) -> int | None:
        n = e
        value = self.size_value(self, n)
        if value is None:
            return None
        if value != value or value in (float("inf"), float("-inf")) or value != int(value):
            self.error(n.line, n.col, f"window size must be an integer from 1 to {MAX_WINDOW}, "
                                      f"found {format_number(value)}")
            return None
        if not 1 <= value <= MAX_WINDOW:
            self.error(n.line, n.col, f"window size must be an integer from 1 to {MAX_WINDOW}, "
                                      f"found {format_number(value)}")
            return None
        return int(value)


def format_number(v) -> str:
    if isinstance(v, Fraction):
        return str(v.numerator) if v.denominator == 1 else f"{float(v):g}"
    if v == int(v) if v == v and abs(v) != float("inf") else False:
        return str(int(v))
    return repr(v)


def constant_size(res: Resolver, n: S.Expr, vars_, consts):
    """The value of a window size expression: literals and locals' initial
    values only (spec §4.4); None after reporting why not."""
    if type(n) is S.Num:  # the common case: a literal, which nothing can make wrong here
        return F64MODE.literal(n.text)
    # Counted on `error_count`: `errors` builds a list, and one per window
    # made many windows with errors quadratic.
    reported = res.diags.error_count
    todo = [n]
    while todo:  # a call inside the size has no window to resolve it with
        x = todo.pop()
        if isinstance(x, S.Call):
            res.error(x.line, x.col, "window size must be a constant: literals and locals' initial values")
            return None
        todo.extend(_children(x))
    sub = Resolver(res.src, res.diags, res.lang, res.names, vars_, [], None, res.silent)
    me = sub.expr(n)
    res.used |= sub.used
    if res.diags.error_count != reported:
        return None
    if _has(me, (M.Roll,)) or any(vars_[i].kind != M.LOCAL for i in _refs(me)):
        res.error(n.line, n.col, "window size must be a constant: literals and locals' initial values")
        return None
    try:
        return evaluate(me, F64MODE, lambda i: F64MODE.read(vars_[i].type, consts[i]))
    except (NotConstant, KeyError):
        return None


# ---- state machine ----------------------------------------------------------

def check_sm(f: S.SmFile, src: Source, sv: M.StateVector, diags: Diagnostics,
             warnings: bool = False) -> M.Machine | None:
    """The typed machine, or None when it has errors (all reported)."""
    checked = memo.run(("check_sm", id(f), id(sv), src.path, src.text), (f, sv), diags,
                       lambda d: _check_sm(f, src, sv, d))
    if checked is None:
        return None
    m, consts, used = checked
    if warnings:
        machine_warnings(m, f, src, diags, consts, used)
    return m


def _check_sm(f: S.SmFile, src: Source, sv: M.StateVector, diags: Diagnostics):
    """(the typed machine, its locals' values, the variables used), or None
    when it has errors (all reported)."""
    lang = SM
    before = diags.error_count
    err = lambda line, col, msg: diags.error(src, lang, line, col, msg)  # noqa: E731
    vars_: list[M.Var] = []
    names: dict[str, int] = {}
    name_lines: dict[str, int] = {}
    listed: dict[str, int] = {}
    broken = frozenset(f.broken)  # declared on a malformed line, reported there
    g = s = None
    for d in f.elements:
        t = TYPES.get(d.type)
        if t is None:
            err(d.line, d.type_col, unknown_type(d.type))
            # Carry on with the state vector's type, so that the element's
            # uses are not reported again.
            known = sv.find(d.name)
            t = known.type if known is not None else TYPES["F64"]
        if d.name in listed:
            err(d.line, d.name_col, f"reuse of element name `{d.name}` (previously used on line {listed[d.name]})")
            continue
        listed[d.name] = d.line
        e = sv.find(d.name)
        if e is None:
            if d.name not in sv.unreadable:  # else the state vector config's own error said it
                err(d.line, d.name_col, f"element `{d.name}` is not in the state vector config ({sv.path})")
        elif e.type is not t:
            err(d.line, d.type_col, f"type mismatch: `{d.name}` is {e.type} in the state vector config, not {t}")
        for n, col in ((d.name, d.name_col), (d.alias, d.alias_col)):
            if n is None:
                continue
            if n in names:
                err(d.line, col, f"reuse of name `{n}` (previously used on line {name_lines[n]})")
            elif n == "T":
                err(d.line, col, "`T` is the built-in time in state and cannot name an element")
        idx = len(vars_)
        role = "G" if "G" in (d.name, d.alias) else "S" if "S" in (d.name, d.alias) else None
        if role == "G":
            if g is not None:
                pass  # reported above as a reuse of the name `G`
            elif t is not U64:
                err(d.line, d.type_col, f"`G` (global time) must be U64, not {t}")
            else:
                g = idx
        elif role == "S":
            if s is not None:
                pass  # reported above as a reuse of the name `S`
            elif t is not U32:
                err(d.line, d.type_col, f"`S` (current state) must be U32, not {t}")
            else:
                s = idx
        vars_.append(M.Var(idx, M.ELEMENT, d.name, d.alias, t, d.read_only or role is not None, d.line))
        for n in (d.name, d.alias):
            if n is not None and n not in names and n != "T":
                names[n] = idx
                name_lines[n] = d.line
    where = f.sv_header or S.Header(1, 0, "")
    # A `G` or `S` that is declared but wrong was reported where it stands.
    declared = {n for d in f.elements for n in (d.name, d.alias)}
    if g is None and "G" not in declared:
        err(where.line, where.col + 1, "missing `G`: one U64 element must be named or aliased `G` (global time)")
    if s is None and "S" not in declared:
        err(where.line, where.col + 1, "missing `S`: one U32 element must be named or aliased `S` (current state)")

    # locals
    windows: list[M.Window] = []
    local_decls: dict[str, S.LocalDecl] = {d.name: d for d in reversed(f.locals)}
    init_used: set[int] = set()
    local_bytes = 0
    def declared(d, kind: str):
        """The type of a new local or parameter `d`, or None when its name
        cannot be taken (reported)."""
        t = TYPES.get(d.type)
        if t is None:
            err(d.line, d.type_col, unknown_type(d.type))
            t = TYPES["F64"]  # carry on, so that its uses are not reported again
        if d.name == "T":
            err(d.line, d.name_col, f"`T` is the built-in time in state and cannot name a {kind}")
            return None
        if d.name in names:
            err(d.line, d.name_col, f"reuse of name `{d.name}` (previously used on line {name_lines[d.name]})")
            return None
        return t

    for d in f.locals:
        t = declared(d, "local")
        if t is None:
            continue
        init_resolver = Resolver(src, diags, lang, names, vars_, [], None, broken)  # no copy: quadratic in locals
        init = _resolve_init(init_resolver, d, local_decls, vars_,
                             param_names=frozenset(p.name for p in f.params))
        init_used |= init_resolver.used
        idx = len(vars_)
        if local_bytes <= MAX_LOCALS_SIZE < local_bytes + t.size:
            err(d.line, d.name_col, f"the machine's locals would grow past {MAX_LOCALS_SIZE:,} B with `{d.name}`: "
                                    "local offsets are 16-bit")
        local_bytes += t.size
        vars_.append(M.Var(idx, M.LOCAL, d.name, None, t, d.read_only, d.line, init))
        names[d.name] = idx
        name_lines[d.name] = d.line
    # parameters: read-only locals whose value the ground may change
    param_decls: dict[str, S.ParamDecl] = {d.name: d for d in reversed(f.params)}
    param_exprs: dict[int, tuple[S.ParamDecl, M.Expr | None, M.Expr | None]] = {}
    for d in f.params:
        t = declared(d, "parameter")
        if t is None:
            continue
        init_resolver = Resolver(src, diags, lang, names, vars_, [], None, broken)
        init = _resolve_init(init_resolver, d, {**local_decls, **param_decls}, vars_, "default value")
        bounds = []
        for what, e in (("@min", d.min), ("@max", d.max)):
            if e is None:
                bounds.append(None)
                continue
            b = S.LocalDecl(e.line, 0, d.type, 0, d.name + what, e, True)
            bounds.append(_resolve_init(init_resolver, b, {**local_decls, **param_decls}, vars_, f"`{what}` value",
                                        owner=d.name))
        init_used |= init_resolver.used
        if t.is_bool and (d.min is not None or d.max is not None):
            at = dict(d.annot_cols)
            col = at.get("@min", at.get("@max", d.name_col))
            err(d.line, col, f"`{d.name}` is bool: a bool parameter has no range (`@min`/`@max`)")
        elif not t.is_bool and (d.min is None or d.max is None):
            missing = " and ".join(a for a, e in (("`@min`", d.min), ("`@max`", d.max)) if e is None)
            err(d.line, d.name_col, f"parameter `{d.name}` needs {missing}: the ground may set it only within "
                                    "a range")
        idx = len(vars_)
        param_exprs[idx] = (d, bounds[0], bounds[1])
        vars_.append(M.Var(idx, M.LOCAL, d.name, None, t, True, d.line, init, M.Param(None, None, d.unit, ())))
        names[d.name] = idx
        name_lines[d.name] = d.line
    t_idx = len(vars_)
    vars_.append(M.Var(t_idx, M.TIME_IN_STATE, "T", None, U64, True, 0))
    names["T"] = t_idx

    # local values, for window sizes and constant folding
    consts: dict[int, object] = {}
    if diags.error_count == before:
        probe = M.Machine(src.path, "", sv, tuple(vars_), (), (), 0, 0, t_idx)
        try:
            consts = local_values(probe, F64MODE)
        except NotConstant:
            consts = {}

    def size_value(res: Resolver, n: S.Expr):
        return constant_size(res, n, vars_, consts)

    res = Resolver(src, diags, lang, names, vars_, windows, size_value, broken)
    res.used |= init_used

    # states
    state_lines: dict[str, int] = {}
    state_index: dict[str, int] = {}
    for st in f.states:
        h = st.header
        if h.name in KEYWORDS:  # spec §1: a keyword is never a name (no `-> else` could reach it)
            err(h.line, h.col + 1, f"`{h.name}` is a keyword and cannot name a state")
        if h.name in state_lines:
            err(h.line, h.col + 1, f"reuse of state name `{h.name}` (previously used on line {state_lines[h.name]})")
        else:
            state_lines[h.name] = h.line
            state_index[h.name] = len(state_index)
    if not f.states:
        n = len(src.lines)
        last = max(1, n - 1 if n > 1 and src.lines[-1] == "" else n)
        err(last, 1, "a state machine needs at least one state")

    states: list[M.State] = []
    seen_states: set[str] = set()
    for st in f.states:
        blocks = {"entry": (), "step": (), "exit": ()}
        for b in st.blocks:
            blocks[b.label] = _stmts(b.stmts, res, state_index, b.label == "exit", err)
        if st.header.name in seen_states:
            continue
        seen_states.add(st.header.name)
        idx = len(states)
        states.append(M.State(idx, idx + 1, st.header.name, st.header.line,
                              blocks["entry"], blocks["step"], blocks["exit"]))

    for idx, (d, lo_e, hi_e) in param_exprs.items():
        vars_[idx] = _param_var(vars_[idx], d, lo_e, hi_e, consts, state_index, err)

    if diags.error_count != before or g is None or s is None:
        return None
    name = src.path.replace("\\", "/").rsplit("/", 1)[-1].rsplit(".", 1)[0]
    m = M.Machine(src.path, name, sv, tuple(vars_), tuple(states), tuple(windows), g, s, t_idx)
    return m, consts, frozenset(res.used)


def _param_var(v: M.Var, d: S.ParamDecl, lo_e, hi_e, consts, state_index, err) -> M.Var:
    """A parameter's Var with its range (values of its type) and the ids of
    the states that allow a change; errors for a default or a bound that is
    not a value of the type (a fraction for an integer, beyond binary32, a
    number F32 holds as 0), a default outside the range, an unknown state."""
    from .numeric import to_type

    t = v.type

    def value(label: str, e, col: int):
        """`e` as a value of the type, or None (said when it is none)."""
        try:
            x = evaluate(e, F64MODE, lambda i: _const(consts, i))
        except NotConstant:
            return None
        if x != x or x in (math.inf, -math.inf):
            err(d.line, col, f"{label} of `{d.name}` must be a finite number, not {x}")
            return None
        if t.is_int and (x != int(x) or not t.lo <= x <= t.hi):
            err(d.line, col, f"{label} of `{d.name}` must be a whole number in {t.lo}..{t.hi} ({t}), not {x:g}")
            return None
        if t.is_float and t.size == 4 and abs(x) > 3.4028234663852886e38:
            err(d.line, col, f"{label} of `{d.name}` is beyond binary32 (F32): {x:g}")
            return None
        y = to_type(t, x)
        if t.is_float and x != 0 and y == 0:  # a bound or default the user set apart from 0 would be 0
            err(d.line, col, f"{label} of `{d.name}` is {x:g}, which {t} holds as 0: give 0, or a number {t} "
                             f"holds apart from 0 (from {'1.4e-45' if t.size == 4 else '4.9e-324'})")
            return None
        return y

    default_ok = t.is_bool or v.init is None or value("the default", v.init, d.name_col) is not None
    bounds = []
    for what, e in (("@min", lo_e), ("@max", hi_e)):
        if e is None:
            bounds.append(None)
            continue
        bounds.append(value(f"`{what}`", e, dict(d.annot_cols).get(what, d.name_col)))
    lo, hi = bounds
    if lo is not None and hi is not None:
        if lo > hi:
            err(d.line, dict(d.annot_cols)["@max"], f"`@max` of `{d.name}` ({hi:g}) is below its `@min` ({lo:g})")
        elif default_ok and v.index in consts and not lo <= consts[v.index] <= hi:
            err(d.line, d.name_col, f"the default of `{d.name}` ({consts[v.index]:g}) is outside its range "
                                    f"{lo:g}..{hi:g}")
    when: list[int] = []
    for st, col in d.when:
        if st not in state_index:
            known = ", ".join(state_index) or "none"
            err(d.line, col, f"`@when {st}`: no state `{st}` in this machine (its states: {known})")
        elif state_index[st] + 1 in when:
            err(d.line, col, f"state `{st}` is named twice after `@when`")
        else:
            when.append(state_index[st] + 1)
    if not d.when and state_index:
        when = [1]  # without @when: the initial state only
    return M.Var(v.index, v.kind, v.name, v.alias, t, True, v.line, v.init, M.Param(lo, hi, d.unit, tuple(when)))


def _const(consts, i):
    if i not in consts:
        raise NotConstant(None)
    return float(consts[i])


def _resolve_init(res: Resolver, d: S.LocalDecl, local_decls, vars_, what: str = "initial value",
                  owner: str | None = None, param_names: frozenset = frozenset()) -> M.Expr:
    """A local's initial value (a parameter's default or bound): literals and
    earlier locals only (and earlier parameters, for a parameter)."""
    ok = True
    param = isinstance(d, S.ParamDecl) or owner is not None
    who = owner or d.name

    def visit(e):
        nonlocal ok
        if isinstance(e, S.Name):
            if not param and (e.name in param_names or
                              (e.name in res.names and vars_[res.names[e.name]].param is not None)):
                res.error(e.line, e.col, f"initial value of `{d.name}` uses parameter `{e.name}`: a local's "
                                         "initial value cannot depend on a value the ground may change")
                ok = False
            elif (owner is not None and e.name != who and e.name in res.names
                  and vars_[res.names[e.name]].param is not None):  # a bound: fixed when the firmware is built
                res.diags.warning(res.src, res.lang, e.line, e.col,
                                  f"{what} of `{who}` uses parameter `{e.name}`: its default, fixed when the firmware "
                                  f"is built; the range does not follow a change of `{e.name}` from the ground")
            elif e.name == who:
                res.error(e.line, e.col, f"parameter `{who}` cannot be used in its own {what}" if param else
                          f"local `{d.name}` cannot be used in its own initial value")
                ok = False
            elif e.name in res.names and vars_[res.names[e.name]].kind != M.LOCAL:
                res.error(e.line, e.col, f"{what} of `{who}` uses element `{e.name}`: "
                                         "only literals and earlier locals are allowed")
                ok = False
            elif e.name == "T":
                res.error(e.line, e.col, f"{what} of `{who}` uses `T`: "
                                         "only literals and earlier locals are allowed")
                ok = False
            elif e.name not in res.names and e.name in local_decls:
                res.error(e.line, e.col, f"{what} of `{who}` uses `{e.name}`, declared later "
                                         f"(line {local_decls[e.name].line}): only earlier locals are allowed")
                ok = False
        elif isinstance(e, S.Call):
            res.error(e.line, e.col, f"`{e.func}` cannot be used in an {what}" if what[0] in "aeiou" else
                      f"`{e.func}` cannot be used in a {what}")
            ok = False
            return
        for c in _children(e):
            visit(c)

    visit(d.expr)
    if not ok:
        return M.Const("0", d.line, d.name_col)
    return res.expr(d.expr)


def _children(e):
    if isinstance(e, S.Binary):
        return (e.left, e.right)
    if isinstance(e, S.Unary):
        return (e.operand,)
    if isinstance(e, S.Chain):
        return e.operands
    if isinstance(e, S.Call):
        return e.args
    return ()


def _stmts(stmts, res: Resolver, state_index, in_exit: bool, err) -> tuple[M.Stmt, ...]:
    out = []
    for st in stmts:
        t = type(st)
        if t is S.Assign:
            i = res.names.get(st.target)
            expr = res.expr(st.expr)
            if i is None:
                if st.target not in res.silent:
                    err(st.line, st.col, f"unknown element `{st.target}`")
                continue
            v = res.vars[i]
            res.used.add(i)
            if v.kind == M.TIME_IN_STATE:
                err(st.line, st.col, "`T` is read-only: it is the time spent in the current state")
                continue
            if v.read_only:
                kind = "parameter" if v.param else "local" if v.kind == M.LOCAL else "element"
                why = ": the ground changes it (`fsw param set`), the machine only reads it" if v.param else ""
                for role, what in (("G", "the global time, written by the application"),
                                   ("S", "the current state's ID, written by the machine itself")):
                    if v.kind == M.ELEMENT and role in (v.name, v.alias):
                        why = f": it is {what}" if st.target == role else f": it is `{role}`, {what}"
                err(st.line, st.col, f"{kind} `{st.target}` is read-only{why}")
                continue
            out.append(M.Assign(i, expr, st.line, st.col))
        elif t is S.Transition:
            if in_exit:
                err(st.line, st.col, "illegal transition in exit label")
                continue
            target = state_index.get(st.target)
            if target is None:
                err(st.line, st.target_col, f"unknown state `{st.target}`")
                continue
            out.append(M.Goto(target, st.line, st.col))
        else:
            cond = res.expr(st.cond)
            then = _stmts(st.body, res, state_index, in_exit, err)
            orelse = _stmts(st.orelse, res, state_index, in_exit, err) if st.orelse is not None else ()
            out.append(M.If(cond, then, orelse, st.line, st.col))
    return tuple(out)


def _refs(e: M.Expr):
    """Variable indices an expression reads."""
    todo = [e]
    while todo:
        n = todo.pop()
        if isinstance(n, M.Ref):
            yield n.var
        else:
            todo.extend(model_children(n))


def _has(e: M.Expr, kinds) -> bool:
    todo = [e]
    while todo:
        n = todo.pop()
        if isinstance(n, kinds):
            return True
        todo.extend(model_children(n))
    return False


def model_children(n: M.Expr):
    if isinstance(n, (M.Arith, M.Cmp, M.Logic)):
        return (n.left, n.right)
    if isinstance(n, (M.Neg, M.Not)):
        return (n.operand,)
    if isinstance(n, M.ChainCmp):
        return n.operands
    if isinstance(n, M.Roll):
        return (n.arg,)
    return ()


# ---- literals in the run's evaluation type -----------------------------------

def stmt_exprs(stmts):
    """Every expression of a statement list (conditions and assigned values),
    nested ones included."""
    for st in stmts:
        if isinstance(st, M.Assign):
            yield st.expr
        elif isinstance(st, M.If):
            yield st.cond
            yield from stmt_exprs(st.then)
            yield from stmt_exprs(st.orelse)


def machine_exprs(m: M.Machine):
    """Every expression of a machine: locals' initial values and blocks."""
    for v in m.vars:
        if v.init is not None:
            yield v.init
    for st in m.states:
        for block in (st.entry, st.step, st.exit):
            yield from stmt_exprs(block)


def script_exprs(s: M.Script):
    """Every expression of a script's own sections (not its machine's),
    the guards of empty blocks included."""
    yield from s.idle_guards
    for sec in s.sections:
        for g in sec.inputs:
            yield g.guard
            for a in g.inputs:
                yield a.expr
        for g in sec.checks:
            yield g.guard
            for c in g.checks:
                if isinstance(c, M.Assert):
                    yield c.expr


# A decimal literal beyond binary32's range has an exponent or 39 digits or
# more; a file without either has no literal to refuse (comments may give
# a false alarm: the expressions are walked then). Both start with a digit
# or a point (39 digits: a digit, then 38 more), so one scan looks for both.
_MAY_OVERFLOW_F32 = re.compile(r"[0-9.](?:[eE][+-]?[0-9]|(?<=[0-9])[0-9]{38})")


def check_literals(exprs, real, src: Source, diags: Diagnostics, lang: str, whose: str = "this run's") -> bool:
    """Every literal of `exprs` is finite in the evaluation type `real`
    (the parser already holds them to binary64): `1e39` is infinity in
    binary32, so on a board whose `R` is binary32 it is an error where it
    stands. False after reporting any."""
    if real.bits == 64 or not _MAY_OVERFLOW_F32.search(src.text):
        return True  # every literal is in range: no walk of the expressions
    before = diags.error_count
    todo = list(exprs)
    while todo:
        n = todo.pop()
        if isinstance(n, M.Const):
            if n.text not in ("true", "false") and math.isinf(real.literal(n.text)):
                most = "3.4028235e38" if real.bits == 32 else "1.7976931348623157e308"
                diags.error(src, lang, n.line, n.col, f"number is outside the representable range of "
                                                      f"binary{real.bits}, {whose} evaluation type R (at most {most})")
        else:
            todo.extend(model_children(n))
    return diags.error_count == before


# ---- warnings -----------------------------------------------------------------

def fold(e: M.Expr, m: M.Machine, consts) -> float | None:
    """The value of a guard when it is a compile-time constant (literals and
    read-only locals), else None."""
    def read(i):
        v = m.vars[i]
        if v.kind == M.LOCAL and v.read_only and i in consts:
            return F64MODE.read(v.type, consts[i])
        raise NotConstant(None)
    try:
        return evaluate(e, F64MODE, read)
    except NotConstant:
        return None


def machine_warnings(m: M.Machine, f: S.SmFile, src: Source, diags: Diagnostics, consts, used) -> None:
    warn = lambda line, col, msg: diags.warning(src, SM, line, col, msg)  # noqa: E731

    def walk(stmts) -> bool:
        """Warns about dead statements and constant guards; True when the
        list always ends in a transition."""
        ends = False
        for st in stmts:
            if ends:
                warn(st.line, st.col, "statement can never run: it follows a transition")
                return True
            if isinstance(st, M.Goto):
                ends = True
            elif isinstance(st, M.If):
                c = fold(st.cond, m, consts)
                if c is None:
                    a, b = walk(st.then), walk(st.orelse)
                    ends = a and b
                elif truthy(c):
                    warn(st.cond.line, st.cond.col, "guard is always true")
                    if st.orelse:
                        s0 = st.orelse[0]
                        warn(s0.line, s0.col, "statement can never run: the guard before `else` is always true")
                    ends = walk(st.then)
                else:
                    warn(st.cond.line, st.cond.col, "guard is always false")
                    if st.then:
                        s0 = st.then[0]
                        warn(s0.line, s0.col, "statement can never run: its guard is always false")
                    ends = walk(st.orelse)
        return ends

    for st in m.states:
        for block in (st.entry, st.step, st.exit):
            walk(block)

    # states no transition reaches from the initial state
    edges = {st.index: set() for st in m.states}
    for st in m.states:
        for block in (st.entry, st.step):
            for g in gotos(block):
                edges[st.index].add(g.state)
    seen = {0}
    todo = [0]
    while todo:
        for nxt in edges[todo.pop()]:
            if nxt not in seen:
                seen.add(nxt)
                todo.append(nxt)
    for st, decl in zip(m.states, f.states):
        if st.index not in seen:
            warn(decl.header.line, decl.header.col + 1,
                 f"state `{st.name}` is never reached: no transition from the initial state leads to it")

    for v in m.vars:
        if v.index in used or v.index in (m.g, m.s) or v.kind == M.TIME_IN_STATE:
            continue
        if v.kind == M.LOCAL:
            d = next(d for d in (*f.locals, *f.params) if d.name == v.name)
            warn(d.line, d.name_col, f"{'parameter' if v.param else 'local'} `{v.name}` is never used")
        else:
            d = next(d for d in f.elements if d.name == v.name)
            warn(d.line, d.name_col, f"element `{v.name}` is listed but never used")


def assignments(m: M.Machine):
    """Every assignment of the machine, nested ones included, state by
    state and block by block in source order."""
    out: list[M.Assign] = []

    def walk(stmts):
        for st in stmts:
            if isinstance(st, M.Assign):
                out.append(st)
            elif isinstance(st, M.If):
                walk(st.then)
                walk(st.orelse)

    for st in m.states:
        walk(st.entry)
        walk(st.step)
        walk(st.exit)
    return out


def assigned_vars(m: M.Machine) -> set[int]:
    """Every variable some statement of the machine assigns."""
    return {a.var for a in assignments(m)}


def gotos(stmts):
    """Every transition in a statement list, nested ones included."""
    for st in stmts:
        if isinstance(st, M.Goto):
            yield st
        elif isinstance(st, M.If):
            yield from gotos(st.then)
            yield from gotos(st.orelse)


# ---- state script -----------------------------------------------------------------

def _script_options(f: S.SsFile, src: Source, m: M.Machine | None, err):
    """A script's `[options]`, checked: (delta_t, where its value stands,
    init_state, max_steps), None for one not given or wrong. Without its
    machine (`m` None: the machine has errors) every check but the name of
    `init_state`'s state is made."""
    delta_t = init_state = max_steps = None
    delta_t_at = (1, 1)
    seen: dict[str, int] = {}
    for o in f.options:
        if o.name in seen:
            err(o.line, o.col, f"duplicate option `{o.name}` (previously on line {seen[o.name]})")
            continue
        seen[o.name] = o.line
        if o.name in ("delta_t", "max_steps"):
            v = _int_option(o, err)
            if v is not None:
                if o.name == "delta_t":
                    delta_t = v
                    delta_t_at = (o.line, o.args[0].col)
                else:
                    max_steps = v
        elif o.name == "init_state":
            if len(o.args) != 1 or o.args[0].kind != "id":
                col = o.args[0].col if o.args else o.col + len(o.name)
                err(o.line, col, "`init_state` takes one state name")
                continue
            if m is None:  # its machine did not check: a state's name cannot be told
                continue
            st = m.state(o.args[0].text)
            if st is None:
                err(o.line, o.args[0].col, f"unknown state `{o.args[0].text}`")
            else:
                init_state = st.index
        else:
            err(o.line, o.col, f"unknown option `{o.name}`: expected `delta_t`, `init_state` or `max_steps`")
    if delta_t is None and "delta_t" not in seen:
        line, col = _options_pos(src)
        err(line, col, "missing option `delta_t` (how much `G` grows per step)")
    return delta_t, delta_t_at, init_state, max_steps


def check_ss_alone(f: S.SsFile, src: Source, diags: Diagnostics) -> None:
    """The checks of a script that need no machine (its options, a
    `@stop`), for a script whose machine has errors: spec §8, every
    independent error in one run."""
    err = lambda line, col, msg: diags.error(src, SS, line, col, msg)  # noqa: E731
    before = diags.error_count
    _script_options(f, src, None, err)
    has_stop = any(not isinstance(st, (S.Assign, S.Assert)) for sec in f.sections for g in sec.stmts for st in g.body)
    if not has_stop and not before:
        _no_stop(src, err)


def _no_stop(src: Source, err) -> None:
    n = len(src.lines)
    last = max(1, n - 1 if n > 1 and src.lines[-1] == "" else n)
    err(last, 1, "the state script has no `@stop`: it would never end")


def check_ss(f: S.SsFile, src: Source, m: M.Machine, diags: Diagnostics) -> M.Script | None:
    lang = SS
    before = diags.error_count
    err = lambda line, col, msg: diags.error(src, lang, line, col, msg)  # noqa: E731
    delta_t, delta_t_at, init_state, max_steps = _script_options(f, src, m, err)

    names: dict[str, int] = {}
    for v in m.vars:
        names.setdefault(v.name, v.index)
        if v.alias is not None:
            names.setdefault(v.alias, v.index)
    windows: list[M.Window] = []
    consts: dict[int, object] = {}
    try:
        consts = local_values(m, F64MODE)
    except NotConstant:
        pass

    def size_value(res, n):
        return constant_size(res, n, m.vars, consts)

    res = Resolver(src, diags, lang, names, list(m.vars), windows, size_value)
    owned = {m.g: ("G", "the global time, which the script runner advances by `delta_t` each step"),
             m.s: ("S", "the current state's ID, written by the machine"),
             m.t: ("T", "the time spent in the current state, kept by the machine")}
    sections = []
    idle_guards = []
    state_sections: dict[int, int] = {}
    has_stop = False
    for sec in f.sections:
        h = sec.header
        if h.name == "all_states":
            state = None
        else:
            st = m.state(h.name)
            if st is None:
                err(h.line, h.col + 1, f"unknown state `{h.name}`")
                state = -1
            elif st.index in state_sections:
                err(h.line, h.col + 1,
                    f"duplicate section for state `{h.name}` (previously on line {state_sections[st.index]})")
                state = -1
            else:
                state = st.index
                state_sections[st.index] = h.line
        inputs, checks = [], []
        for g in sec.stmts:
            guard = res.expr(g.cond)
            ins, chk = [], []
            for st in g.body:
                if isinstance(st, S.Assign):
                    i = names.get(st.target)
                    expr = res.expr(st.expr)
                    if i is None:
                        err(st.line, st.col, f"unknown element `{st.target}`")
                    elif i in owned:
                        role, what = owned[i]
                        it = "it is" if st.target == role else f"it is `{role}`,"
                        err(st.line, st.col, f"`{st.target}` cannot be written by a state script: {it} {what}")
                    else:
                        ins.append(M.Assign(i, expr, st.line, st.col))
                elif isinstance(st, S.Assert):
                    chk.append(M.Assert(res.expr(st.expr), st.line, st.col))
                else:
                    has_stop = True
                    chk.append(M.Stop(st.line, st.col))
            if ins:
                inputs.append(M.InputGroup(guard, tuple(ins)))
            if chk:
                checks.append(M.CheckGroup(guard, tuple(chk)))
            if not ins and not chk:
                idle_guards.append(guard)
        if state != -1:
            sections.append(M.ScriptSection(state, tuple(inputs), tuple(checks), h.line))
    if not has_stop and not before:  # after a syntax error, the `@stop` may be in the broken part
        _no_stop(src, err)
    if diags.error_count != before:
        return None
    values = _script_params(f, m, err)
    if diags.error_count != before:
        return None
    if values:  # the run sees the script's parameter values, as a loaded file would give them
        from .params import machine_with_values
        m = machine_with_values(m, values)
    return M.Script(src.path, m, delta_t, init_state if init_state is not None else 0,
                    max_steps if max_steps is not None else DEFAULT_MAX_STEPS,
                    tuple(sections), tuple(windows), tuple(idle_guards), delta_t_at)


def _script_params(f: S.SsFile, m: M.Machine, err) -> dict:
    """A script's `[parameters]` values, checked (a parameter of the
    machine, a constant of its type, in its range)."""
    from .params import check_value, var_param

    out: dict = {}
    seen: dict[str, int] = {}
    for sp in f.params:
        v = m.var(sp.name)
        if v is None or v.param is None:
            names = ", ".join(x.name for x in m.vars if x.param is not None) or "none"
            err(sp.line, sp.col, f"`{sp.name}` is not a parameter of machine `{m.name}` (its parameters: {names})")
            continue
        if sp.name in seen:
            err(sp.line, sp.col, f"parameter `{sp.name}` given twice (previously on line {seen[sp.name]})")
            continue
        seen[sp.name] = sp.line
        try:
            x = evaluate(_const_of(sp.expr), F64MODE, _no_var)
        except NotConstant:
            err(sp.line, sp.expr_col, f"the value of `{sp.name}` must be a number or true/false")
            continue
        if v.type.is_bool and x not in (0.0, 1.0):
            err(sp.line, sp.expr_col, f"`{sp.name}` is bool: give true or false")
            continue
        value = (x != 0) if v.type.is_bool else (int(x) if v.type.is_int and x == int(x) else x)
        value, why = check_value(var_param(m, v), value)
        if why is not None:
            err(sp.line, sp.expr_col, why)
            continue
        out[sp.name] = value
    return out


def _no_var(i):
    raise NotConstant(None)


def _const_of(e: S.Expr) -> M.Expr:
    """A literal, a negated literal or true/false as a model expression;
    NotConstant for anything else."""
    if isinstance(e, S.Num):
        return M.Const(e.text, e.line, e.col)
    if isinstance(e, S.Bool):
        return M.Const("true" if e.value else "false", e.line, e.col)
    if isinstance(e, S.Unary) and e.op == "-" and isinstance(e.operand, S.Num):
        return M.Neg(M.Const(e.operand.text, e.line, e.col), e.line, e.col)
    raise NotConstant(None)


def failure_diagnostics(script: M.Script, source_line) -> dict:
    """Every located failure a run of `script` can end with, rendered the
    same by the interpreter and the native runner: `max_steps`,
    `step_error`, and `asserts` (one per `@assert`, in section order)."""
    def located(line: int, col: int, title: str | None, message: str) -> Diagnostic:
        text = source_line(script.path, line) if source_line else ""
        return Diagnostic(SS, "error", script.path, line, col, message, text, title)

    stop = next(c for sec in script.sections for g in sec.checks for c in g.checks if isinstance(c, M.Stop))
    return {
        "max_steps": located(stop.line, stop.col, None,
                             f"`@stop` not reached within {script.max_steps} steps "
                             "(raise `max_steps` in [options] if the script needs more)"),
        "step_error": located(*script.delta_t_at, None, "the machine refused the step: `G` did not increase "
                                                        "(it wrapped around at 2^64: lower `delta_t`)"),
        "asserts": [located(c.line, c.col, "assertion failure", "assertion failed")
                    for sec in script.sections for g in sec.checks for c in g.checks
                    if isinstance(c, M.Assert)],
    }


def _int_option(o: S.Option, err) -> int | None:
    if len(o.args) != 1 or o.args[0].kind != "num":
        col = o.args[0].col if o.args else o.col + len(o.name)
        err(o.line, col, f"`{o.name}` takes one positive integer")
        return None
    q = exact_literal(o.args[0].text)
    if q is None or q.denominator != 1 or q <= 0 or q >= 1 << 64:
        err(o.line, o.args[0].col, f"`{o.name}` must be a positive integer, found `{o.args[0].text}`")
        return None
    return int(q)


def _options_pos(src: Source):
    """Where a missing option belongs: the `[options]` header, else 1:1."""
    for n, text in enumerate(src.lines, 1):
        code = text.split("#", 1)[0]
        # `[opt ions]` is no header (and has no "options" to point at)
        if code.replace(" ", "").replace("\t", "") == "[options]" and "options" in code:
            return n, visual_col(text, code.index("options"))
    return 1, 1
