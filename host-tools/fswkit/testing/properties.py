"""The property tests' settings and helpers (tests/autocode/{lexer,parser,
check}, tests/run): example counts scaled by FSW_PROPERTY_SCALE (default 0.3
in `make test`; `make fuzz` runs 5), shrinking of whole programs only with
FSW_PROPERTY_SHRINK=1 (slow), and the parse/check/compare steps the tests
share. Needs Hypothesis."""

from __future__ import annotations

import os
import struct

from hypothesis import HealthCheck, Phase, settings

from fswkit.autocode import model as M
from fswkit.autocode.check import check_sm, check_ss, check_sv
from fswkit.autocode.diagnostics import Diagnostics, Source
from fswkit.autocode.numeric import F32MODE, F64MODE
from fswkit.autocode.parser import parse_sm, parse_ss, parse_sv
from fswkit.testing import strategies as T

SCALE = float(os.environ.get("FSW_PROPERTY_SCALE", "0.3"))
REAL_MODES = (F64MODE, F32MODE)


# Shrinking a whole generated program can take minutes: the program-level
# tests report the failing program as drawn unless FSW_PROPERTY_SHRINK=1.
SHRINK = os.environ.get("FSW_PROPERTY_SHRINK") == "1"
NO_SHRINK = {} if SHRINK else {"phases": [Phase.explicit, Phase.reuse, Phase.generate]}


def cases(n: int, **kw):
    return settings(max_examples=max(1, int(n * SCALE)), deadline=None, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.large_base_example, HealthCheck.filter_too_much],
                    **kw)


def parse(kind: str, text: str, path: str | None = None):
    d = Diagnostics()
    src = Source.from_text(path or f"p.{kind}", text)
    tree = {"sv": parse_sv, "sm": parse_sm, "ss": parse_ss}[kind](src, d)
    return tree, src, d


def compile_program(p: T.Program):
    """The checked machine and script of a generated program; asserts that
    both check without errors."""
    (svf, svs, d1), (smf, sms, d2), (ssf, sss, d3) = (
        parse("sv", p.sv_text), parse("sm", p.sm_text), parse("ss", p.ss_text))
    d = Diagnostics()
    sv = check_sv(svf, svs, d)
    m = check_sm(smf, sms, sv, d, warnings=True)
    script = check_ss(ssf, sss, m, d) if m is not None else None
    assert not (d1.items or d2.items or d3.items or d.errors), (
        (d1.render() + d2.render() + d3.render() + d.render()) + "\n" + p.sv_text + p.sm_text + p.ss_text)
    return m, script


def same(a, b) -> bool:
    """Bit-for-bit equality of two variable values (NaN equals NaN)."""
    if type(a) is not type(b):
        return False
    if isinstance(a, float):
        return (a != a and b != b) or struct.pack("<d", a) == struct.pack("<d", b)
    return a == b


def assert_same_values(a: list, b: list, m: M.Machine, where: str) -> None:
    for i, (x, y) in enumerate(zip(a, b)):
        assert same(x, y), f"{where}: `{m.vars[i].name}` is {x!r} compiled, {y!r} by the tree walk"
    assert len(a) == len(b)
