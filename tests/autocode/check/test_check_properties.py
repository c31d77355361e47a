"""Properties of the checker over generated programs
(fswkit.testing.strategies): generated valid programs check without errors
and run through `fsw check` / `fsw test`; programs calling any function with
any arguments get diagnostics, never an exception. FSW_PROPERTY_SCALE scales
the example counts (fswkit.testing.properties)."""

from __future__ import annotations

import math
import os
import tempfile

from hypothesis import given

from conftest import run_fsw
from fswkit.autocode.check import check_sm, check_ss, check_sv
from fswkit.autocode.diagnostics import Diagnostics, Source
from fswkit.autocode.numeric import F32MODE
from fswkit.testing import fuzz
from fswkit.testing import strategies as T
from fswkit.testing.properties import NO_SHRINK, cases, compile_program, parse


# ---- checking ---------------------------------------------------------------------------

@cases(60)
@given(T.programs(loose=True))
def test_programs_calling_anything_check_to_diagnostics(p):
    """Calls of any function, any number of arguments, calls in window
    sizes: the checker reports, never raises."""
    sources = {f"p.{k}": getattr(p, f"{k}_text") for k in ("sv", "sm", "ss")}
    (svf, svs, d1), (smf, sms, d2), (ssf, sss, d3) = (parse(k, sources[f"p.{k}"]) for k in ("sv", "sm", "ss"))
    d = Diagnostics()
    m = check_sm(smf, sms, check_sv(svf, svs, d), d, warnings=True)
    if m is not None:
        check_ss(ssf, sss, m, d)
    fuzz.check_diagnostics(d, sources)


@cases(80, **NO_SHRINK)
@given(T.programs())
def test_generated_programs_check_and_run_through_fsw(p):
    compile_program(p)
    with tempfile.TemporaryDirectory() as d:
        for ext, text in (("sv", p.sv_text), ("sm", p.sm_text), ("ss", p.ss_text)):
            with open(os.path.join(d, f"p.{ext}"), "w") as f:
                f.write(text)
        r = run_fsw("check", d)
        assert r.code == 0, r.err
        assert ", 0 errors," in r.err
        r = run_fsw("test", os.path.join(d, "p.ss"), "--real", "f32")
        if _beyond_binary32(p.sm_text + "\n" + p.ss_text):  # `1e39` is infinity there: an error
            assert r.code == 2 and "number is outside the representable range of binary32" in r.err, r.err
            return
        assert r.code in (0, 1), r.err
        assert r.out.startswith("state script ran for ")


def _beyond_binary32(text: str) -> bool:
    from fswkit.autocode.lexer import NUM, lex

    toks = lex(Source.from_text("p", text), Diagnostics(), "sm")
    return any(t.kind == NUM and math.isinf(F32MODE.literal(t.text)) for line in toks for t in line)
