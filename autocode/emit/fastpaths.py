"""The fast paths' shared decisions: which locals read as constants, which
operands are known values and exact integers, which side of a comparison is
the variable and which the constant, and when an integer comparison is the
same over its variable's whole range. The C++ emitter (expr.py) and the
bytecode compiler (bytecode.py) decide them here, so that an image takes a
fast path exactly where generated code does."""

from __future__ import annotations

import math

from .. import model as M
from ..check import assigned_vars
from ..evaluate import NotConstant, compare, local_values
from ..numeric import Real

# `a op b` is `b FLIP[op] a`.
FLIP = {"<": ">", "<=": ">=", ">": "<", ">=": "<=", "==": "==", "!=": "!="}


def orient(left, op: str, right, as_var, as_const):
    """`x op c` read from `left op right`: (the variable's expression,
    as_var(it), as_const(the other side), op turned around when the
    variable is on the right), or None when neither order fits. The left
    side is tried as the variable first."""
    a, c = as_var(left), as_const(right)
    if a is not None and c is not None:
        return left, a, c, op
    a, c = as_var(right), as_const(left)
    if a is not None and c is not None:
        return right, a, c, FLIP[op]
    return None


def folded_compare(op: str, c: int, lo: int, hi: int):
    """`x op c` when it is the same for every integer x of [lo, hi] (c
    outside the range, or `x >= 0` of an unsigned x): True or False, as
    compilers would warn about the test; None when it depends on x."""
    points = (lo, hi) if not lo <= c <= hi else (lo, hi, c)
    results = {compare(op, x, c) for x in points}
    return results.pop() if len(results) == 1 else None


def no_reads(i: int):
    """`evaluate`'s read of a variable for an expression of literals only."""
    raise NotConstant(None)


def folded_locals(m: M.Machine, real: Real, scriptable: bool) -> dict[int, float]:
    """The locals read as constants, with their R values. In firmware only
    the machine writes its locals: one it never assigns keeps its initial
    value, exactly like a @read_only one; a parameter is the ground's to
    write. (A state script may write any local: `scriptable` keeps them all.)"""
    if scriptable:
        return {}
    values = local_values(m, real)
    written = assigned_vars(m)
    return {v.index: real.read(v.type, values[v.index]) for v in m.vars
            if v.kind == M.LOCAL and v.param is None and (v.read_only or v.index not in written)}


def known(e: M.Expr, real: Real, consts: dict[int, float]):
    """The R value of a literal, of a local read as a constant, or of the
    negation of either (`-5`, `-GATE`: negating is exact in R), or None."""
    if type(e) is M.Neg:
        v = known(e.operand, real, consts)
        return None if v is None else -v
    if type(e) is M.Const:
        return real.literal(e.text)
    return consts.get(e.var) if type(e) is M.Ref else None


def exact_int(x, real: Real):
    """The known value `x` as an integer when it is one of magnitude below
    2^p (p = R's precision: 24 or 53), so that every integer near it is
    exact in R; else None."""
    if x is None or x != x or x in (math.inf, -math.inf) or x != int(x):
        return None
    c = int(x)
    return c if abs(c) < (1 << (24 if real.bits == 32 else 53)) else None


def add_operands(e: M.Expr, as_var, as_const):
    """`x + k`, `k + x` or `x - k` read from `e` (an Arith + or -): (as_var(x),
    k with the sign it adds), or None."""
    a, k = as_var(e.left), as_const(e.right)
    if e.op == "+" and (a is None or k is None):
        a, k = as_var(e.right), as_const(e.left)
    if a is None or k is None:
        return None
    return a, -k if e.op == "-" else k


def exact_sum_limit(k: int, real: Real) -> int:
    """The largest |x| for which x, x + k and the sum are all exact in R
    (negative: none is)."""
    return (1 << (24 if real.bits == 32 else 53)) - 1 - abs(k)
