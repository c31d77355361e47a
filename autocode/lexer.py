"""The lexer shared by every config language (spec §1): line oriented,
`#` comments, whole-word keywords, numbers with optional fraction and
exponent, `-` always an operator."""

from __future__ import annotations

import re
from typing import NamedTuple

from .diagnostics import Columns, Diagnostics, Source

KEYWORDS = frozenset({"if", "else", "and", "or", "not", "true", "false"})
ANNOTATIONS = frozenset({"@read_only", "@alias", "@assert", "@stop", "@min", "@max", "@unit", "@when"})

# Token kinds.
NUM, ID, KW, OP, ANNOT, LABEL, NL, EOF = "num", "id", "kw", "op", "annot", "label", "nl", "eof"


class Tok(NamedTuple):
    kind: str
    text: str
    line: int
    col: int  # 1-based, tabs expanded


# One token, with the blanks before it (a line's blanks are no token). No
# two kinds match at the same place, so they are tried most common first.
_BLANKS = r"[ \t\f\v\r]*"
_KINDS = r"""
    (?P<id>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<op>->|<=|>=|==|!=|[-+*/<>=!(){}:,\[\]])
  | (?P<num>(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?)
  | (?P<label>\.[A-Za-z_][A-Za-z0-9_]*)
  | (?P<annot>@[A-Za-z_][A-Za-z0-9_]*)
  | (?P<comment>\#.*)
"""
_TOKEN = re.compile(_BLANKS + "(?:" + _KINDS + ")", re.X)
# The same tokens for `_lex_clean`, each as (its blanks, then one group a
# kind, in _KINDS' order), and any other character that is no blank as a
# last group: the matches of a line then cover it, all but its trailing
# blanks, and `findall` gives them as plain tuples.
_CLEAN = re.compile("(" + _BLANKS + ")(?:" + _KINDS + r"| ([^ \t\f\v\r]))", re.X)
_SKIP_BLANKS = re.compile(_BLANKS)
_NUMBER_TAIL = re.compile(r"[A-Za-z0-9_.]+")


def describe(ch: str) -> str:
    if 0xDC80 <= ord(ch) <= 0xDCFF:  # a byte that is not UTF-8 (diagnostics.decode)
        return f"byte 0x{ord(ch) - 0xDC00:02X} (the file is not valid UTF-8)"
    return f"character `{ch}`" if ch.isprintable() else f"character U+{ord(ch):04X}"


_new_tok = tuple.__new__
_NUMBER_TAIL_START = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_.")


def _lex_clean(n: int, text: str) -> list[Tok] | None:
    """The tokens of a line that holds nothing wrong (the common case, one
    regex search for the line), each at its visual column (`Columns`, as
    `lex_line` gives it, where the line has a tab); None for any other
    line, which `lex_line` reads character by character with its reports."""
    toks: list[Tok] = []
    append = toks.append
    cols = Columns(text) if "\t" in text else None
    pos = 0  # index of the next character
    for blanks, name, op, num, label, annot, comment, other in _CLEAN.findall(text):
        if blanks:
            pos += len(blanks)
        col = pos + 1 if cols is None else cols(pos)
        if name:
            append(_new_tok(Tok, (KW if name in KEYWORDS else ID, name, n, col)))
            pos += len(name)
        elif op:
            append(_new_tok(Tok, (OP, op, n, col)))
            pos += len(op)
        elif num:
            append(_new_tok(Tok, (NUM, num, n, col)))
            pos += len(num)
            if text[pos:pos + 1] in _NUMBER_TAIL_START:  # `12abc`, `1.2.3`: a malformed number
                return None
        elif label:
            append(_new_tok(Tok, (LABEL, label, n, col)))
            pos += len(label)
        elif annot:
            if annot not in ANNOTATIONS:
                return None
            append(_new_tok(Tok, (ANNOT, annot, n, col)))
            pos += len(annot)
        elif comment:  # (to the end of the line)
            break
        else:  # a character no token starts with
            return None
    return toks


def lex_line(src: Source, n: int, text: str, diags: Diagnostics, lang: str) -> list[Tok]:
    """Tokens of line `n` (without its newline). Lexical errors are reported
    and the offending characters skipped."""
    toks = _lex_clean(n, text)
    if toks is not None:
        return toks
    toks: list[Tok] = []
    pos, end = 0, len(text)
    match = _TOKEN.match
    cols = Columns(text) if "\t" in text else None
    bad_end = -1  # a run of unexpected characters is reported once, at its start
    while pos < end:
        m = match(text, pos)
        if m is None:  # blanks to the end, or a character no token starts with
            pos = _SKIP_BLANKS.match(text, pos).end()
            if pos == end:
                break
            if pos != bad_end:
                col = cols(pos) if cols else pos + 1
                diags.lexical_error(src, lang, n, col, f"unexpected {describe(text[pos])}")
            pos += 1
            bad_end = pos
            continue
        kind = m.lastgroup
        s = m[kind]
        pos = m.end()
        start = pos - len(s)
        col = cols(start) if cols else start + 1
        if kind == "comment":
            continue
        if kind == "num":
            tail = _NUMBER_TAIL.match(text, pos)
            if tail:
                diags.lexical_error(src, lang, n, col, f"malformed number `{s + tail.group()}`")
                pos = tail.end()
                continue
        elif kind == "id":
            if s in KEYWORDS:
                kind = KW
        elif kind == "annot":
            if s not in ANNOTATIONS:
                diags.lexical_error(src, lang, n, col, f"unknown annotation `{s}`")
                continue
        toks.append(Tok(kind, s, n, col))
    return toks


def lex(src: Source, diags: Diagnostics, lang: str) -> list[list[Tok]]:
    """Tokens line by line; index 0 is line 1. Blank and comment-only lines
    give empty lists."""
    return [lex_line(src, i + 1, text, diags, lang) for i, text in enumerate(src.lines)]
