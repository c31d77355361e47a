"""`fsw skeleton`: a state-script skeleton that drives a machine through
every state and transition it can, found by searching for inputs with the
reference interpreter (binary64), with `@assert` placeholders to complete.

The search, in short. A *configuration* is the machine just entering a state
(or starting): its variables, windows and state. From a configuration, for
each transition out of its state, candidate inputs are tried by simulation:
none (just wait: `T` grows, counters count), then one writable variable at a
time set to values taken from the guards (each constant, ±1, ±0.5, the value
that solves a comparison against the variable, 0, halfway points; true and
false for booleans), then a combination chosen to satisfy the most terms of
the guard while keeping the transitions that would fire first from firing
(tried before the single changes when it satisfies every term that does not
wait on the clock), then inputs one step after entry, then pairs. Every
transition that fires
gives a move to a new configuration. A script follows one path, so runs are
built greedily: from the start, a breadth-first search over configurations
finds the nearest transition not yet taken, preferring one after which the
other untaken transitions stay reachable; a run ends when nothing more can be
taken from where it stands (a state no transition leaves, say), and the next
run starts over. Everything is bounded by simulated steps, never by the
clock, so the output is byte-reproducible."""

from __future__ import annotations

import itertools
import math
import operator
import os
from collections import deque
from dataclasses import dataclass, field, replace

from fswkit.autocode import model as M
from fswkit.autocode.check import assigned_vars, fold, model_children
from fswkit.autocode.evaluate import NotConstant, compare, evaluate, local_values
from fswkit.autocode.numeric import F64MODE, to_type, truthy
from fswkit.autocode.types import TYPES
from fswkit.autocode.emit.graph import Arrow, describe, guard_expr, transitions
from fswkit.run.interp import MachineRun
from fswkit.run.windows import Window

# Bounds of the search. All count simulated machine steps or searched
# configurations, so the result never depends on the speed of the machine.
STEP_BUDGET = 2_000_000  # simulated steps in all
WAIT_MIN, WAIT_CAP = 64, 50_000  # steps one candidate may wait for a transition
MAX_VALUES = 48  # candidate values per variable
MAX_LATE_VALUES = 12  # of which tried one step late
MAX_PAIRS = 256  # two-variable candidates per transition
GIVE_UP_AFTER = 3  # configurations a transition may fail from before it is no longer tried
MAX_EXPANSIONS = 64  # configurations one path search expands
MAX_RUNS = 12  # scripts in one skeleton
DEFAULT_MAX_STEPS = 1_000_000  # a script's own default (spec §5)
U64_MAX = (1 << 64) - 1


# ---- the plan ---------------------------------------------------------------------

@dataclass
class Config:
    """The machine about to take the first step of a state (or the very
    first step), at time `g`."""
    state: int
    g: int
    snap: tuple
    key: tuple
    moves: dict = field(default_factory=dict)  # transition index -> Move
    tried: set = field(default_factory=set)  # transitions already searched for here
    memo: dict = field(default_factory=dict)  # (candidate, wait) -> simulation result


@dataclass(frozen=True)
class Move:
    """From a configuration: set `inputs` (step offset, ((var, text), ...)),
    step `steps` times; the last step takes transition `t`."""
    t: int
    inputs: tuple
    steps: int
    child: Config


@dataclass(frozen=True)
class Run:
    """One script: the transitions it takes, in order."""
    moves: tuple[Move, ...]

    @property
    def taken(self) -> list[int]:
        """Transition indices, each once, in the order first taken."""
        out: list[int] = []
        for e in self.moves:
            if e.t not in out:
                out.append(e.t)
        return out


@dataclass
class Plan:
    machine: M.Machine
    delta_t: int
    transitions: list[Arrow]
    runs: list[Run]
    not_reached: dict[int, str]  # transition index -> why
    steps_used: int
    exhausted: bool


# ---- instrumentation: which transition fired ------------------------------------

def instrument(m: M.Machine) -> tuple[M.Machine, int]:
    """A copy of `m` with one more U32 variable (the last) that each
    transition sets to its index + 1 just before it fires (indices as in
    `graph.transitions`). Nothing else changes; 0 means none fired."""
    hit = len(m.vars)
    var = M.Var(hit, M.ELEMENT, "(transition)", None, TYPES["U32"], False, 0)
    counter = itertools.count(1)

    def rewrite(stmts):
        out = []
        for s in stmts:
            if isinstance(s, M.Goto):
                out.append(M.Assign(hit, M.Const(str(next(counter)), s.line, s.col), s.line, s.col))
                out.append(s)
            elif isinstance(s, M.If):
                out.append(M.If(s.cond, rewrite(s.then), rewrite(s.orelse), s.line, s.col))
            else:
                out.append(s)
        return tuple(out)

    states = []
    for st in m.states:  # the order of graph.transitions: entry, then step
        entry = rewrite(st.entry)
        step = rewrite(st.step)
        states.append(replace(st, entry=entry, step=step))
    return replace(m, vars=m.vars + (var,), states=tuple(states)), hit


# ---- static analysis of the machine ------------------------------------------------

def _nodes(e: M.Expr):
    todo = [e]
    while todo:
        n = todo.pop()
        yield n
        todo.extend(model_children(n))


def _refs(e: M.Expr) -> set[int]:
    return {n.var for n in _nodes(e) if isinstance(n, M.Ref)}


def _pairs(e: M.Expr):
    """The compared pairs of every comparison in `e`, outermost first."""
    out = []
    todo = [e]
    while todo:
        n = todo.pop(0)
        if isinstance(n, M.Cmp):
            out.append((n.left, n.right))
        elif isinstance(n, M.ChainCmp):
            out += list(zip(n.operands, n.operands[1:]))
        todo.extend(model_children(n))
    return out


class _Analysis:
    """What the search needs to know about a machine before running it."""

    def __init__(self, m: M.Machine, trans: list[Arrow], delta_t: int):
        self.m = m
        try:
            self.consts = local_values(m, F64MODE)
        except NotConstant:  # the checker refuses such a machine; be safe anyway
            self.consts = {}
        owned = {m.g, m.s, m.t}
        self.assigned: set[int] = set()
        self.deps: dict[int, set[int]] = {}
        self.feeds: dict[int, list[M.Expr]] = {}  # var -> what its assignments compute and depend on
        self.exprs: list[M.Expr] = []  # every expression, in file order
        state_refs: dict[int, set[int]] = {}

        def walk(stmts, conds: list[M.Expr], refs: set[int]):
            for s in stmts:
                if isinstance(s, M.Assign):
                    self.assigned.add(s.var)
                    d = self.deps.setdefault(s.var, set())
                    d |= _refs(s.expr)
                    for c in conds:
                        d |= _refs(c)
                    self.feeds.setdefault(s.var, []).extend([s.expr] + conds)
                    self.exprs.append(s.expr)
                    refs |= _refs(s.expr)
                elif isinstance(s, M.If):
                    self.exprs.append(s.cond)
                    refs |= _refs(s.cond)
                    walk(s.then, conds + [s.cond], refs)
                    walk(s.orelse, conds + [s.cond], refs)

        for st in m.states:
            refs: set[int] = set()
            walk(st.entry, [], refs)
            walk(st.step, [], refs)
            walk(st.exit, [], set())
            state_refs[st.index] = refs
        window_refs: set[int] = set()
        for w in m.windows:
            self.exprs.append(w.arg)
            window_refs |= _refs(w.arg)
        # Variables whose value follows the clock: T, G, and what is computed from them.
        self.time_like = {m.t, m.g}
        changed = True
        while changed:
            changed = False
            for x, d in self.deps.items():
                if x not in self.time_like and d & self.time_like:
                    self.time_like.add(x)
                    changed = True
        self.reads_g = any(m.g in _refs(e) for e in self.exprs)
        # A state is timed when what it does may change with time alone.
        self.timed = {i: bool((r | window_refs) & self.time_like) for i, r in state_refs.items()}
        self.max_window = max((w.size for w in m.windows), default=0)
        self.pairs = [p for e in self.exprs for p in _pairs(e)]
        self.dt = delta_t
        self.pool = self._pool()
        # Who may be written by the script, most natural first: elements the
        # machine only reads (sensors), elements it writes, its writable
        # locals, and last its read-only locals (constants of the machine).
        self.tier: dict[int, int] = {}
        for v in m.vars:
            if v.index in owned:
                continue
            if v.kind == M.ELEMENT:
                self.tier[v.index] = 1 if v.index in self.assigned else 0
            elif v.kind == M.LOCAL:
                self.tier[v.index] = 3 if v.read_only else 2
        self.sensors = [v.index for v in m.vars if self.tier.get(v.index) == 0]
        self.static_reach = self._static_reach(trans)

    def const_value(self, e: M.Expr) -> float | None:
        """A compile-time value: a literal, or a local that keeps its initial value."""
        if isinstance(e, M.Const):
            return F64MODE.literal(e.text)
        if isinstance(e, M.Ref) and e.var in self.consts and e.var not in self.assigned:
            return F64MODE.read(self.m.vars[e.var].type, self.consts[e.var])
        return None

    def _consts_in(self, e: M.Expr) -> list[float]:
        out = []
        for n in _nodes(e):
            c = self.const_value(n)
            if c is not None and math.isfinite(c):
                out.append(c)
        return out

    def closure(self, t: Arrow) -> list[int]:
        """The variables `t`'s guard reads, then those the machine computes
        them from, and so on."""
        order: list[int] = []
        todo = deque()
        for cond, _ in t.path:
            for n in _refs_in_order(cond):
                if n not in order:
                    order.append(n)
                    todo.append(n)
        while todo:
            x = todo.popleft()
            for n in sorted(self.deps.get(x, ())):
                if n not in order:
                    order.append(n)
                    todo.append(n)
        return order

    def wait_limit(self, t: Arrow) -> int:
        """How many steps a candidate for `t` waits: enough for `T` to pass
        every constant it is compared with in `t`'s guard (or in what that
        guard is computed from), and for a counter of the machine to count
        (twice over) to every constant it is compared with there."""
        exprs = [c for c, _ in t.path]
        for x in self.closure(t):
            exprs += self.feeds.get(x, [])
        dt = self.dt
        lim = WAIT_MIN
        for a, b in (p for e in exprs for p in _pairs(e)):
            refs = _refs(a) | _refs(b)
            cs = [abs(c) for c in self._consts_in(a) + self._consts_in(b)]
            if not cs:
                continue
            c = max(cs)
            if refs & self.time_like:
                lim = max(lim, int(min(c / dt, WAIT_CAP)) + 2)
            if refs & self.assigned:
                lim = max(lim, int(min(2 * c, WAIT_CAP)) + 2)
        return min(lim + self.max_window, WAIT_CAP)

    def _pool(self) -> list[float]:
        """Values worth trying anywhere: each constant of the machine, ±1,
        ±0.5, its negation, 0, and the halfway points between constants."""
        seen: list[float] = []
        for e in self.exprs:
            for c in self._consts_in(e):
                if c not in seen:
                    seen.append(c)
        out: list[float] = []
        for c in seen:
            out += [c, c + 1, c - 1, c + 0.5, c - 0.5, -c]
        out.append(0.0)
        s = sorted(set(seen))
        out += [a + (b - a) / 2 for a, b in zip(s, s[1:])]
        return [x for x in out if math.isfinite(x)]

    def _static_reach(self, trans: list[Arrow]) -> dict[int, set[int]]:
        """The states each state can reach along transitions (itself included)."""
        nxt: dict[int, set[int]] = {st.index: set() for st in self.m.states}
        for t in trans:
            nxt[t.source].add(t.target)
        out = {}
        for s in nxt:
            seen = {s}
            todo = [s]
            while todo:
                for n in nxt[todo.pop()]:
                    if n not in seen:
                        seen.add(n)
                        todo.append(n)
            out[s] = seen
        return out

    def relevant(self, t: Arrow, rivals: list[M.Expr]) -> list[int]:
        """The writable variables that can affect `t`'s guard: those it reads,
        those the machine computes them from, then those read by the guards
        of the `rivals` that would fire before it; most natural first."""
        order = self.closure(t)
        for e in rivals:
            for n in _refs_in_order(e):
                if n not in order:
                    order.append(n)
        return sorted((x for x in order if x in self.tier), key=lambda x: self.tier[x])


def _refs_in_order(e: M.Expr) -> list[int]:
    out: list[int] = []

    def visit(n):
        if isinstance(n, M.Ref):
            if n.var not in out:
                out.append(n.var)
        for c in model_children(n):
            visit(c)

    visit(e)
    return out


def _dead(m: M.Machine, trans: list[Arrow], reach0: set[int]) -> dict[int, str]:
    """Transitions that can never fire whatever the inputs, and why. Unlike
    the checker's warnings, a read-only local is not a constant here: a
    script may write it."""
    consts: dict = {}
    index = {id(t.goto): t.index for t in trans}
    out: dict[int, str] = {}

    def walk(stmts, reason):
        ends = False
        for s in stmts:
            why = reason or ("it follows a transition that always fires first" if ends else None)
            if isinstance(s, M.Goto):
                if why:
                    out[index[id(s)]] = why
                ends = True
            elif isinstance(s, M.If):
                c = fold(s.cond, m, consts)
                never = c is not None and not truthy(c)
                a = walk(s.then, why or ("its guard is always false" if never else None))
                b = walk(s.orelse, why or ("the guard before its `else` is always true"
                                           if c is not None and truthy(c) else None))
                ends = ends or (a and b if c is None else a if truthy(c) else b)
        return ends

    for st in m.states:
        walk(st.entry, None)
        walk(st.step, None)
    for t in trans:
        if t.index not in out and t.source not in reach0:
            out[t.index] = (f"state `{m.states[t.source].name}` is never reached: "
                            "no transition from the initial state leads to it")
    return out


# ---- values the script can write -----------------------------------------------------

def _num_text(x: float) -> str:
    if x == int(x) and abs(x) < 1e15:
        return str(int(x))
    return repr(x)


def input_value(t, text: str):
    """What the script stores when it runs `name = text` (binary64)."""
    if text in ("true", "false"):
        return to_type(t, 1.0 if text == "true" else 0.0)
    neg = text.startswith("-")
    x = F64MODE.literal(text[1:] if neg else text)
    return to_type(t, -x if neg else x)


def _score(e: M.Expr, want: bool, ev) -> int:
    """How many terms of `e` are as wanted (a hill to climb)."""
    t = type(e)
    if t is M.Not:
        return _score(e.operand, not want, ev)
    if t is M.Logic:
        a, b = _score(e.left, want, ev), _score(e.right, want, ev)
        both = (e.op == "and") == want
        return a + b if both else max(a, b)
    if t is M.ChainCmp and want:
        vals = [ev(o) for o in e.operands]
        return sum(1 for i, op in enumerate(e.ops) if compare(op, vals[i], vals[i + 1]))
    return 1 if truthy(ev(e)) == want else 0


def _max_score(e: M.Expr, want: bool) -> int:
    """`_score` when every term is as wanted."""
    t = type(e)
    if t is M.Not:
        return _max_score(e.operand, not want)
    if t is M.Logic:
        a, b = _max_score(e.left, want), _max_score(e.right, want)
        return a + b if (e.op == "and") == want else max(a, b)
    if t is M.ChainCmp and want:
        return len(e.ops)
    return 1


# ---- the search ------------------------------------------------------------------------

class _Budget(Exception):
    pass


class _Search:
    def __init__(self, m: M.Machine, delta_t: int, budget: int):
        self.m = m
        self.dt = delta_t
        self.budget = budget
        self.trans = transitions(m)
        self.by_state: dict[int, list[Arrow]] = {st.index: [] for st in m.states}
        for t in self.trans:
            self.by_state[t.source].append(t)
        self.a = _Analysis(m, self.trans, delta_t)
        self.dead = _dead(m, self.trans, self.a.static_reach[0])
        im, self.hit = instrument(m)
        self.run = MachineRun(im, F64MODE, 0)
        self.watch = [i for i in range(len(m.vars)) if i not in (m.g, m.s, m.t)]
        # For each transition: the guards of those that would fire before it
        # (its state's entry transitions, earlier ones in its own block),
        # and how long its candidates wait.
        self.rivals: dict[int, list[M.Expr]] = {}
        for t in self.trans:
            self.rivals[t.index] = [
                g for u in self.by_state[t.source]
                if u.index < t.index and (u.block == "entry" or u.block == t.block)
                for g in [guard_expr(u)] if g is not None]
        self.wait = {t.index: self.a.wait_limit(t) for t in self.trans}
        self.watched = operator.itemgetter(*self.watch) if self.watch else (lambda v: ())
        self.copy_cost = sum(w.size for w in m.windows) // 1000  # copying windows is work too
        self.steps_used = 0
        self.exhausted = False
        self.configs: dict[tuple, Config] = {}
        self.failures: dict[int, int] = {}
        self.values_cache: dict = {}
        self.root = self._config(0)

    # -- machine snapshots --

    def charge(self, n: int) -> None:
        """Counts `n` steps' worth of work against the budget."""
        self.steps_used += n
        if self.steps_used > self.budget:
            self.exhausted = True
            raise _Budget()

    def _snapshot(self) -> tuple:
        r = self.run
        self.charge(self.copy_cost)
        return (list(r.v), list(r.wv), [_clone(w) for w in r.windows], r.state, r.first,
                r.entry_time, r.prev_g)

    def _restore(self, snap: tuple) -> None:
        r = self.run
        self.charge(self.copy_cost)
        v, wv, windows, r.state, r.first, r.entry_time, r.prev_g = snap
        r.v = list(v)
        r.wv = list(wv)
        r.windows = [_clone(w) for w in windows]
        r._push = [w.push for w in r.windows]

    def _config(self, g: int) -> Config:
        r = self.run
        snap = self._snapshot()
        key = (r.state, tuple(_frozen(r.v[i]) for i in self.watch), tuple(_frozen(x) for x in r.wv),
               tuple(_frozen(w) for w in r.windows), g if self.a.reads_g else None)
        cfg = self.configs.get(key)
        if cfg is None:
            cfg = Config(r.state, g, snap, key)
            self.configs[key] = cfg
        return cfg

    # -- simulation --

    def simulate(self, cfg: Config, cand: tuple, wait: int):
        """From `cfg`, apply the candidate's inputs and step until a
        transition fires: (transition index, steps, next configuration), or
        None when nothing fires within `wait` steps."""
        mk = (cand, wait)
        if mk in cfg.memo:
            return cfg.memo[mk]
        self._restore(cfg.snap)
        r, m, hit, dt = self.run, self.m, self.hit, self.dt
        v = r.v
        gi = m.g
        g = cfg.g
        sets = {}
        for off, assigns in cand:
            sets.setdefault(off, []).extend(
                (i, input_value(m.vars[i].type, text)) for i, text in assigns)
        last = max(sets, default=-1)
        timed = self.a.timed[cfg.state]
        patience = self.a.max_window + 1
        prev, same = None, 0
        result = None
        watched = self.watched
        for k in range(wait):
            if self.steps_used >= self.budget:
                self.exhausted = True
                raise _Budget()
            if g > U64_MAX:
                break  # a script's G would wrap around
            v[gi] = g
            r.pre_step_view(g)
            for i, x in sets.get(k, ()):
                v[i] = x
            v[hit] = 0
            r.step()
            self.steps_used += 1
            if v[hit]:
                result = (v[hit] - 1, k + 1, self._config(g + dt))
                break
            if not timed and k >= last:
                cur = (watched(v), r.wv[:])
                if cur == prev:
                    same += 1
                    if same >= patience:
                        break  # nothing changes any more, and time alone changes nothing
                else:
                    prev, same = cur, 0
            g += dt
        cfg.memo[mk] = result
        return result

    # -- candidates --

    def _eval(self, cfg: Config, e: M.Expr, over: dict[int, float]) -> float:
        v, wv = cfg.snap[0], cfg.snap[1]
        m = self.m

        def read(i):
            if i in over:
                return over[i]
            if i == m.t:
                return 0.0
            if i == m.s:
                return float(cfg.state + 1)
            if i == m.g:
                return float(cfg.g)
            return F64MODE.read(m.vars[i].type, v[i])

        return evaluate(e, F64MODE, read, lambda w: wv[w])

    def values(self, cfg: Config, var: int, t: Arrow) -> list[str]:
        """Texts of the values worth writing to `var`, best first."""
        ck = (id(cfg), var, t.index)
        if ck in self.values_cache:
            return self.values_cache[ck]
        vt = self.m.vars[var].type
        cur = cfg.snap[0][var]
        if vt.kind == "bool":
            out = [x for x in ("true", "false") if input_value(vt, x) != cur]
            self.values_cache[ck] = out
            return out
        own = [p for cond, _ in t.path for p in _pairs(cond)]
        gk = (id(cfg), var)
        if gk not in self.values_cache:
            self.values_cache[gk] = self._solutions(cfg, var, self.a.pairs) + self.a.pool
        nums = self._solutions(cfg, var, own) + self.values_cache[gk]
        texts: list[str] = []
        for x in nums:
            if not math.isfinite(x):
                continue
            if vt.kind == "int":
                cands = [min(max(math.floor(x), vt.lo), vt.hi), min(max(math.ceil(x), vt.lo), vt.hi)]
            else:
                cands = [x]
            for c in cands:
                text = _num_text(float(c)) if vt.kind == "float" else str(c)
                if text not in texts and input_value(vt, text) != cur:
                    texts.append(text)
            if len(texts) >= MAX_VALUES:
                break
        out = texts[:MAX_VALUES]
        self.values_cache[ck] = out
        return out

    def _solutions(self, cfg: Config, var: int, pairs) -> list[float]:
        """Around each value of `var` that makes a compared pair equal."""
        nums: list[float] = []
        for a, b in pairs:
            for side, other in ((a, b), (b, a)):
                if var not in _refs(side) or var in _refs(other):
                    continue
                x = self._solve(cfg, side, var, other)
                if x is not None:
                    nums += [x, x + 1, x - 1, x + 0.5, x - 0.5]
        return nums

    def _solve(self, cfg: Config, side: M.Expr, var: int, other: M.Expr) -> float | None:
        """The value of `var` that makes `side` equal `other` at `cfg`, when
        `side` is linear in it."""
        try:
            c = self._eval(cfg, other, {})
            if not math.isfinite(c):
                return None
            if isinstance(side, M.Ref):
                return c
            f0 = self._eval(cfg, side, {var: 0.0})
            f1 = self._eval(cfg, side, {var: 1.0})
        except (ArithmeticError, NotConstant):
            return None
        b = f1 - f0
        if not (math.isfinite(b) and math.isfinite(f0)) or b == 0:
            return None
        x = (c - f0) / b
        return x if math.isfinite(x) else None

    def _greedy(self, cfg: Config, t: Arrow, rel: list[int]) -> tuple[tuple, bool]:
        """Inputs chosen one variable at a time to satisfy the most terms of
        `t`'s guard, and to falsify those of its rivals (static evaluation
        at the first step); and whether all terms that do not follow the
        clock then hold."""
        m = self.m
        over: dict[int, float] = {}
        chosen: dict[int, str] = {}
        terms = list(t.path) + [(g, False) for g in self.rivals[t.index]]
        static = [(c, want) for c, want in terms if not (_refs(c) & self.a.time_like)]

        def score(terms=terms) -> int:
            ev = lambda e: self._eval(cfg, e, over)  # noqa: E731
            self.charge(1)
            try:
                return sum(_score(c, want, ev) for c, want in terms)
            except (ArithmeticError, NotConstant):
                return -1

        best = score()
        for _ in range(3):
            improved = False
            for var in rel:
                vt = m.vars[var].type
                keep = over.get(var)
                for text in self.values(cfg, var, t):
                    over[var] = F64MODE.read(vt, input_value(vt, text))
                    s = score()
                    if s > best:
                        best, keep, improved = s, over[var], True
                        chosen[var] = text
                if keep is None:
                    over.pop(var, None)
                else:
                    over[var] = keep
            if not improved:
                break
        combo = tuple((var, chosen[var]) for var in rel if var in chosen)
        full = score(static) == sum(_max_score(c, want) for c, want in static)
        return combo, full

    def candidates(self, cfg: Config, t: Arrow):
        yield ()
        rel = self.a.relevant(t, self.rivals[t.index])
        combo, full = self._greedy(cfg, t, rel)
        if len(combo) >= 2 and full:
            yield ((0, combo),)  # likely right: before the long list of single changes
        for var in rel:
            for text in self.values(cfg, var, t):
                yield ((0, ((var, text),)),)
        if len(combo) >= 2 and not full:
            yield ((0, combo),)
        if t.block == "step":
            # Inputs one step late, after the entry transitions had their
            # chance; possibly with another value at entry (a switch that must
            # be off on entry and on afterwards).
            for var in rel:
                vals = self.values(cfg, var, t)
                cur = _text_of(self.m, var, cfg.snap[0][var])
                for late in vals[:MAX_LATE_VALUES] + [cur]:
                    for early in [None] + vals[:4]:
                        if early == late or (early is None and late == cur):
                            continue
                        first = () if early is None else ((0, ((var, early),)),)
                        yield first + ((1, ((var, late),)),)
        n = 0
        for i, a in enumerate(rel):
            for b in rel[i + 1:]:
                for ta in self.values(cfg, a, t)[:8]:
                    for tb in self.values(cfg, b, t)[:8]:
                        yield ((0, ((a, ta), (b, tb))),)
                        n += 1
                        if n >= MAX_PAIRS:
                            return

    def outcomes(self, cfg: Config) -> list[Move]:
        """The transitions found to fire from `cfg`, searching for those
        not yet tried here."""
        for t in self.by_state[cfg.state]:
            i = t.index
            if i in cfg.moves or i in cfg.tried or i in self.dead:
                continue
            if self.failures.get(i, 0) >= GIVE_UP_AFTER:
                continue
            cfg.tried.add(i)
            for cand in self.candidates(cfg, t):
                res = self.simulate(cfg, cand, self.wait[i])
                if res is not None and res[0] not in cfg.moves:
                    cfg.moves[res[0]] = Move(res[0], cand, res[1], res[2])
                if i in cfg.moves:
                    break
            else:
                self.failures[i] = self.failures.get(i, 0) + 1
        return [cfg.moves[i] for i in sorted(cfg.moves)]

    # -- runs --

    def reach(self, state: int, remaining: set[int]) -> int:
        r = self.a.static_reach[state]
        return sum(1 for i in remaining if self.trans[i].source in r)

    def find_path(self, start: Config, remaining: set[int]) -> list[Move] | None:
        """Breadth-first over configurations: the shortest path whose last
        move takes a transition in `remaining`, preferring one after which the
        most of the others stay reachable."""
        best, best_rank = None, None
        level = [(start, [])]
        seen = {id(start)}
        expansions = 0
        for depth in range(len(self.m.states) + 1):
            nxt = []
            for cfg, path in level:
                if expansions >= MAX_EXPANSIONS:
                    break
                expansions += 1
                for e in self.outcomes(cfg):
                    p = path + [e]
                    if e.t in remaining and all(x.t != e.t for x in path):
                        left = remaining - {x.t for x in p}
                        rank = (-self.reach(self.trans[e.t].target, left), depth)
                        if best_rank is None or rank < best_rank:
                            best, best_rank = p, rank
                    if id(e.child) not in seen:
                        seen.add(id(e.child))
                        nxt.append((e.child, p))
            if best is not None:
                left = remaining - {x.t for x in best}
                if -best_rank[0] == len(left):
                    break  # nothing is lost by taking it
            level = nxt
            if not level:
                break
        return best

    def plan(self) -> Plan:
        todo = {t.index for t in self.trans if t.index not in self.dead}
        runs: list[Run] = []
        while todo and len(runs) < MAX_RUNS and not self.exhausted:
            cfg, path, got = self.root, [], set()
            try:
                while True:
                    p = self.find_path(cfg, todo - got)
                    if not p:
                        break
                    path += p
                    got |= {e.t for e in p}
                    cfg = p[-1].child
            except _Budget:
                pass  # keep what this run found so far
            if not (got & todo):
                break
            runs.append(Run(tuple(path)))
            todo -= got
        taken = {i for r in runs for i in r.taken}
        visited = {0} | {self.trans[i].target for i in taken}
        not_reached: dict[int, str] = {}
        for t in self.trans:
            if t.index in taken:
                continue
            if t.index in self.dead:
                why = self.dead[t.index]
            elif len(runs) >= MAX_RUNS and t.index in todo:
                why = f"it needs more than {MAX_RUNS} scripts"
            elif t.source not in visited:
                why = f"the search did not reach state `{self.m.states[t.source].name}`"
            elif self.exhausted:
                why = "the search ran out of its step budget first"
            else:
                why = ("no inputs found that make it fire: tried the guards' constants and "
                       f"waiting up to {self.wait[t.index]} steps")
            if t.index not in self.dead and self.wait[t.index] >= WAIT_CAP:
                why += (f"; waiting is capped at {WAIT_CAP} steps, and a larger `--delta-t` "
                        "reaches later times")
            not_reached[t.index] = why
        return Plan(self.m, self.dt, self.trans, runs, not_reached, self.steps_used, self.exhausted)


def _slots(w: Window):
    for cls in type(w).__mro__:
        for s in getattr(cls, "__slots__", ()):
            if s != "real":
                yield s


def _frozen(x):
    """A hashable, exact picture of a value (-0.0 apart from 0.0) or of a
    rolling window (which never holds -0.0: it stores 0 for zero and NaN)."""
    if isinstance(x, float):
        return repr(x)
    if isinstance(x, Window):
        return (type(x).__name__,) + tuple(_frozen(getattr(x, s)) for s in _slots(x))
    if isinstance(x, (list, deque)):
        return tuple(x)
    return x


def _clone(w: Window) -> Window:
    """A copy of a rolling window sharing nothing mutable with it."""
    c = object.__new__(type(w))
    c.real = w.real
    for s in _slots(w):
        x = getattr(w, s)
        if isinstance(x, list):
            x = list(x)
        elif isinstance(x, deque):
            x = deque(x)
        elif isinstance(x, Window):
            x = _clone(x)
        setattr(c, s, x)
    return c


def plan(m: M.Machine, delta_t: int = 10, budget: int = STEP_BUDGET) -> Plan:
    """Searches for the runs that take every transition it can."""
    if not isinstance(delta_t, int) or not 0 < delta_t <= U64_MAX:
        raise ValueError("delta_t must be an integer from 1 to 2^64 - 1")
    return _Search(m, delta_t, budget).plan()


# ---- the script text -------------------------------------------------------------------

def _script(p: Plan, k: int) -> str:
    m, dt = p.machine, p.delta_t
    run = p.runs[k] if p.runs else Run(())
    nruns = max(1, len(p.runs))
    name = os.path.basename(m.path.replace("\\", "/"))
    name = "".join(c if c.isprintable() else "?" for c in name)
    which = f" (run {k + 1} of {nruns})" if nruns > 1 else ""
    out = [f"# State-script skeleton for {name}, made by `fsw skeleton`{which}.",
           "# Its inputs were found by running the machine in binary64: they drive it",
           "# along the transitions listed here, and every assert below passes as it",
           "# stands. Replace each TODO with what must hold, and the inputs with",
           "# realistic values where these are not."]
    if run.taken:
        out += ["#", "# This script takes, in order:"]
        out += [f"#   {describe(p.transitions[i], m)}" for i in run.taken]
    if k == 0:
        for j, r in enumerate(p.runs[1:], start=2):
            out += ["#", f"# Run {j} (below, commented out) takes what this one cannot come back for:"]
            before = _taken_before(p, j - 1)
            out += [f"#   {describe(p.transitions[i], m)}" for i in r.taken if i not in before]
        for i in sorted(p.not_reached):
            out += ["#", f"# not reached: {describe(p.transitions[i], m)}",
                    f"#   ({p.not_reached[i]})"]
    out.append("")

    # timeline
    events: list[str] = []
    g = 0
    start = {i: None for i in _sensors(m)}
    first_inputs = {}
    for off, assigns in (run.moves[0].inputs if run.moves else ()):
        if off == 0:
            first_inputs.update(dict(assigns))
    for i in start:
        start[i] = first_inputs.pop(i, None)
    lines0 = []
    for i, text in start.items():
        if text is None:
            text = _text_of(m, i, 0 if m.vars[i].type.kind != "float" else 0.0)
        lines0.append(f"{m.vars[i].alias or m.vars[i].name} = {text}")
    lines0 += [f"{_vname(m, i)} = {text}" for i, text in first_inputs.items()]
    visited = [0]
    steps_total = 0
    for n, e in enumerate(run.moves):
        t = p.transitions[e.t]
        fire = g + (e.steps - 1) * dt
        events.append(f"# {n + 1}. from G = {g}: {describe(t, m)}; it fires at G = {fire}")
        if n == 0 and lines0:
            events += _group(0, lines0)
            lines0 = []
        for off, assigns in e.inputs:
            if n == 0 and off == 0:
                continue  # already in the first group
            events += _group(g + off * dt, [f"{_vname(m, i)} = {text}" for i, text in assigns])
        g += e.steps * dt
        steps_total += e.steps
        events.append(f"G == {g}: @assert S == {m.states[t.target].id} and T == 0"
                      f"  # entered {m.states[t.target].name}")
        if t.target not in visited:
            visited.append(t.target)
    if lines0:
        events = ["# the inputs at the start"] + _group(0, lines0) + events
    steps_total += 1

    out += ["[options]", f"delta_t {dt}", f"init_state {m.states[0].name}"]
    if steps_total > DEFAULT_MAX_STEPS:
        out.append(f"max_steps {steps_total}")
    out.append("")
    if events:
        out += ["[all_states]"] + events + [""]
    for si in sorted(visited):
        st = m.states[si]
        out += [f"[{st.name}]", f"true: @assert S == {st.id}  # TODO: what must hold in {st.name}"]
        sets = _written(m, st)
        if sets:
            out.append(f"# {st.name} sets {', '.join(sets)}")
        out.append("")
    out += ["[all_states]", f"G == {g}: @stop"]
    return "\n".join(out) + "\n"


def _written(m: M.Machine, st: M.State) -> list[str]:
    """The names a state assigns, in order of first assignment."""
    out: list[str] = []

    def walk(stmts):
        for s in stmts:
            if isinstance(s, M.Assign):
                name = _vname(m, s.var)
                if name not in out:
                    out.append(name)
            elif isinstance(s, M.If):
                walk(s.then)
                walk(s.orelse)

    for b in (st.entry, st.step, st.exit):
        walk(b)
    return out


def _taken_before(p: Plan, k: int) -> set[int]:
    return {i for r in p.runs[:k] for i in r.taken}


def _sensors(m: M.Machine) -> list[int]:
    """Elements the machine reads and never writes (its inputs), G and S aside."""
    assigned = assigned_vars(m)
    return [v.index for v in m.vars if v.kind == M.ELEMENT and v.index not in (m.g, m.s)
            and v.index not in assigned]


def _vname(m: M.Machine, i: int) -> str:
    v = m.vars[i]
    return v.alias or v.name


def _text_of(m: M.Machine, i: int, x) -> str:
    t = m.vars[i].type
    if t.kind == "bool":
        return "true" if x else "false"
    if t.kind == "int":
        return str(int(x))
    return _num_text(float(x))


def _group(g: int, lines: list[str]) -> list[str]:
    if len(lines) == 1:
        return [f"G == {g}: {lines[0]}"]
    return [f"G == {g} {{"] + [f"    {x}" for x in lines] + ["}"]


def skeleton_runs(m: M.Machine, delta_t: int = 10, budget: int = STEP_BUDGET) -> list[str]:
    """One state script per run: together they take every transition the
    search could drive."""
    p = plan(m, delta_t, budget)
    return [_script(p, k) for k in range(max(1, len(p.runs)))]


def skeleton(m: M.Machine, delta_t: int = 10, budget: int = STEP_BUDGET) -> str:
    """The skeleton as one file: the first run as a script, each further run
    (needed when a run ends where it cannot come back from) appended as
    comments, to be saved as a script of its own."""
    scripts = skeleton_runs(m, delta_t, budget)
    out = scripts[0]
    for k, text in enumerate(scripts[1:], start=2):
        out += ("\n" + f"# ==== run {k} of {len(scripts)} " + "=" * 50 + "\n"
                "# A script follows one path. Save the lines below without their leading\n"
                f"# \"# \" as a script of their own (e.g. {m.name}_{k}.ss).\n#\n")
        out += "".join(("# " + line if line else "#") + "\n" for line in text.rstrip("\n").split("\n"))
    return out
