"""The fast paths' shared decisions: which side of a comparison is the
variable and which the constant, and when an integer comparison is the same
over its variable's whole range. The C++ emitter (expr.py) and the bytecode
compiler (bytecode.py) decide them here, so that an image takes a fast path
exactly where generated code does."""

from __future__ import annotations

from ..evaluate import compare

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
