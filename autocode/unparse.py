"""Canonical text for syntax trees and model expressions: what `fsw graph`
and `fsw skeleton` print, and what the round-trip tests parse back."""

from __future__ import annotations

from . import model as M
from . import syntax as S

# Binding strength of each operator, weakest first (spec §4.4).
LEVEL = {"or": 1, "and": 2, "==": 3, "!=": 3, "<": 4, "<=": 4, ">": 4, ">=": 4,
         "+": 5, "-": 5, "*": 6, "/": 6}
UNARY, ATOM = 7, 8


def _level(e: S.Expr) -> int:
    if isinstance(e, S.Binary):
        return LEVEL[e.op]
    if isinstance(e, S.Chain):
        return 4
    if isinstance(e, S.Unary):
        return UNARY
    return ATOM


def expr(e: S.Expr) -> str:
    """Text that parses back to the same tree, with the fewest parentheses."""
    if isinstance(e, S.Num):
        return e.text
    if isinstance(e, S.Bool):
        return "true" if e.value else "false"
    if isinstance(e, S.Name):
        return e.name
    if isinstance(e, S.Call):
        return f"{e.func}({', '.join(expr(a) for a in e.args)})"
    if isinstance(e, S.Unary):
        inner = _wrap(e.operand, _level(e.operand) < UNARY)
        return f"not {inner}" if e.op == "not" else f"{e.op}{inner}"
    if isinstance(e, S.Chain):
        parts = [_wrap(e.operands[0], _level(e.operands[0]) <= 4)]
        for op, o in zip(e.ops, e.operands[1:]):
            parts += [op, _wrap(o, _level(o) <= 4)]
        return " ".join(parts)
    lv = LEVEL[e.op]
    # Left-associative: an equal-strength left operand needs no parentheses,
    # except a comparison, which would otherwise chain.
    left_paren = _level(e.left) < lv or (lv == 4 and _level(e.left) == 4)
    right_paren = _level(e.right) <= lv
    return f"{_wrap(e.left, left_paren)} {e.op} {_wrap(e.right, right_paren)}"


def _wrap(e: S.Expr, paren: bool) -> str:
    text = expr(e)
    return f"({text})" if paren else text


def _simple(st) -> bool:
    return isinstance(st, (S.Assign, S.Transition))


def stmt(st: S.Stmt, indent: str, out: list[str]) -> None:
    if isinstance(st, S.Assign):
        out.append(f"{indent}{st.target} = {expr(st.expr)}")
    elif isinstance(st, S.Transition):
        out.append(f"{indent}-> {st.target}")
    else:
        _if(st, indent, "if ", out)


def _if(st: S.If, indent: str, lead: str, out: list[str]) -> None:
    head = f"{indent}{lead}{expr(st.cond)}"
    if len(st.body) == 1 and _simple(st.body[0]) and not st.braced:
        one: list[str] = []
        stmt(st.body[0], "", one)
        out.append(f"{head}: {one[0]}")
    else:
        out.append(head + " {")
        for b in st.body:
            stmt(b, indent + "    ", out)
        out.append(indent + "}")
    if st.orelse is None:
        return
    if len(st.orelse) == 1 and isinstance(st.orelse[0], S.If) and not st.else_braced:
        _if(st.orelse[0], indent, "else if ", out)
    elif len(st.orelse) == 1 and _simple(st.orelse[0]) and not st.else_braced:
        one = []
        stmt(st.orelse[0], "", one)
        out.append(f"{indent}else: {one[0]}")
    else:
        out.append(indent + "else {")
        for b in st.orelse:
            stmt(b, indent + "    ", out)
        out.append(indent + "}")


def sm_file(f: S.SmFile) -> str:
    out: list[str] = []
    if f.elements or f.sv_header:
        out.append("[state_vector]")
        for e in f.elements:
            line = f"{e.type} {e.name}"
            if e.read_only:
                line += " @read_only"
            if e.alias is not None:
                line += f" @alias {e.alias}"
            out.append(line)
        out.append("")
    if f.locals or f.local_header:
        out.append("[local]")
        for d in f.locals:
            out.append(f"{d.type} {d.name} = {expr(d.expr)}" + (" @read_only" if d.read_only else ""))
        out.append("")
    for st in f.states:
        out.append(f"[{st.header.name}]")
        for b in st.blocks:
            out.append(f".{b.label}")
            for s in b.stmts:
                stmt(s, "    ", out)
        out.append("")
    return "\n".join(out)


def sv_file(f: S.SvFile) -> str:
    out: list[str] = []
    if f.options:
        out.append("[options]")
        out += [" ".join([o.name] + [a.text for a in o.args]) for o in f.options]
        out.append("")
    for r in f.regions:
        out.append(f"[{r.header.name}]")
        out += [f"{e.type} {e.name}" for e in r.elements]
        out.append("")
    return "\n".join(out)


def ss_file(f: S.SsFile) -> str:
    out: list[str] = []
    if f.options:
        out.append("[options]")
        out += [" ".join([o.name] + [a.text for a in o.args]) for o in f.options]
        out.append("")
    for sec in f.sections:
        out.append(f"[{sec.header.name}]")
        for g in sec.stmts:
            body = [_ss_stmt(s) for s in g.body]
            if len(body) == 1 and not g.braced:
                out.append(f"{expr(g.cond)}: {body[0]}")
            else:
                out.append(f"{expr(g.cond)} {{")
                out += ["    " + b for b in body]
                out.append("}")
        out.append("")
    return "\n".join(out)


def _ss_stmt(s) -> str:
    if isinstance(s, S.Assign):
        return f"{s.target} = {expr(s.expr)}"
    if isinstance(s, S.Assert):
        return f"@assert {expr(s.expr)}"
    return "@stop"


# ---- model expressions ------------------------------------------------------------

def to_syntax(e: M.Expr, m: M.Machine) -> S.Expr:
    """A model expression as a syntax tree, names as the machine spells them
    (an alias where there is one)."""
    t = type(e)
    if t is M.Const:
        if e.text in ("true", "false"):
            return S.Bool(e.line, e.col, e.text == "true")
        return S.Num(e.line, e.col, e.text)
    if t is M.Ref:
        v = m.vars[e.var]
        return S.Name(e.line, e.col, v.alias or v.name)
    if t is M.Neg:
        return S.Unary(e.line, e.col, "-", to_syntax(e.operand, m))
    if t is M.Not:
        return S.Unary(e.line, e.col, "not", to_syntax(e.operand, m))
    if t in (M.Arith, M.Cmp, M.Logic):
        return S.Binary(e.line, e.col, e.op, to_syntax(e.left, m), to_syntax(e.right, m))
    if t is M.ChainCmp:
        return S.Chain(e.line, e.col, tuple(to_syntax(o, m) for o in e.operands), e.ops)
    if t is M.Roll:
        return S.Call(e.line, e.col, "roll_" + e.func,
                      (to_syntax(e.arg, m), S.Num(e.line, e.col, str(e.size))))
    raise TypeError(t)


def model_expr(e: M.Expr, m: M.Machine) -> str:
    return expr(to_syntax(e, m))
