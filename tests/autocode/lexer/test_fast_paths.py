"""The lexer's one-search path for a line with nothing wrong (with tabs or
without) gives exactly the tokens and columns of its character-by-character
path, and leave every line with something wrong to it.
FSW_PROPERTY_SCALE scales the example counts (fswkit.testing.properties)."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from fswkit.autocode import lexer
from fswkit.autocode.diagnostics import Diagnostics, Source
from fswkit.testing.properties import cases

PIECES = ["x", "ab_1", "if", "and", "true", "1", "2.5", ".5", "1e3", "3.", "12abc", "1.2.3", "->", "<=",
          "==", "!", "(", ")", "{", "}", ":", ",", "[", "]", "-", "+", ".entry", "@assert", "@bogus",
          "# note", " ", "  ", "\t", "\t\t", "\r", "\f", "$", "\u00e9", "\x00"]


def _slow(text: str) -> tuple[list, list[str]]:
    """lex_line with its one-search path turned off."""
    fast = lexer._lex_clean
    lexer._lex_clean = lambda n, text: None
    try:
        return _lex(text)
    finally:
        lexer._lex_clean = fast


def _lex(text: str) -> tuple[list, list[str]]:
    d = Diagnostics()
    toks = lexer.lex_line(Source.from_text("p.sm", text), 3, text, d, "sm")
    return toks, [x.render() for x in d.items]


@cases(1500)
@given(st.lists(st.sampled_from(PIECES), max_size=30).map("".join))
def test_the_fast_path_is_the_slow_path(text):
    assert _lex(text) == _slow(text)


def test_a_tab_indented_line_takes_the_fast_path():
    text = "\t\tif x <= 2.5:\t# a comment\t"
    toks = lexer._lex_clean(3, text)
    assert toks is not None and toks == _slow(text)[0]
    assert [t.col for t in toks] == [17, 20, 22, 25, 28]
    for bad in ("\t12abc", "\tx $ y", "\t@bogus x"):
        assert lexer._lex_clean(1, bad) is None
