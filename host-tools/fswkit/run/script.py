"""State scripts (spec §5): drive a machine step by step, apply inputs,
check asserts, stop. The run loop and its report are the contract users
know from the reference implementation."""

from __future__ import annotations

import csv
import functools
import itertools
from dataclasses import dataclass

from fswkit.autocode import model as M
from fswkit.autocode.check import failure_diagnostics
from fswkit.autocode.collect import fewer_collections
from fswkit.autocode.diagnostics import Diagnostic
from fswkit.autocode.numeric import Real
from fswkit.run.interp import ERR_TIME, MachineRun, _Emitter, compile_functions
from fswkit.run.windows import make_window

U64_MOD = 1 << 64


@dataclass
class Result:
    passed: bool
    steps: int
    asserts: int
    failure: Diagnostic | None
    values: list[tuple[str, str]]
    taken: frozenset = frozenset()    # (line, col) of the transitions taken (cover=True)
    visited: frozenset = frozenset()  # indexes of the states entered (cover=True)

    def report(self) -> str:
        lines = [f"state script ran for {self.steps} step{'' if self.steps == 1 else 's'}",
                 f"{self.asserts} assert{'' if self.asserts == 1 else 's'} passed"]
        if self.failure is not None:
            lines.append(self.failure.render())
        lines.append("final state vector:")
        lines += [f"  {name} = {value}" for name, value in self.values]
        return "\n".join(lines) + "\n"


def _compile(script: M.Script, real: Real):
    """Python functions for the script: `pre(v, wv, sw, state)` applies the
    inputs of the active sections and returns the checks whose guards held;
    check `k` is evaluated after the step by `check_k(v, wv, sw)`."""
    m = script.machine
    em = _Emitter(m.vars, real)
    src = ["def update(v, wv, sw, W):"]
    sem = _Emitter(m.vars, real, wv="sw")
    for w in script.windows:
        src.append(f"    sw[{w.index}] = W[{w.index}]({sem.value(w.arg)})")
    src.append("    pass")
    src.append("def pre(v, wv, sw, state):")
    src.append("    rem = []")
    checks: list[M.Assert | M.Stop] = []
    for sec in script.sections:
        ind = "    "
        if sec.state is not None:
            src.append(f"    if state == {sec.state}:")
            ind = "        "
        body_start = len(src)
        for g in sec.inputs:
            for a in g.inputs:  # the guard again before each input: an earlier one may change it (spec §5)
                src.append(f"{ind}if {sem.cond(g.guard)}:")
                src.append(f"{ind}    {sem.assign(a.var, a.expr)}")
        for g in sec.checks:
            ids = []
            for c in g.checks:
                ids.append(len(checks))
                checks.append(c)
            src.append(f"{ind}if {sem.cond(g.guard)}:")
            src.append(f"{ind}    rem.extend({tuple(ids)!r})")
        if len(src) == body_start:
            src.append(f"{ind}pass")
    src.append("    return rem")
    for k, c in enumerate(checks):
        src.append(f"def check_{k}(v, wv, sw):")
        if isinstance(c, M.Assert):
            src.append(f"    return {sem.cond(c.expr)}")
        else:
            src.append("    return None")
    ns = compile_functions("\n".join(src) + "\n", script.path, {"_deep": sem.deep})
    del em
    return ns, checks


@fewer_collections()
def run(script: M.Script, real: Real, trace_path: str | None = None, source_line=None,
        cover: bool = False) -> Result:
    """Runs a checked script. `source_line(path, line)` gives the text of a
    script line for the failure diagnostic. `cover`: the result names the
    transitions taken and the states entered. The collector runs as seldom
    as in the loaders (fswkit.autocode.collect)."""
    m = script.machine
    run_ = MachineRun(m, real, script.init_state, cover=cover)
    ns, checks = _compile(script, real)
    pre, update = ns["pre"], ns["update"]
    check = [ns[f"check_{k}"] for k in range(len(checks))]
    windows = [make_window(w.func, w.size, real).push for w in script.windows]
    sw = [0.0] * len(script.windows)
    v, wv = run_.v, run_.wv
    g_i = m.g
    delta = script.delta_t
    g = 0
    steps = asserts = 0
    failure = None
    passed = False
    tracer = _Tracer(trace_path, m) if trace_path else None

    fails = failure_diagnostics(script, source_line)
    assert_number = {id(c): k for k, c in enumerate(
        c for sec in script.sections for g in sec.checks for c in g.checks if isinstance(c, M.Assert))}

    try:
        while True:
            if steps >= script.max_steps:
                failure = fails["max_steps"]
                break
            v[g_i] = g
            run_.pre_step_view(g)
            if windows:
                update(v, wv, sw, windows)
            rem = pre(v, wv, sw, run_.state)
            if run_.step() == ERR_TIME:
                steps += 1
                failure = fails["step_error"]
                break
            steps += 1
            if tracer:
                tracer.row(steps, v)
            done = False
            for k in rem:
                c = checks[k]
                if type(c) is M.Stop:
                    passed = done = True
                    break
                if check[k](v, wv, sw):
                    asserts += 1
                else:
                    failure = fails["asserts"][assert_number[id(c)]]
                    done = True
                    break
            if done:
                break
            g = (g + delta) % U64_MOD
    finally:
        if tracer:
            tracer.close()
    return Result(passed and failure is None, steps, asserts, failure, run_.values(),
                  frozenset(run_.taken), frozenset(run_.visited))


def _trace_order(m: M.Machine) -> list:
    return sorted(m.vars, key=lambda var: var.display.encode())


def trace_header(m: M.Machine) -> bytes:
    """The first line of `m`'s trace, its line end included, as the trace
    writes it: what marks a file as an earlier trace of this machine."""
    import io

    buf = io.StringIO(newline="")
    csv.writer(buf).writerow(["step"] + [var.display for var in _trace_order(m)])
    return buf.getvalue().encode()


@functools.lru_cache(maxsize=256)
def _row_maker(kinds: tuple[str, ...], places: tuple[int, ...]) -> object:
    """A function (step, values) -> a trace row's line, its line end
    included: the step, then values[p] for each place p, written as the
    trace writes its kind (a bool as true/false, a float by repr, an
    integer as it is), comma-separated, as the csv module writes them (no
    field of these needs quoting) and ends its lines (CR LF). Made once a
    trace, from the machine's variable kinds and small integers only: a
    row a step costs one call, not a loop over the variables."""
    cols = []
    for k, at in zip(kinds, places):
        at = int(at)
        cols.append(f"{{'true' if v[{at}] else 'false'}}" if k == "bool" else f"{{v[{at}]!r}}" if k == "float"
                    else f"{{v[{at}]}}")
    return eval(f"lambda step, v: f\"{{step}}{''.join(',' + c for c in cols)}\\r\\n\"")  # noqa: S307 (ints and fixed text)


class _Tracer:
    """`--trace FILE.csv`: every variable after every step."""

    def __init__(self, path: str, m: M.Machine):
        self.f = open(path, "w", newline="")
        order = _trace_order(m)
        kinds = tuple(var.type.kind for var in order)
        self._row = _row_maker(kinds, tuple(var.index for var in order))
        self._ordered = _row_maker(kinds, tuple(range(len(order))))
        csv.writer(self.f).writerow(["step"] + [var.display for var in order])
        self._write = self.f.write

    def row(self, step: int, v) -> None:
        """The row of step `step`: `v` the variables by index."""
        self._write(self._row(step, v))

    def rows_ordered(self, first: int, values) -> None:
        """Rows from step `first` on: `values` an iterable of tuples, each a
        step's variables in the trace's column order."""
        self.f.writelines(map(self._ordered, itertools.count(first), values))

    def close(self) -> None:
        self.f.close()
