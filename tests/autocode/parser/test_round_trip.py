"""Properties of the parser over generated programs
(fswkit.testing.strategies): tree -> unparse -> parse gives the tree back,
and unparse is a fixed point; every other accepted spelling parses to the
same tree. FSW_PROPERTY_SCALE scales the example counts
(fswkit.testing.properties)."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from fswkit.autocode import unparse
from fswkit.testing import strategies as T
from fswkit.testing.properties import NO_SHRINK, cases, parse


# ---- round trip --------------------------------------------------------------------

@cases(80, **NO_SHRINK)
@given(T.programs(), st.randoms(use_true_random=False))
def test_round_trip_and_other_spellings(p, r):
    for kind, tree, spell in (("sv", p.sv, T.spell_sv), ("sm", p.sm, T.spell_sm), ("ss", p.ss, T.spell_ss)):
        text = getattr(unparse, f"{kind}_file")(tree)
        back, _, d = parse(kind, text)
        assert not d.items, d.render() + "\n" + text
        assert T.strip(back) == T.strip(tree), text
        assert getattr(unparse, f"{kind}_file")(back) == text  # a fixed point
        spelled = spell(tree, r)
        back, _, d = parse(kind, spelled)
        assert not d.items, d.render() + "\n" + spelled
        assert T.strip(back, flags=True) == T.strip(tree, flags=True), spelled


@cases(60, **NO_SHRINK)
@given(T.programs(loose=True))
def test_round_trip_of_any_calls(p):
    """Calls of any function with any number of arguments are syntax too."""
    text = p.sm_text
    back, _, d = parse("sm", text)
    assert not d.items, d.render() + "\n" + text
    assert T.strip(back) == T.strip(p.sm)
    assert unparse.sm_file(back) == text


@cases(300)
@given(T.exprs(T.Ctx(("a", "b", "iffy", "T"), (T._n("3"),)), 5))
def test_expression_round_trip(e):
    text = unparse.expr(e)
    back, _, d = parse("sm", f"[state_vector]\n[local]\nF64 x = {text}\n")
    assert not d.items, text
    assert T.strip(back.locals[0].expr) == T.strip(e), text
