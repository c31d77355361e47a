"""Hypothesis strategies for the config languages.

`programs()` draws a valid project as syntax trees: a state vector (`.sv`),
a machine over it (`.sm`) and a state script for that machine (`.ss`).
Every tree is *canonical*: `unparse` prints it and `parse` gives it back,
positions aside. `spell_*` print the same trees in the other spellings the
language accepts (optional `if`, `:` or `{}`, braces and `else` on the next
line, chained `else if` / `else: if`, redundant parentheses, spacing, tabs,
comments, blank lines, CRLF), which must parse to the same meaning.

All positions in generated trees are 0; compare trees with `strip()`.
"""

from __future__ import annotations

import functools
import random
from dataclasses import dataclass, fields, is_dataclass, replace

from hypothesis import strategies as st

from fswkit.autocode import syntax as S
from fswkit.autocode import unparse
from fswkit.autocode.lexer import ID, KEYWORDS, NUM, Tok

TYPE_NAMES = ("I8", "I16", "I32", "I64", "U8", "U16", "U32", "U64", "F32", "F64", "bool")
NUMERIC_TYPES = tuple(t for t in TYPE_NAMES if t != "bool")
RESERVED = frozenset({"state_vector", "local", "all_states", "options"})
ROLL = ("roll_avg", "roll_median", "roll_min", "roll_max", "roll_range")
ARITH = ("*", "/", "+", "-")
RELATIONAL = ("<", "<=", ">", ">=")
BINARY = ARITH + RELATIONAL + ("==", "!=", "and", "or")
# Identifiers that look like keywords, types or functions but are not.
TRICKY = ("iffy", "order", "notify", "android", "nota", "orbit", "andy", "elsewhere",
          "true_", "if_", "_", "__", "e3", "E", "roll_avg", "roll", "U8", "F64", "bool1",
          "x1", "A", "Z9", "entry", "step", "exit", "lock", "delta_t")
# Literals at the edges of the types and of binary32/binary64.
SPECIAL_NUMBERS = (
    "0", "1", "2", "127", "128", "255", "256", "32767", "32768", "65535", "65536",
    "2147483647", "2147483648", "4294967295", "4294967296",
    "16777216", "16777217", "9007199254740992", "9007199254740993",
    "9223372036854775807", "9223372036854775808", "18446744073709551615",
    "18446744073709551616", "1e19", "1e20", "3.4028234e38", "3.4028235e38", "3.4028236e38",
    "1e39", "1e308", "1.7976931348623157e308", "1.4e-45", "7e-46",
    "1e-45", "1.17549435e-38", "5e-324", "1e-400", "0.1", "0.5", ".5", "5.", "2.5E-3",
    "1e+3", "000", "0.0", "00.10", "1E0", "0.3e1", "123456789.987654321",
)


@functools.lru_cache(maxsize=None)
def _one_of(options: tuple):
    """`st.sampled_from`, one strategy object per tuple (strategies are
    validated once per object: building them anew on every draw is slow)."""
    return st.sampled_from(options)


@functools.lru_cache(maxsize=None)
def _ints(lo: int, hi: int):
    return st.integers(lo, hi)


# ---- positions ---------------------------------------------------------------

# Positions, and what the parser counts of the text (RegionDecl.lines).
_POSITION = frozenset({"line", "col", "op_col", "type_col", "name_col", "alias_col", "target_col", "lines"})


def strip(node, flags: bool = False):
    """`node` with every position set to 0 and every path to "" (and, with
    `flags`, the brace flags of `If`/`Guarded` cleared): what two trees of
    the same text in different spellings have in common."""
    if isinstance(node, Tok):
        return Tok(node.kind, node.text, 0, 0)
    if isinstance(node, tuple):
        return tuple(strip(n, flags) for n in node)
    if is_dataclass(node) and not isinstance(node, type):
        changes = {}
        for f in fields(node):
            v = getattr(node, f.name)
            if f.name in _POSITION:
                changes[f.name] = 0
            elif f.name == "path":
                changes[f.name] = ""
            elif flags and f.name in ("braced", "else_braced"):
                changes[f.name] = False
            elif isinstance(v, (tuple, Tok)) or (is_dataclass(v) and not isinstance(v, type)):
                changes[f.name] = strip(v, flags)
        return replace(node, **changes)
    return node


# ---- names and numbers ---------------------------------------------------------

def _ok_name(n: str) -> bool:
    return n not in KEYWORDS and n not in RESERVED and n not in ("G", "S", "T")


names = st.one_of(
    _one_of(TRICKY),
    st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,9}", fullmatch=True),
).filter(_ok_name)


@st.composite
def name_pool(draw, size: int = 40) -> list[str]:
    """`size` distinct identifiers: some drawn, the rest plain."""
    drawn = draw(st.lists(names, unique=True, max_size=10))
    pool = list(drawn)
    i = 0
    while len(pool) < size:
        n = f"v{i}"
        if n not in pool:
            pool.append(n)
        i += 1
    return pool


@functools.lru_cache(maxsize=None)
def int_texts(lo: int, hi: int):
    """An integer from lo to hi written as a literal in any form that keeps
    it an integer (`5`, `5.`, `5.0`, `5e0`, `0.5e1`, `50e-1`)."""
    return st.tuples(_ints(lo, hi), _ints(0, 5)).map(
        lambda p: (str(p[0]), f"{p[0]}.", f"{p[0]}.0", f"{p[0]}e0", f"0.{p[0]}e{len(str(p[0]))}",
                   f"{p[0]}0e-1")[p[1]])


# ---- expressions ---------------------------------------------------------------

@functools.lru_cache(maxsize=None)
def _number_table(n: int = 600) -> tuple[str, ...]:
    """Literals in every lexical form (`12`, `0.5`, `.5`, `5.`, `1e3`,
    `2.5E-3`, `5.e+2`, leading zeros, exponents up to 400) and the edge
    values, built once from a fixed seed: one draw picks one (drawing each
    digit is what made big programs slow to generate)."""
    r = random.Random(20240601)
    out = list(SPECIAL_NUMBERS)
    while len(out) < n:
        whole = str(r.randrange(10 ** r.randint(1, 6)))
        if r.random() < 0.1:
            whole = "0" * r.randint(1, 3) + whole
        frac = str(r.randrange(1000)).rjust(r.randint(1, 3), "0")
        text = r.choice((whole, whole, f"{whole}.{frac}", f".{frac}", f"{whole}."))
        if r.random() < 0.25:
            exp = r.randint(0, 400 if r.random() < 0.15 else 12)
            text += r.choice("eE") + r.choice(("", "+", "-")) + str(exp)
        if float(text) == float("inf"):
            continue  # beyond binary64: an error ("number is outside the representable range")
        out.append(text)
    return tuple(out)


# A numeric literal: an edge value or any other form.
NUMBERS = st.one_of(_one_of(_number_table()[:len(SPECIAL_NUMBERS)]), _one_of(_number_table()))


@dataclass(frozen=True)
class Ctx:
    """What an expression may use."""
    readable: tuple[str, ...]
    window_sizes: tuple[S.Expr, ...] = ()  # constant window size expressions
    calls: bool = True
    loose: bool = False  # any function name and argument count (syntax only)


def _n(text: str) -> S.Num:
    return S.Num(0, 0, text)


@functools.lru_cache(maxsize=None)
def exprs(ctx: Ctx, depth: int = 3):
    """Expressions over `ctx`, at most `depth` operators deep."""
    return _exprs(ctx, depth)


@st.composite
def _exprs(draw, ctx: Ctx, depth: int) -> S.Expr:
    kind = draw(_ints(0, 11)) if depth > 0 else 0
    if kind <= 3:
        leaf = draw(_ints(0, 5))
        if leaf <= 1 or not ctx.readable:
            return _n(draw(NUMBERS))
        if leaf == 2:
            return S.Bool(0, 0, draw(st.booleans()))
        return S.Name(0, 0, draw(_one_of(ctx.readable)))
    sub = exprs(ctx, depth - 1)
    if kind <= 5:
        return S.Unary(0, 0, draw(_one_of(("-", "-", "not", "!"))), draw(sub))
    if kind <= 8:
        return S.Binary(0, 0, draw(_one_of(BINARY)), draw(sub), draw(sub))
    if kind == 9:
        n = draw(_ints(2, 4))
        ops = tuple(draw(_one_of(RELATIONAL)) for _ in range(n))
        return S.Chain(0, 0, tuple(draw(sub) for _ in range(n + 1)), ops)
    if ctx.loose:  # mostly roll_* with two arguments, the second anything
        func = draw(_one_of(ROLL)) if draw(_ints(0, 3)) else draw(names)
        return S.Call(0, 0, func, tuple(draw(sub) for _ in range(draw(_one_of((0, 1, 2, 2, 2, 3))))))
    if not ctx.calls or not ctx.window_sizes:
        return S.Binary(0, 0, draw(_one_of(ARITH)), draw(sub), draw(sub))
    return S.Call(0, 0, draw(_one_of(ROLL)), (draw(sub), draw(_one_of(ctx.window_sizes))))


# ---- state machine statements ---------------------------------------------------

def _simple(s) -> bool:
    return isinstance(s, (S.Assign, S.Transition))


@dataclass(frozen=True)
class StmtCtx:
    expr: Ctx
    writable: tuple[str, ...]
    states: tuple[str, ...]


@functools.lru_cache(maxsize=None)
def sm_stmts(c: StmtCtx, depth: int, gotos: bool, max_len: int = 3):
    return _sm_stmts(c, depth, gotos, max_len)


@st.composite
def _sm_stmts(draw, c: StmtCtx, depth: int, gotos: bool, max_len: int) -> tuple:
    return tuple(draw(sm_stmt(c, depth, gotos)) for _ in range(draw(_ints(0, max_len))))


@functools.lru_cache(maxsize=None)
def sm_stmt(c: StmtCtx, depth: int, gotos: bool):
    return _sm_stmt(c, depth, gotos)


@st.composite
def _sm_stmt(draw, c: StmtCtx, depth: int, gotos: bool):
    kinds = []
    if c.writable:
        kinds += ["assign"] * 3
    if gotos and c.states:
        kinds.append("goto")
    if depth > 0 or not kinds:
        kinds += ["if"] * 2
    kind = draw(_one_of(tuple(kinds)))
    if kind == "assign":
        return S.Assign(0, 0, draw(_one_of(c.writable)), draw(exprs(c.expr, 3)))
    if kind == "goto":
        return S.Transition(0, 0, draw(_one_of(c.states)), 0)
    return draw(if_stmts(c, max(depth - 1, 0), gotos))


@functools.lru_cache(maxsize=None)
def if_stmts(c: StmtCtx, depth: int, gotos: bool):
    return _if_stmts(c, depth, gotos)


@st.composite
def _if_stmts(draw, c: StmtCtx, depth: int, gotos: bool) -> S.If:
    cond = draw(exprs(c.expr, 3))
    body = draw(sm_stmts(c, depth, gotos, 3 if depth else 1))
    braced = draw(st.booleans()) if len(body) == 1 and _simple(body[0]) else True
    which = draw(_ints(0, 3))
    orelse, else_braced = None, False
    if which == 1:
        # `else` with nothing after it is an error ("expected logic after else")
        orelse = draw(sm_stmts(c, depth, gotos, 3 if depth else 1)) or (draw(sm_stmt(c, depth, gotos)),)
        single = len(orelse) == 1 and (_simple(orelse[0]) or isinstance(orelse[0], S.If))
        else_braced = draw(st.booleans()) if single else True
    elif which == 2:  # an else-if chain
        orelse = (draw(if_stmts(c, max(depth - 1, 0), gotos)),)
        else_braced = draw(st.booleans())
    return S.If(0, 0, cond, body, orelse, braced, else_braced)


# ---- whole programs ------------------------------------------------------------------

@dataclass(frozen=True)
class Program:
    sv: S.SvFile
    sm: S.SmFile
    ss: S.SsFile

    @property
    def sv_text(self) -> str:
        return unparse.sv_file(self.sv)

    @property
    def sm_text(self) -> str:
        return unparse.sm_file(self.sm)

    @property
    def ss_text(self) -> str:
        return unparse.ss_file(self.ss)


def _header(name: str) -> S.Header:
    return S.Header(0, 0, name)


@st.composite
def programs(draw, max_states: int = 4, max_elements: int = 5, max_locals: int = 4,
             loose: bool = False) -> Program:
    """A valid project: every name resolves, every rule of spec §3–§5 holds.
    With `loose`, expressions may call any function with any arguments
    (still parseable, not checkable)."""
    pool = iter(draw(name_pool()))
    take = lambda: next(pool)  # noqa: E731

    # The state vector: G, S and some other elements, listed in the machine
    # or not, read-only or not, aliased or not.
    sv_elems: list[tuple[str, str]] = []  # (type, name)
    sm_elems: list[S.SmElem] = []
    g_name = "G" if draw(st.booleans()) else take()
    s_name = "S" if draw(st.booleans()) else take()
    for role, name, typ in (("G", g_name, "U64"), ("S", s_name, "U32")):
        alias = role if name != role else (take() if draw(_ints(0, 3)) == 0 else None)
        sv_elems.append((typ, name))
        sm_elems.append(S.SmElem(0, 0, typ, 0, name, draw(st.booleans()), alias, 0))
    for _ in range(draw(_ints(0, max_elements))):
        typ, name = draw(_one_of(TYPE_NAMES)), take()
        sv_elems.append((typ, name))
        if draw(_ints(0, 4)):
            alias = take() if draw(_ints(0, 2)) == 0 else None
            sm_elems.append(S.SmElem(0, 0, typ, 0, name, draw(st.booleans()), alias, 0))
    sm_elems = draw(st.permutations(sm_elems))

    order = draw(st.permutations(sv_elems))
    cuts = sorted(draw(st.sets(_ints(1, len(order) - 1), max_size=2))) if len(order) > 1 else []
    regions = []
    for a, b in zip([0] + cuts, cuts + [len(order)]):
        regions.append(S.RegionDecl(_header(take()),
                                    tuple(S.ElemDecl(0, 0, t, 0, n) for t, n in order[a:b])))
    sv_options = (S.Option(0, 0, "lock", ()),) if draw(_ints(0, 3)) == 0 else ()
    sv = S.SvFile("", sv_options, tuple(regions))

    # Locals: initial values over literals and earlier locals; some hold
    # small integers to serve as window sizes.
    locals_: list[S.LocalDecl] = []
    window_sizes: list[S.Expr] = []
    for _ in range(draw(_ints(0, max_locals))):
        name = take()
        if draw(_ints(0, 3)) == 0:
            n = draw(_ints(1, 30))
            typ = draw(_one_of(NUMERIC_TYPES))
            init: S.Expr = _n(str(n))
            window_sizes.append(S.Name(0, 0, name))
            if n < 30:
                window_sizes.append(S.Binary(0, 0, "+", S.Name(0, 0, name), _n("1")))
        else:
            typ = draw(_one_of(TYPE_NAMES))
            earlier = tuple(d.name for d in locals_)
            init = draw(exprs(Ctx(earlier, calls=False), 2))
        locals_.append(S.LocalDecl(0, 0, typ, 0, name, init, draw(st.booleans())))
    window_sizes += [_n(t) for t in draw(st.lists(int_texts(1, 40), min_size=1, max_size=3))]
    if draw(_ints(0, 9)) == 0:
        window_sizes.append(_n("100000"))

    readable = []
    writable = []
    for e in sm_elems:
        spelled = [e.name] + ([e.alias] if e.alias else [])
        readable += spelled
        if not e.read_only and "G" not in spelled and "S" not in spelled:
            writable += spelled
    for d in locals_:
        readable.append(d.name)
        if not d.read_only:
            writable.append(d.name)
    readable.append("T")
    ctx = Ctx(tuple(readable), tuple(window_sizes), True, loose)

    state_names = [take() for _ in range(draw(_ints(1, max_states)))]
    c = StmtCtx(ctx, tuple(writable), tuple(state_names))
    states = []
    for name in state_names:
        labels = draw(st.permutations(("entry", "step", "exit")))[:draw(_ints(0, 3))]
        blocks = tuple(S.Block(0, 0, label, draw(sm_stmts(c, 2, label != "exit")))
                       for label in labels)
        states.append(S.StateDecl(_header(name), blocks))
    sm = S.SmFile("", tuple(sm_elems), tuple(locals_), tuple(states),
                  _header("state_vector"), _header("local") if locals_ or draw(st.booleans()) else None)

    ss = draw(scripts(sm, ctx, state_names))
    return Program(sv, sm, ss)


@st.composite
def scripts(draw, sm: S.SmFile, ctx: Ctx, state_names: list[str]) -> S.SsFile:
    """A valid state script for machine `sm`: inputs (which may write what
    is read-only for the machine, but not G, S, T), asserts, stops."""
    owned = {"T"}
    readable = ["T"]
    inputs = []
    for e in sm.elements:
        spelled = [e.name] + ([e.alias] if e.alias else [])
        readable += spelled
        if "G" in spelled or "S" in spelled:
            owned.update(spelled)
        else:
            inputs += spelled
    for d in sm.locals:
        readable.append(d.name)
        inputs.append(d.name)
    sctx = Ctx(tuple(readable), ctx.window_sizes, True, ctx.loose)
    g = next(e.alias if e.alias == "G" else e.name for e in sm.elements if "G" in (e.name, e.alias))

    delta = draw(_ints(1, 100))
    options = [S.Option(0, 0, "delta_t", (Tok(NUM, draw(int_texts(delta, delta)), 0, 0),))]
    bounded = draw(_ints(0, 4)) != 0
    if bounded:
        options.append(S.Option(0, 0, "max_steps", (Tok(NUM, draw(int_texts(1, 60)), 0, 0),)))
    if draw(st.booleans()):
        options.append(S.Option(0, 0, "init_state", (Tok(ID, draw(_one_of(tuple(state_names))), 0, 0),)))
    options = draw(st.permutations(options)) if draw(st.booleans()) else options

    def stmt(last: bool):
        k = draw(_ints(0, 9 if last else 7))
        if k <= 3 and inputs:
            return S.Assign(0, 0, draw(_one_of(tuple(inputs))), draw(exprs(sctx, 3)))
        if k <= 7:
            return S.Assert(0, 0, draw(exprs(sctx, 3)))
        return S.Stop(0, 0)

    def section_body():
        out = []
        for _ in range(draw(_ints(0, 4))):
            cond = draw(exprs(sctx, 2))
            if draw(st.booleans()):
                out.append(S.Guarded(0, 0, cond, (stmt(True),), draw(st.booleans())))
            else:
                n = draw(_ints(0, 3))
                out.append(S.Guarded(0, 0, cond, tuple(stmt(i == n - 1) for i in range(n)), True))
        return out

    sections = []
    n_all = draw(_ints(1, 2))
    for _ in range(n_all):
        sections.append(S.ScriptSection(_header("all_states"), tuple(section_body())))
    for name in draw(st.lists(_one_of(tuple(state_names)), unique=True)):
        sections.append(S.ScriptSection(_header(name), tuple(section_body())))
    # A stop that is always reached, in an [all_states] section (and the
    # `@stop` the spec requires): no run is longer than 61 steps.
    k = draw(_ints(0, 60))
    stop = S.Guarded(0, 0, S.Binary(0, 0, ">=", S.Name(0, 0, g), _n(str(k * delta))),
                     (S.Stop(0, 0),), draw(st.booleans()))
    i = draw(_ints(0, n_all - 1))
    at = draw(_ints(0, len(sections[i].stmts)))
    stmts = sections[i].stmts[:at] + (stop,) + sections[i].stmts[at:]
    sections[i] = S.ScriptSection(sections[i].header, stmts)
    return S.SsFile("", tuple(options), tuple(draw(st.permutations(sections))))


# ---- the same trees in other spellings -------------------------------------------------

def _sp(r: random.Random) -> str:
    """Optional whitespace."""
    return r.choice(("", "", " ", " ", "  ", "\t"))


def _ws(r: random.Random) -> str:
    """Required whitespace."""
    return r.choice((" ", " ", " ", "  ", "\t", " \t "))


def _comment(r: random.Random) -> str:
    return r.choice(("", "", "", "", _sp(r) + "# note", "  #", "\t# [x] -> y { } : @stop"))


def spell_expr(e: S.Expr, r: random.Random) -> str:
    """`e` with random spacing and redundant parentheses; parses back to `e`."""
    text = _spell_core(e, r)
    if r.random() < 0.08:
        text = f"({_sp(r)}{text}{_sp(r)})"
    return text


def _wrap(e: S.Expr, paren: bool, r: random.Random) -> str:
    text = spell_expr(e, r)
    return f"({_sp(r)}{text}{_sp(r)})" if paren else text


def _spell_core(e: S.Expr, r: random.Random) -> str:
    lvl = unparse._level
    if isinstance(e, (S.Num, S.Bool, S.Name)):
        return unparse.expr(e)
    if isinstance(e, S.Call):
        sep = _sp(r) + "," + _sp(r)
        return f"{e.func}{_sp(r)}({_sp(r)}{sep.join(spell_expr(a, r) for a in e.args)}{_sp(r)})"
    if isinstance(e, S.Unary):
        inner = _wrap(e.operand, lvl(e.operand) < unparse.UNARY, r)
        if e.op == "not":
            return "not" + (_sp(r) if inner.startswith("(") else _ws(r)) + inner
        return e.op + _sp(r) + inner
    if isinstance(e, S.Chain):
        parts = [_wrap(e.operands[0], lvl(e.operands[0]) <= 4, r)]
        for op, o in zip(e.ops, e.operands[1:]):
            parts.append(_sp(r) + op + _sp(r) + _wrap(o, lvl(o) <= 4, r))
        return "".join(parts)
    lv = unparse.LEVEL[e.op]
    left = _wrap(e.left, lvl(e.left) < lv or (lv == 4 and lvl(e.left) == 4), r)
    right = _wrap(e.right, lvl(e.right) <= lv, r)
    if e.op in ("and", "or"):
        return f"{left}{_ws(r)}{e.op}{_ws(r)}{right}"
    return f"{left}{_sp(r)}{e.op}{_sp(r)}{right}"


class _Lines:
    """Output lines; the last one may still be continued."""

    def __init__(self, r: random.Random):
        self.r = r
        self.lines: list[str] = []

    def new(self, text: str) -> None:
        r = self.r
        while r.random() < 0.05:
            self.lines.append(r.choice(("", "   ", "\t", "# comment", "  # x = 1")))
        self.lines.append(text)

    def add(self, text: str) -> None:
        self.lines[-1] += text

    def end(self) -> None:
        self.lines[-1] += self.r.choice(("", "", "", " ", "\t")) + _comment(self.r)


def _indent(r: random.Random, depth: int) -> str:
    return r.choice(("    ", "  ", "\t", "")) * depth + r.choice(("", "", " "))


def _spell_simple(st_: S.Stmt, r: random.Random) -> str:
    if isinstance(st_, S.Assign):
        return f"{st_.target}{_sp(r)}={_sp(r)}{spell_expr(st_.expr, r)}"
    return f"->{_sp(r)}{st_.target}"


def _spell_stmt(st_: S.Stmt, depth: int, out: _Lines, inline: bool) -> None:
    """Prints a statement on a new line, or (inline) continuing the last."""
    r = out.r
    put = out.add if inline else (lambda t: out.new(_indent(r, depth) + t))
    if not isinstance(st_, S.If):
        put(_spell_simple(st_, r))
        return
    _spell_if(st_, depth, out, put)


def _spell_if(st_: S.If, depth: int, out: _Lines, put, lead: str | None = None) -> None:
    """Prints an if (and its else) starting with `put`; `lead` replaces the
    random choice between writing `if` and leaving it out."""
    r = out.r
    if lead is None:
        lead = r.choice(("if" + _ws(r), "if" + _ws(r), ""))
    put(lead + spell_expr(st_.cond, r))
    body = st_.body
    ends_in_assign = False
    # A colon body that is itself an `if` would take this `if`'s `else`.
    colon_ok = len(body) == 1 and (_simple(body[0]) or (isinstance(body[0], S.If) and st_.orelse is None))
    if colon_ok and r.random() < 0.6:
        out.add(_sp(r) + ":" + _sp(r) + (" " if r.random() < 0.5 else ""))
        _spell_stmt(body[0], depth, out, inline=True)
        ends_in_assign = isinstance(body[0], S.Assign)
    else:
        _spell_braced(body, depth, out)
    if st_.orelse is None:
        return
    # `else`, on this line (after `}` or an assignment) or on a later one
    if (ends_in_assign or out.lines[-1].endswith("}")) and r.random() < (0.2 if ends_in_assign else 0.5):
        out.add(_ws(r) + "else")
    else:
        out.end()
        out.new(_indent(r, depth) + "else")
    orelse = st_.orelse
    chained = len(orelse) == 1 and isinstance(orelse[0], S.If)
    simple = len(orelse) == 1 and _simple(orelse[0])
    if chained and r.random() < 0.7:
        way = r.randrange(3)
        if way == 0:  # else if
            out.add(_ws(r))
            _spell_if(orelse[0], depth, out, out.add, "if" + _ws(r))
        elif way == 1:  # else: if / else: cond
            out.add(_sp(r) + ":" + _sp(r))
            _spell_if(orelse[0], depth, out, out.add, r.choice(("if" + _ws(r), "")))
        else:  # else, then `if` on the next line
            out.end()
            out.new(_indent(r, depth))
            _spell_if(orelse[0], depth, out, out.add, "if" + _ws(r))
    elif (chained or simple) and r.random() < 0.7:
        out.add(_sp(r) + ":" + _sp(r))
        _spell_stmt(orelse[0], depth, out, inline=True)
    else:
        _spell_braced(orelse, depth, out)


def _spell_braced(stmts: tuple, depth: int, out: _Lines) -> None:
    r = out.r
    if not stmts and r.random() < 0.5:
        out.add(_sp(r) + r.choice(("{}", "{ }", "{\t}")))
        return
    if len(stmts) == 1 and _simple(stmts[0]) and r.random() < 0.3:
        out.add(_sp(r) + "{" + _sp(r) + _spell_simple(stmts[0], r) + _sp(r) + "}")
        return
    if r.random() < 0.25:
        out.end()
        out.new(_indent(r, depth) + "{")
    else:
        out.add(_sp(r) + "{")
    out.end()
    for s in stmts:
        _spell_stmt(s, depth + 1, out, inline=False)
        out.end()
    out.new(_indent(r, depth) + "}")


def _join(lines: list[str], r: random.Random) -> str:
    nl = "\r\n" if r.random() < 0.15 else "\n"
    return nl.join(lines) + (nl if r.random() < 0.8 else "")


def _header_text(name: str, r: random.Random) -> str:
    return f"{_sp(r)}[{_sp(r)}{name}{_sp(r)}]{_sp(r)}{_comment(r)}"


def spell_sm(f: S.SmFile, r: random.Random) -> str:
    out = _Lines(r)
    if f.sv_header is not None:
        out.new(_header_text("state_vector", r))
        for e in f.elements:
            annots = []
            if e.read_only:
                annots.append("@read_only")
            if e.alias is not None:
                annots.append(f"@alias{_ws(r)}{e.alias}")
            r.shuffle(annots)
            out.new(_sp(r) + e.type + _ws(r) + e.name + "".join(_ws(r) + a for a in annots))
            out.end()
    if f.local_header is not None:
        out.new(_header_text("local", r))
        for d in f.locals:
            ro = _ws(r) + "@read_only" if d.read_only else ""
            out.new(f"{_sp(r)}{d.type}{_ws(r)}{d.name}{_sp(r)}={_sp(r)}{spell_expr(d.expr, r)}{ro}")
            out.end()
    for s in f.states:
        out.new(_header_text(s.header.name, r))
        for b in s.blocks:
            out.new(_sp(r) + "." + b.label)
            out.end()
            for x in b.stmts:
                _spell_stmt(x, 1, out, inline=False)
                out.end()
    return _join(out.lines, r)


def spell_sv(f: S.SvFile, r: random.Random) -> str:
    out = _Lines(r)
    if f.options:
        out.new(_header_text("options", r))
        for o in f.options:
            out.new(_sp(r) + " ".join([o.name] + [a.text for a in o.args]))
            out.end()
    for reg in f.regions:
        out.new(_header_text(reg.header.name, r))
        for e in reg.elements:
            out.new(_sp(r) + e.type + _ws(r) + e.name)
            out.end()
    return _join(out.lines, r)


def _spell_ss_stmt(s, r: random.Random) -> str:
    if isinstance(s, S.Assign):
        return _spell_simple(s, r)
    if isinstance(s, S.Assert):
        return "@assert" + _ws(r) + spell_expr(s.expr, r)
    return "@stop"


def spell_ss(f: S.SsFile, r: random.Random) -> str:
    out = _Lines(r)
    if f.options:
        out.new(_header_text("options", r))
        for o in f.options:
            out.new(_sp(r) + _ws(r).join([o.name] + [a.text for a in o.args]))
            out.end()
    for sec in f.sections:
        out.new(_header_text(sec.header.name, r))
        for g in sec.stmts:
            out.new(_sp(r) + r.choice(("", "", "if" + _ws(r))) + spell_expr(g.cond, r))
            if len(g.body) == 1 and r.random() < 0.6:
                out.add(_sp(r) + ":" + _sp(r) + _spell_ss_stmt(g.body[0], r))
            elif len(g.body) == 1 and r.random() < 0.3:
                out.add(_sp(r) + "{" + _sp(r) + _spell_ss_stmt(g.body[0], r) + _sp(r) + "}")
            else:
                if r.random() < 0.25:
                    out.end()
                    out.new(_sp(r) + "{")
                else:
                    out.add(_sp(r) + "{")
                out.end()
                for s in g.body:
                    out.new(_indent(r, 1) + _spell_ss_stmt(s, r))
                    out.end()
                out.new(_sp(r) + "}")
            out.end()
    return _join(out.lines, r)
