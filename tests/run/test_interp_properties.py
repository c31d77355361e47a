"""Properties of the interpreter over generated programs
(fswkit.testing.strategies) and generated expressions:

- differential: the interpreter's compiled Python and the tree walk of
  `evaluate` agree bit for bit, expression by expression and step by step,
  in binary64 and binary32;
- independent oracles: binary32 arithmetic is numpy's float32 arithmetic;
  conversions are C's, saturated as spec §4.5 says; binary32 literals and
  integers are correctly rounded; rolling windows hold the last N samples.

FSW_PROPERTY_SCALE scales the example counts (fswkit.testing.properties);
FSW_PROPERTY_SHRINK=1 shrinks failing programs (slow) before reporting.
"""

from __future__ import annotations

import math
from dataclasses import replace
from fractions import Fraction

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st

from fswkit.autocode import model as M
from fswkit.autocode import unparse
from fswkit.autocode.evaluate import evaluate, local_values
from fswkit.autocode.numeric import F32MODE, F64MODE, format_value, to_type, truthy
from fswkit.autocode.types import TYPES
from fswkit.run.interp import ERR_TIME, OK, MachineRun, _Emitter, compile_functions
from fswkit.run.script import run as run_script
from fswkit.run.windows import make_window
from fswkit.testing import strategies as T
from fswkit.testing.properties import NO_SHRINK, REAL_MODES, assert_same_values, cases, compile_program, same


# ---- the tree walk: spec §4.6 and §5 written out plainly ----------------------------------------

class TreeMachine:
    """One machine stepped by walking its model with `evaluate`."""

    def __init__(self, m: M.Machine, real, init_state: int = 0):
        self.m, self.real = m, real
        self.v = [0.0 if var.type.kind == "float" else 0 for var in m.vars]
        for i, x in local_values(m, real).items():
            self.v[i] = x
        self.windows = [make_window(w.func, w.size, real) for w in m.windows]
        self.wv = [0.0] * len(m.windows)
        self.state, self.first, self.entry, self.prev = init_state, True, 0, None

    def read(self, i: int) -> float:
        return self.real.read(self.m.vars[i].type, self.v[i])

    def ev(self, e: M.Expr, roll=None) -> float:
        return evaluate(e, self.real, self.read, roll or self.wv.__getitem__)

    def assign(self, var: int, x: float) -> None:
        self.v[var] = to_type(self.m.vars[var].type, x)

    def block(self, stmts):
        for s in stmts:
            if isinstance(s, M.Assign):
                self.assign(s.var, self.ev(s.expr))
            elif isinstance(s, M.Goto):
                return s.state
            else:
                k = self.block(s.then if truthy(self.ev(s.cond)) else s.orelse)
                if k is not None:
                    return k
        return None

    def step(self) -> int:
        m, v = self.m, self.v
        g = v[m.g]
        if self.prev is not None and not g > self.prev:
            return ERR_TIME
        self.prev = g
        if self.first:
            self.entry = g
            v[m.s] = self.state + 1
        v[m.t] = g - self.entry
        for w in m.windows:
            self.wv[w.index] = self.windows[w.index].push(self.ev(w.arg))
        st_ = m.states[self.state]
        k = None
        if self.first:
            self.first = False
            k = self.block(st_.entry)
        if k is None:
            k = self.block(st_.step)
        if k is not None:
            self.block(st_.exit)
            self.state, self.first = k, True
        return OK


def tree_script(script: M.Script, real):
    """The run loop of spec §5: (passed, steps, asserts, failure position, machine)."""
    m = script.machine
    tm = TreeMachine(m, real, script.init_state)
    windows = [make_window(w.func, w.size, real) for w in script.windows]
    sw = [0.0] * len(script.windows)
    ev = lambda e: tm.ev(e, sw.__getitem__)  # noqa: E731 - a script's calls read its own windows
    v = tm.v
    g = steps = asserts = 0
    while True:
        if steps >= script.max_steps:
            stop = next(c for sec in script.sections for grp in sec.checks for c in grp.checks
                        if isinstance(c, M.Stop))
            return False, steps, asserts, (stop.line, stop.col), tm
        v[m.g] = g
        v[m.s] = tm.state + 1
        v[m.t] = 0 if tm.first else g - tm.entry
        for w in script.windows:
            sw[w.index] = windows[w.index].push(ev(w.arg))
        remembered = []
        for sec in script.sections:
            if sec.state is not None and sec.state != tm.state:
                continue
            for grp in sec.inputs:
                for a in grp.inputs:  # the guard just before each input: an earlier input may turn it false
                    if truthy(ev(grp.guard)):
                        tm.assign(a.var, ev(a.expr))
            for grp in sec.checks:
                if truthy(ev(grp.guard)):
                    remembered += grp.checks
        code = tm.step()
        steps += 1
        if code == ERR_TIME:
            return False, steps, asserts, (1, 1), tm
        for c in remembered:
            if isinstance(c, M.Stop):
                return True, steps, asserts, None, tm
            if not truthy(ev(c.expr)):
                return False, steps, asserts, (c.line, c.col), tm
            asserts += 1
        g = (g + script.delta_t) % (1 << 64)


# ---- differential: compiled interpreter vs tree walk ---------------------------------------------

edge_floats = st.sampled_from([
    0.0, -0.0, 1.0, -1.0, 0.5, -0.5, 2.5, -2.9, 255.5, 256.0, 65535.99, -32768.5, 2.0**31, -(2.0**31) - 1,
    2.0**32, 2.0**53 + 2, 2.0**63, -(2.0**63), 2.0**64, 2.0**64 - 2048, 16777217.0, 3.4028235e38, 3.5e38,
    1e-45, 1e-310, math.inf, -math.inf, math.nan])
any_floats = st.one_of(edge_floats, st.floats(), st.floats(width=32),
                       st.integers(-(2**65), 2**65).map(float))


@cases(80, **NO_SHRINK)
@given(T.programs(), st.data())
def test_machine_steps_match_tree_walk(p, data):
    """Random inputs, then a step, in both modes: every variable, the
    state and the step's result agree after every step."""
    m, script = compile_program(p)
    writable = [v.index for v in m.vars if v.kind != M.TIME_IN_STATE and v.index not in (m.g, m.s)]
    init = data.draw(st.integers(0, len(m.states) - 1))
    runs = [(MachineRun(m, real, init), TreeMachine(m, real, init)) for real in REAL_MODES]
    g = 0
    for step in range(data.draw(st.integers(1, 25))):
        inputs = data.draw(st.lists(st.tuples(st.sampled_from(writable), any_floats), max_size=4)) if writable else []
        g += data.draw(st.sampled_from((1, 10, 1000, 0))) if step else 0
        for fast, slow in runs:
            for i, x in inputs:
                fast.v[i] = slow.v[i] = to_type(m.vars[i].type, x)
            fast.v[m.g] = slow.v[m.g] = g
            a, b = fast.step(), slow.step()
            where = f"{fast.real} step {step + 1}"
            assert a == b, where
            assert (fast.state, fast.first) == (slow.state, slow.first), where
            assert_same_values(fast.v, slow.v, m, where)
            assert [same(x, y) for x, y in zip(fast.wv, slow.wv)] == [True] * len(m.windows), where


@cases(80, **NO_SHRINK)
@given(T.programs())
def test_script_runs_match_tree_walk(p):
    m, script = compile_program(p)
    for real in REAL_MODES:
        res = run_script(script, real)
        assert res.steps <= 61  # the generated stop (strategies.scripts) is always reached
        passed, steps, asserts, failure, tm = tree_script(script, real)
        where = f"{real}\n{p.sm_text}\n{p.ss_text}"
        assert (res.passed, res.steps, res.asserts) == (passed, steps, asserts), where
        assert (None if res.failure is None else (res.failure.line, res.failure.col)) == failure, where
        expected = sorted(((var.display, format_value(var.type, tm.v[var.index])) for var in m.vars),
                          key=lambda row: row[0].encode())
        assert res.values == expected, where


# ---- differential: single expressions ---------------------------------------------------------------

# One variable of every type to read, and one of every type to write.
_TYPES = T.TYPE_NAMES
IN = {t: i for i, t in enumerate(_TYPES)}
OUT = {t: len(_TYPES) + i for i, t in enumerate(_TYPES)}
G_, S_, T_ = 2 * len(_TYPES), 2 * len(_TYPES) + 1, 2 * len(_TYPES) + 2


def _vars():
    out = [M.Var(i, M.ELEMENT, f"in_{t}", None, TYPES[t], False, 0) for t, i in IN.items()]
    out += [M.Var(i, M.ELEMENT, f"out_{t}", None, TYPES[t], False, 0) for t, i in OUT.items()]
    out += [M.Var(G_, M.ELEMENT, "G", None, TYPES["U64"], True, 0),
            M.Var(S_, M.ELEMENT, "S", None, TYPES["U32"], True, 0),
            M.Var(T_, M.TIME_IN_STATE, "T", None, TYPES["U64"], True, 0)]
    return tuple(out)


VARS = _vars()
SV = M.StateVector("p.sv", False, (), (), 0)


@st.composite
def model_exprs(draw, depth: int = 4):
    """Model expressions over VARS, with `roll_*` calls (windows numbered later)."""
    k = draw(st.integers(0, 12)) if depth else draw(st.integers(0, 2))
    sub = model_exprs(depth - 1) if depth else None
    if k == 0:
        return M.Const(draw(T.NUMBERS), 0, 0)
    if k in (1, 2):
        return M.Ref(draw(st.sampled_from([*IN.values(), G_, S_, T_])), 0, 0)
    if k == 3:
        return M.Neg(draw(sub), 0, 0)
    if k == 4:
        return M.Not(draw(sub), 0, 0)
    if k in (5, 6, 7):
        return M.Arith(draw(st.sampled_from(T.ARITH)), draw(sub), draw(sub), 0, 0)
    if k == 8:
        return M.Cmp(draw(st.sampled_from(T.RELATIONAL + ("==", "!="))), draw(sub), draw(sub), 0, 0)
    if k == 9:
        n = draw(st.integers(2, 3))
        return M.ChainCmp(tuple(draw(sub) for _ in range(n + 1)),
                          tuple(draw(st.sampled_from(T.RELATIONAL)) for _ in range(n)), 0, 0)
    if k == 10:
        return M.Logic(draw(st.sampled_from(("and", "or"))), draw(sub), draw(sub), 0, 0)
    func = draw(st.sampled_from(("avg", "median", "min", "max", "range")))
    return M.Roll(func, draw(sub), draw(st.integers(1, 4)), -1, 0, 0)


def number_windows(e: M.Expr, windows: list) -> M.Expr:
    """Gives each roll_* call its window, inner calls first (as the checker does)."""
    if isinstance(e, M.Roll):
        arg = number_windows(e.arg, windows)
        w = M.Window(len(windows), e.func, e.size, arg, 0, 0)
        windows.append(w)
        return replace(e, arg=arg, window=w.index)
    if isinstance(e, (M.Neg, M.Not)):
        return replace(e, operand=number_windows(e.operand, windows))
    if isinstance(e, (M.Arith, M.Cmp, M.Logic)):
        return replace(e, left=number_windows(e.left, windows), right=number_windows(e.right, windows))
    if isinstance(e, M.ChainCmp):
        return replace(e, operands=tuple(number_windows(o, windows) for o in e.operands))
    return e


def stored(t: str):
    """Values an element of type `t` can hold (every write goes through to_type)."""
    ty = TYPES[t]
    if ty.kind == "float":
        return any_floats.map(lambda x: to_type(ty, x))
    return st.one_of(st.integers(ty.lo, ty.hi),
                     st.sampled_from([ty.lo, ty.hi, 0, 1, min(ty.hi, 2**24 + 1), min(ty.hi, 2**53 + 1)]))


inputs = st.fixed_dictionaries({t: stored(t) for t in _TYPES})


@st.composite
def deep_model_exprs(draw):
    """An expression nested 30 to 90 levels deep (past the depth where the
    interpreter hands subtrees to the tree walker)."""
    e = draw(model_exprs(1))
    for _ in range(draw(st.integers(30, 90))):
        k = draw(st.integers(0, 5)) if draw(st.integers(0, 19)) == 0 else draw(st.integers(0, 4))
        other = draw(model_exprs(0))
        if k == 0:
            e = M.Neg(e, 0, 0)
        elif k == 1:
            e = M.Not(e, 0, 0)
        elif k == 2:
            e = M.Arith(draw(st.sampled_from(T.ARITH)), *draw(st.permutations([e, other])), 0, 0)
        elif k == 3:
            e = M.Logic(draw(st.sampled_from(("and", "or"))), *draw(st.permutations([e, other])), 0, 0)
        elif k == 4:
            e = M.ChainCmp((other, e, other), ("<=", "<"), 0, 0)
        else:
            e = M.Roll(draw(st.sampled_from(("avg", "max", "range"))), e, 2, -1, 0, 0)
    return e


@cases(200)
@given(st.one_of(model_exprs(), model_exprs(), model_exprs(), deep_model_exprs()),  # a quarter deep
       st.lists(inputs, min_size=1, max_size=4))
def test_expressions_match_tree_walk(e, steps):
    """One machine assigns the expression to an element of every type and
    branches on it; after every step both runs hold the same bits."""
    windows: list = []
    e = number_windows(e, windows)
    body = tuple(M.Assign(i, e, 0, 0) for i in OUT.values())
    body += (M.If(e, (M.Assign(OUT["bool"], M.Const("1", 0, 0), 0, 0),),
                  (M.Assign(OUT["bool"], M.Const("0", 0, 0), 0, 0),), 0, 0),)
    state = M.State(0, 1, "A", 0, (), body, ())
    m = M.Machine("p.sm", "p", SV, VARS, (state,), tuple(windows), G_, S_, T_)
    for real in REAL_MODES:
        fast, slow = MachineRun(m, real), TreeMachine(m, real)
        for k, values in enumerate(steps):
            for t, x in values.items():
                fast.v[IN[t]] = slow.v[IN[t]] = x
            fast.v[G_] = slow.v[G_] = 7 * k
            assert fast.step() == slow.step() == OK
            assert_same_values(fast.v, slow.v, m, f"{real} step {k + 1}: {unparse.model_expr(e, m)}")


@cases(200)
@given(st.one_of(model_exprs(), model_exprs(), model_exprs(), deep_model_exprs()), inputs,
       st.lists(st.one_of(any_floats, st.just(math.nan)), min_size=40, max_size=40))
def test_compiled_values_match_evaluate(e, values, wv):
    """The raw R value (before any conversion) and the truth of a condition."""
    windows: list = []
    e = number_windows(e, windows)
    assume(len(windows) <= len(wv))
    for real in REAL_MODES:
        v = [0.0 if var.type.kind == "float" else 0 for var in VARS]
        for t, x in values.items():
            v[IN[t]] = x
        v[G_], v[S_], v[T_] = 2**64 - 1, 3, 2**53 + 1
        w = [real.rnd(x) for x in wv]
        em = _Emitter(VARS, real)
        src = f"def value(v, wv):\n    return {em.value(e)}\ndef cond(v, wv):\n    return {em.cond(e)}\n"
        ns = compile_functions(src, "prop", {"_deep": getattr(em, "deep", [])})
        want = evaluate(e, real, lambda i: real.read(VARS[i].type, v[i]), w.__getitem__)
        got = ns["value"](v, w)
        assert same(float(got), want), f"{real}: {got!r} != {want!r}"
        assert ns["cond"](v, w) is truthy(want)


# ---- independent oracles: numpy float32 and C conversions -------------------------------------------

f32_values = st.floats(width=32)


@cases(500)
@given(f32_values, st.lists(st.tuples(st.sampled_from(T.ARITH), f32_values), min_size=1, max_size=8),
       st.sampled_from(["F32", "F64"]))
def test_binary32_arithmetic_is_numpy_float32(first, chain, storage):
    """((x0 op x1) op x2) ... in binary32 mode, values read from F32 or F64
    elements, equals numpy's float32 arithmetic bit for bit."""
    t = TYPES[storage]
    vars_ = tuple(M.Var(i, M.ELEMENT, f"x{i}", None, t, False, 0) for i in range(len(chain) + 1))
    values = [first] + [x for _, x in chain]
    stored_ = [to_type(t, x) for x in values]  # NaN is stored as 0
    e: M.Expr = M.Ref(0, 0, 0)
    for i, (op, _) in enumerate(chain):
        e = M.Arith(op, e, M.Ref(i + 1, 0, 0), 0, 0)
    with np.errstate(all="ignore"):
        acc = np.float32(stored_[0])
        for (op, _), x in zip(chain, stored_[1:]):
            x = np.float32(x)
            acc = {"+": acc + x, "-": acc - x, "*": acc * x, "/": acc / x}[op]
    want = float(acc)
    got = evaluate(e, F32MODE, lambda i: F32MODE.read(t, stored_[i]))
    assert same(got, want), f"{got!r} != numpy {want!r}"
    em = _Emitter(vars_, F32MODE)
    ns = compile_functions(f"def f(v, wv):\n    return {em.value(e)}\n", "prop", {"_deep": getattr(em, "deep", [])})
    compiled = ns["f"](stored_, [])
    assert same(compiled, want), f"compiled {compiled!r} != numpy {want!r}"


def exact_int_conversion(ty, x: float) -> int:
    """Spec §4.5 with exact rationals: NaN -> 0, clamp, truncate toward zero."""
    if x != x:
        return 0
    if x == math.inf:
        return ty.hi
    if x == -math.inf:
        return ty.lo
    q = Fraction(x)
    q = min(max(q, Fraction(ty.lo)), Fraction(ty.hi))
    return int(q)  # int() of a Fraction truncates toward zero


NP_INT = {"I8": np.int8, "I16": np.int16, "I32": np.int32, "I64": np.int64,
          "U8": np.uint8, "U16": np.uint16, "U32": np.uint32, "U64": np.uint64}


@cases(1000)
@given(any_floats, st.sampled_from(_TYPES))
def test_conversions_match_c(x, tname):
    ty = TYPES[tname]
    got = to_type(ty, x)
    if ty.kind == "int":
        assert type(got) is int
        assert got == exact_int_conversion(ty, x)
        if math.isfinite(x) and ty.lo <= math.trunc(x) <= ty.hi:
            # In range: C's cast (truncation), as numpy does it.
            assert got == int(np.array([x], dtype=np.float64).astype(NP_INT[tname])[0])
    elif ty.kind == "bool":
        assert got == (0 if x != x or x == 0 else 1)
    elif x != x:
        assert same(got, 0.0)
    elif ty.size == 4:
        with np.errstate(over="ignore"):
            assert same(got, float(np.float32(x)))  # IEEE rounding, overflow to inf
    else:
        assert same(got, x)


def assert_nearest_binary32(r: float, q: Fraction) -> None:
    """`r` is the binary32 nearest `q` (ties to even), as IEEE rounds."""
    assert float(np.float32(r)) == r or math.isinf(r), f"{r!r} is not a binary32"
    big = Fraction(2**128) - Fraction(2**103)  # halfway from the largest binary32 to 2^128
    if math.isinf(r):
        assert abs(q) >= big and math.copysign(1, r) == (1 if q > 0 else -1)
        return
    assert abs(q) < big  # at `big` itself the tie goes to 2^128 (FLT_MAX's mantissa is odd)
    f = np.float32(r)
    d = abs(q - Fraction(r))
    with np.errstate(over="ignore"):
        neighbours = (np.nextafter(f, np.float32(np.inf)), np.nextafter(f, np.float32(-np.inf)))
    for nb in neighbours:
        if np.isinf(nb):
            continue
        dn = abs(q - Fraction(float(nb)))
        assert d <= dn, f"{float(nb)!r} is nearer to {q} than {r!r}"
        if d == dn:  # a tie: the even mantissa wins
            assert int(np.array([r], dtype=np.float32).view(np.uint32)[0]) % 2 == 0, (r, q)


@st.composite
def near_midpoints(draw) -> str:
    """A decimal just above or below the midpoint of two adjacent binary32
    values: rounding it to binary64 first lands on the midpoint, and then
    ties-to-even picks the wrong neighbour (double rounding)."""
    import decimal

    a = np.array([draw(st.integers(1, 0x7F7FFFFE))], dtype=np.uint32).view(np.float32)[0]
    b = np.nextafter(a, np.float32(np.inf))
    mid = (Fraction(float(a)) + Fraction(float(b))) / 2
    side = draw(st.sampled_from([1, -1]))
    # 60 digits, or 400 (past the 200 that rounding keeps, the rest sticky)
    prec, off = draw(st.sampled_from([(60, 30), (400, 300), (400, 10)]))
    q = mid + side * mid / 10**off
    with decimal.localcontext() as c:
        c.prec = prec
        text = str(decimal.Decimal(q.numerator) / decimal.Decimal(q.denominator))
    return text.replace("E+", "e").replace("E", "e")


@cases(500)
@given(st.one_of(T.NUMBERS, st.from_regex(r"[0-9]{1,25}(\.[0-9]{1,25})?([eE][+-]?[0-9]{1,2})?", fullmatch=True),
                 near_midpoints()))
def test_binary32_literals_are_correctly_rounded(text):
    r = F32MODE.literal(text)
    assert_nearest_binary32(r, Fraction(text))


@cases(500)
@given(st.one_of(st.integers(-(2**64), 2**64),
                 st.integers(1, 2**40).map(lambda k: k * 2**24 + 2**23),  # ties
                 st.sampled_from([2**24 + 1, 2**24 + 3, 2**63 - 1, -(2**63), 2**64 - 1])))
def test_binary32_integers_are_correctly_rounded(i):
    assert_nearest_binary32(F32MODE.from_int(i), Fraction(i))
    assert F64MODE.from_int(i) == float(i)


# ---- rolling windows hold the last N samples ------------------------------------------------------------

@cases(300)
@given(st.sampled_from(["min", "max", "range", "median", "avg"]), st.integers(1, 8),
       st.lists(st.one_of(st.floats(-1e6, 1e6), st.sampled_from([0.0, -0.0, math.nan, 1.5, -1.5])),
                min_size=1, max_size=40),
       st.sampled_from(REAL_MODES))
def test_windows_hold_the_last_n_samples(func, n, samples, real):
    w = make_window(func, n, real)
    seen: list[float] = []
    for x in samples:
        x = real.rnd(x)
        got = w.push(x)
        seen.append(0.0 if x != x else x)
        buf = sorted(seen[-n:])
        if func == "min":
            assert got == buf[0]
        elif func == "max":
            assert got == buf[-1]
        elif func == "range":
            assert got == real.rnd(buf[-1] - buf[0])
        elif func == "median":
            k = len(buf)
            a, b = buf[(k - 1) // 2], buf[k // 2]
            assert got == (a if k % 2 else real.rnd(a + real.rnd(real.rnd(b - a) / 2)))
        else:
            exact = sum(Fraction(y) for y in buf) / len(buf)
            # The running sum is exact again after every lap of N samples, so
            # its rounding error is bounded by the samples of the last 2N.
            eps, tiny = (2.0**-24, 2.0**-149) if real is F32MODE else (2.0**-53, 2.0**-1074)
            bound = 4 * (n + 1) * (eps * max(abs(y) for y in seen[-2 * n:]) + tiny)
            assert abs(Fraction(got) - exact) <= Fraction(bound), (got, float(exact))
