"""The reference interpreter: runs a checked machine with the exact step
semantics of spec §4.6 in binary64 or binary32.

For speed the model is translated into Python functions once (the text
holds only variable indices and float literals — no user text), then each
step is plain Python. `fswkit.autocode.evaluate` states the same semantics
as a direct tree walk; the tests hold the two to identical results."""

from __future__ import annotations

import functools
import math

from fswkit.autocode import model as M
from fswkit.autocode.evaluate import evaluate
from fswkit.autocode.numeric import Real, div, f32, f32_from_int
from fswkit.run.windows import make_window

OK = 0
ERR_TIME = 1  # G did not increase since the previous step

# Expression nodes nested deeper than this are handed to the tree walker of
# fswkit.autocode.evaluate (the same semantics), so the generated Python
# stays far below its parser's limit of 200 nested parentheses (each level
# here opens at most 2).
DEEP = 40


def _walker(e: M.Expr, vars_, real: Real):
    types = [var.type for var in vars_]

    def run(v, wv):
        return evaluate(e, real, lambda i: real.read(types[i], v[i]), wv.__getitem__)
    return run


class _Emitter:
    """Python source for expressions and statements of one model."""

    def __init__(self, vars_, real: Real, wv: str = "wv"):
        self.vars = vars_
        self.real = real
        self.wv = wv
        self.tmp = 0
        self.consts: dict[str, float] = {}
        self.depth = 0
        self.deep: list = []  # `_deep[k]` of the generated code: see DEEP
        self.cover = False  # record each transition taken: `_C(line, col)` before it

    def walk(self, e: M.Expr) -> str:
        self.deep.append(_walker(e, self.vars, self.real))
        return f"_deep[{len(self.deep) - 1}](v, {self.wv})"

    def temp(self) -> str:
        self.tmp += 1
        return f"_t{self.tmp}"

    def const(self, x: float) -> str:
        if x != x:
            return "_NAN"
        if x in (math.inf, -math.inf):
            return "_INF" if x > 0 else "(-_INF)"
        return repr(x)

    def read(self, i: int) -> str:
        t = self.vars[i].type
        f32mode = self.real.bits == 32
        if t.kind == "float":
            # Stored values are never NaN: every write goes through to_type.
            return f"_f32(v[{i}])" if f32mode and t.size == 8 else f"v[{i}]"
        if f32mode and t.size >= 4:
            return f"_fi(v[{i}])"
        return f"float(v[{i}])"

    def rnd(self, text: str) -> str:
        return f"_f32({text})" if self.real.bits == 32 else text

    def value(self, e: M.Expr) -> str:
        """An expression giving the R value."""
        if self.depth >= DEEP:
            return self.walk(e)
        self.depth += 1
        try:
            return self._value(e)
        finally:
            self.depth -= 1

    def _value(self, e: M.Expr) -> str:
        t = type(e)
        if t is M.Const:
            return self.const(self.real.literal(e.text))
        if t is M.Ref:
            return self.read(e.var)
        if t is M.Neg:
            return f"(-{self.value(e.operand)})"
        if t is M.Arith:
            a, b = self.value(e.left), self.value(e.right)
            if e.op == "/":
                return self.rnd(f"_div({a}, {b})")
            return self.rnd(f"({a} {e.op} {b})")
        if t is M.Roll:
            return f"{self.wv}[{e.window}]"
        return f"(1.0 if {self.cond(e)} else 0.0)"

    def cond(self, e: M.Expr) -> str:
        """An expression giving a Python bool: true when non-zero, not NaN."""
        if self.depth >= DEEP:
            x = self.temp()
            return f"(({x} := {self.walk(e)}) != 0 and {x} == {x})"
        self.depth += 1
        try:
            return self._cond(e)
        finally:
            self.depth -= 1

    def _cond(self, e: M.Expr) -> str:
        t = type(e)
        if t is M.Cmp:
            return f"({self.value(e.left)} {e.op} {self.value(e.right)})"
        if t is M.ChainCmp:
            parts = [self.value(e.operands[0])]
            for op, o in zip(e.ops, e.operands[1:]):
                parts += [op, self.value(o)]
            return "(" + " ".join(parts) + ")"
        if t is M.Logic:
            return f"({self.cond(e.left)} {e.op} {self.cond(e.right)})"
        if t is M.Not:
            return f"(not {self.cond(e.operand)})"
        x = self.temp()
        return f"(({x} := {self.value(e)}) != 0 and {x} == {x})"

    def assign(self, var: int, e: M.Expr) -> str:
        t = self.vars[var].type
        if t.kind == "bool":
            return f"v[{var}] = 1 if {self.cond(e)} else 0"
        x = self.temp()
        if t.kind == "int":
            return (f"v[{var}] = 0 if ({x} := {self.value(e)}) != {x} else "
                    f"{t.lo} if {x} <= {t.lo} else {t.hi} if {x} >= {t.hi} else int({x})")
        if t.size == 4 and self.real.bits == 64:
            return f"v[{var}] = 0.0 if ({x} := {self.value(e)}) != {x} else _f32({x})"
        return f"v[{var}] = 0.0 if ({x} := {self.value(e)}) != {x} else {x}"

    def block(self, stmts, indent: str, out: list[str]) -> None:
        """Statements of a machine block; a transition returns its target."""
        for st in stmts:
            t = type(st)
            if t is M.Assign:
                out.append(indent + self.assign(st.var, st.expr))
            elif t is M.Goto:
                if self.cover:
                    out.append(f"{indent}_C(({st.line}, {st.col}))")
                out.append(f"{indent}return {st.state}")
                return  # nothing after a transition can run
            else:
                out.append(f"{indent}if {self.cond(st.cond)}:")
                n = len(out)
                self.block(st.then, indent + "    ", out)
                if len(out) == n:
                    out.append(indent + "    pass")
                if st.orelse:
                    out.append(indent + "else:")
                    self.block(st.orelse, indent + "    ", out)


GLOBALS = {"_f32": f32, "_fi": f32_from_int, "_div": div, "_NAN": math.nan, "_INF": math.inf}


@functools.lru_cache(maxsize=64)
def _code(source: str, name: str):
    """The compiled code of generated source: a machine run again (every
    script of a test, each test of a batch) is not compiled again."""
    return compile(source, f"<fswkit:{name}>", "exec")


def compile_functions(source: str, name: str, extra: dict | None = None) -> dict:
    """The namespace of Python source generated from the model (the
    machine's or a script's functions), with the R helpers it calls."""
    namespace = dict(GLOBALS)
    namespace.update(extra or {})
    exec(_code(source, name), namespace)  # generated from the model only
    return namespace


class MachineRun:
    """One machine executing: its variables and its state bookkeeping."""

    def __init__(self, m: M.Machine, real: Real, init_state: int = 0, cover: bool = False):
        """`cover`: keep the (line, col) of every transition taken, and
        every state entered, in `taken` and `visited` (fsw test --coverage)."""
        self.m = m
        self.taken: set[tuple[int, int]] = set()
        self.visited: set[int] = {init_state}
        self.real = real
        self.v: list = [0] * len(m.vars)
        for var in m.vars:
            if var.type.kind == "float":
                self.v[var.index] = 0.0
        from fswkit.autocode.evaluate import local_values
        for i, val in local_values(m, real).items():
            self.v[i] = val
        self.wv = [0.0] * len(m.windows)
        self.windows = [make_window(w.func, w.size, real) for w in m.windows]
        self.state = init_state
        self.first = True
        self.entry_time = 0
        self.prev_g = None
        em = _Emitter(m.vars, real)
        em.cover = cover
        src = ["def update(v, wv, W):"]
        for w in m.windows:
            src.append(f"    wv[{w.index}] = W[{w.index}]({em.value(w.arg)})")
        src.append("    pass")
        for st in m.states:
            for label in ("entry", "step", "exit"):
                src.append(f"def s{st.index}_{label}(v, wv):")
                em.block(getattr(st, label), "    ", src)
                src.append("    return -1")
        ns = compile_functions("\n".join(src) + "\n", m.name, {"_deep": em.deep, "_C": self.taken.add})
        self._update = ns["update"]
        self._push = [w.push for w in self.windows]
        self._entry = [ns[f"s{i}_entry"] for i in range(len(m.states))]
        self._step = [ns[f"s{i}_step"] for i in range(len(m.states))]
        self._exit = [ns[f"s{i}_exit"] for i in range(len(m.states))]

    def pre_step_view(self, g: int) -> None:
        """Sets S and T to the values the machine will have during the next
        step at time `g` (what a state script sees before the step)."""
        v, m = self.v, self.m
        v[m.s] = self.state + 1
        # U64 arithmetic, as the machine keeps T: when `G` wrapped around
        # (the step will be refused) the difference wraps too.
        v[m.t] = 0 if self.first else (g - self.entry_time) % (1 << 64)

    def step(self) -> int:
        m, v = self.m, self.v
        g = v[m.g]
        if self.prev_g is not None and not g > self.prev_g:
            return ERR_TIME
        self.prev_g = g
        st = self.state
        if self.first:
            self.entry_time = g
            v[m.s] = st + 1
        v[m.t] = g - self.entry_time
        if self._push:
            self._update(v, self.wv, self._push)
        wv = self.wv
        k = -1
        if self.first:
            self.first = False
            k = self._entry[st](v, wv)
        if k < 0:
            k = self._step[st](v, wv)
        if k >= 0:
            self._exit[st](v, wv)
            self.state = k
            self.first = True
            self.visited.add(k)
        return OK

    def values(self) -> list[tuple[str, str]]:
        """(name, formatted value) of every variable, sorted by name bytes."""
        from fswkit.autocode.numeric import format_value
        rows = [(var.display, format_value(var.type, self.v[var.index])) for var in self.m.vars]
        return sorted(rows, key=lambda r: r[0].encode())

