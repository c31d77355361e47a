"""Numbers as users type them on the command line: plain ASCII only.

Python's int() and float() take more than that: `1_000`, digits of any
script (`١٢`, `１０`), surrounding spaces, and for float() `nan` and
`infinity`. An option's number is read here instead, so that what reaches
a flight is what the user meant to type, and anything else is refused.

    decimal("2.5e-3")          # 0.0025; None for anything but [+-]digits[.digits][e[+-]digits]
    integer("42")              # 42; None for anything but [+-]digits
    integer("0x76", hex_ok=True)  # 118: a part's address may be written in hex
    non_finite(" -Inf")        # -inf: what float() would read, said apart as not finite
"""

from __future__ import annotations

import re

_DECIMAL = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?\Z", re.ASCII)
_INTEGER = re.compile(r"[+-]?[0-9]+\Z", re.ASCII)
_HEX = re.compile(r"0[xX][0-9a-fA-F]+\Z", re.ASCII)


def decimal(text: str) -> float | None:
    """The number `text` writes in plain ASCII decimal (a float; an
    exponent that overflows gives an infinity), else None."""
    return float(text) if _DECIMAL.match(text) else None


def integer(text: str, hex_ok: bool = False) -> int | None:
    """The whole number `text` writes in ASCII decimal digits (or, with
    `hex_ok`, as 0x and hex digits), else None."""
    if _INTEGER.match(text):
        return int(text, 10)
    if hex_ok and _HEX.match(text):
        return int(text, 16)
    return None


def non_finite(text: str) -> float | None:
    """The NaN or infinity `text` spells as float() reads it (`nan`, `inf`,
    `infinity`, signed, any case, spaces around), else None: a caller that
    refuses it can say it is not finite, not that it is not a number."""
    word = text.strip().lower()
    return float(word) if word.lstrip("+-") in ("nan", "inf", "infinity") else None
