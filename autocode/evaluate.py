"""A direct evaluator of model expressions: the plain statement of the
semantics of spec §4.4–§4.5, used for compile-time values (locals' initial
values, window sizes, constant guards). The interpreter in host-tools
compiles the same semantics into faster code and is tested against this."""

from __future__ import annotations

from . import model as M
from .numeric import Real, div, truthy


class NotConstant(Exception):
    """The expression reads something whose value is not known at compile
    time."""

    def __init__(self, node):
        super().__init__("not constant")
        self.node = node


def evaluate(e: M.Expr, real: Real, read, roll=None) -> float:
    """Evaluates `e` in `real`. `read(var_index)` returns a variable's value
    as an R (it may raise NotConstant); `roll(window_index)` a window's."""
    r = real.rnd
    t = type(e)
    if t is M.Const:
        return real.literal(e.text)
    if t is M.Ref:
        return read(e.var)
    if t is M.Neg:
        return -evaluate(e.operand, real, read, roll)
    if t is M.Not:
        return 0.0 if truthy(evaluate(e.operand, real, read, roll)) else 1.0
    if t is M.Arith:
        a = evaluate(e.left, real, read, roll)
        b = evaluate(e.right, real, read, roll)
        op = e.op
        if op == "+":
            return r(a + b)
        if op == "-":
            return r(a - b)
        if op == "*":
            return r(a * b)
        return r(div(a, b))
    if t is M.Cmp:
        return 1.0 if compare(e.op, evaluate(e.left, real, read, roll),
                              evaluate(e.right, real, read, roll)) else 0.0
    if t is M.ChainCmp:
        vals = [evaluate(o, real, read, roll) for o in e.operands]
        return 1.0 if all(compare(op, vals[i], vals[i + 1]) for i, op in enumerate(e.ops)) else 0.0
    if t is M.Logic:
        a = truthy(evaluate(e.left, real, read, roll))
        if e.op == "and":
            return 1.0 if a and truthy(evaluate(e.right, real, read, roll)) else 0.0
        return 1.0 if a or truthy(evaluate(e.right, real, read, roll)) else 0.0
    if t is M.Roll:
        if roll is None:
            raise NotConstant(e)
        return roll(e.window)
    raise TypeError(f"unknown expression node {t.__name__}")


def compare(op: str, a: float, b: float) -> bool:
    if op == "<":
        return a < b
    if op == "<=":
        return a <= b
    if op == ">":
        return a > b
    if op == ">=":
        return a >= b
    if op == "==":
        return a == b
    return a != b


def local_values(machine: M.Machine, real: Real) -> dict[int, object]:
    """Each local's initial value, converted to its type, in `real`."""
    from .numeric import to_type

    values: dict[int, object] = {}
    for v in machine.vars:
        if v.kind == M.LOCAL:
            def read(i):
                if i not in values:
                    raise NotConstant(None)
                return real.read(machine.vars[i].type, values[i])
            values[v.index] = to_type(v.type, evaluate(v.init, real, read))
    return values
