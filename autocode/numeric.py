"""The evaluation type `R` and the conversions of spec §4.5, bit-exact.

`R` is binary64 (`F64MODE`) on hosts and binary32 (`F32MODE`) on boards
whose `double` is 32 bits. In binary32 mode every intermediate result is
rounded to binary32 as an AVR would: a + b, a - b, a * b and a / b of two
binary32 values are computed exactly enough in binary64 that rounding the
binary64 result once more gives the correctly rounded binary32 result
(53 >= 2 * 24 + 2), so one rounding after each binary64 operation is exact.
"""

from __future__ import annotations

import math
import struct
from fractions import Fraction

from .types import ElemType

INF = math.inf
_F = struct.Struct("<f")
_pack, _unpack = _F.pack, _F.unpack


def f32(x: float) -> float:
    """Rounds a binary64 value to the nearest binary32 (ties to even;
    overflow to infinity)."""
    try:
        return _unpack(_pack(x))[0]
    except OverflowError:
        return math.copysign(INF, x)


def f32_from_fraction(q: Fraction) -> float:
    """Correctly rounded binary32 value of an exact rational."""
    if q == 0:
        return 0.0
    neg = q < 0
    if neg:
        q = -q
    num, den = q.numerator, q.denominator
    e = num.bit_length() - den.bit_length()
    if (num << -e if e < 0 else num) < (den << e if e > 0 else den):
        e -= 1
    qexp = max(e, -126) - 23  # exponent of the last mantissa bit
    if qexp >= 0:
        m, r = divmod(num, den << qexp)
        d = den << qexp
    else:
        m, r = divmod(num << -qexp, den)
        d = den
    if 2 * r > d or (2 * r == d and m & 1):
        m += 1
    if m * (2.0 ** qexp) >= 2.0 ** 128:
        v = INF
    else:
        v = math.ldexp(m, qexp)
    return -v if neg else v


def f32_from_int(i: int) -> float:
    if -(1 << 24) <= i <= (1 << 24):
        return float(i)
    return f32_from_fraction(Fraction(i))


def div(a: float, b: float) -> float:
    """IEEE-754 division: by zero gives a signed infinity, or NaN."""
    try:
        return a / b
    except ZeroDivisionError:
        if a != a or a == 0:
            return math.nan
        return math.copysign(INF, a) * math.copysign(1.0, b)


def truthy(x: float) -> bool:
    """Non-zero and not NaN (spec §4.5: NaN is false everywhere)."""
    return x == x and x != 0


class Real:
    """One evaluation type: how literals, element reads and results are
    rounded."""

    name: str
    bits: int

    def rnd(self, x: float) -> float:  # pragma: no cover - overridden
        raise NotImplementedError

    def from_int(self, i: int) -> float:  # pragma: no cover - overridden
        raise NotImplementedError

    def literal(self, text: str) -> float:  # pragma: no cover - overridden
        raise NotImplementedError

    def read(self, t: ElemType, v) -> float:
        """The value of an element of type `t` holding `v`, as an `R`."""
        if t.kind == "float":
            if v != v:
                return 0.0
            return self.rnd(v)
        return self.from_int(int(v))

    def __repr__(self) -> str:
        return self.name


BOOL_LITERALS = {"true": 1.0, "false": 0.0}


class _F64(Real):
    name, bits = "f64", 64

    def rnd(self, x: float) -> float:
        return x

    def from_int(self, i: int) -> float:
        return float(i)

    def literal(self, text: str) -> float:
        if text in BOOL_LITERALS:
            return BOOL_LITERALS[text]
        return float(text)


_F32_LITERALS: dict[str, float] = {}  # a literal's text -> its binary32 value (exact rounding costs)


class _F32(Real):
    name, bits = "f32", 32

    def rnd(self, x: float) -> float:
        return f32(x)

    def from_int(self, i: int) -> float:
        return f32_from_int(i)

    def literal(self, text: str) -> float:
        value = _F32_LITERALS.get(text)
        if value is None:
            value = _F32_LITERALS[text] = self._literal(text)
        return value

    def _literal(self, text: str) -> float:
        if text in BOOL_LITERALS:
            return BOOL_LITERALS[text]
        d = float(text)
        if d == 0.0 or d == INF:
            return d  # underflows or overflows binary64: binary32 too
        parts = decimal_parts(text)
        if parts is None:  # pragma: no cover - an exponent of a billion digits
            return f32(d)
        digits, e = parts
        if len(digits) > 200:
            # Keep 200 significant digits and a sticky 1 for the rest: no
            # binary32 value or midpoint needs more than 113 digits, so none
            # lies between the literal and this shorter one, and both round
            # alike (and a 100,000-digit literal costs no quadratic int()).
            e += len(digits) - 201
            digits = digits[:200] + "1"
        n = int(digits)
        return f32_from_fraction(Fraction(n * 10**e) if e >= 0 else Fraction(n, 10**-e))


F64MODE = _F64()
F32MODE = _F32()
REALS = {"f64": F64MODE, "f32": F32MODE}


def to_type(t: ElemType, x: float):
    """Assignment conversion of an `R` value into an element of type `t`
    (spec §4.5). Integers and bool give a Python int, floats a float."""
    k = t.kind
    if k == "int":
        if x != x:
            return 0
        if x <= t.lo:
            return t.lo
        if x >= t.hi:
            return t.hi
        return int(x)
    if k == "bool":
        return 1 if (x == x and x != 0) else 0
    if x != x:
        return 0.0
    return f32(x) if t.size == 4 else x


def format_value(t: ElemType, v) -> str:
    """An element's value as the state-script report prints it."""
    if t.kind == "bool":
        return "true" if v else "false"
    if t.kind == "int":
        return str(int(v))
    return "%.6f" % v


def decimal_parts(text: str) -> tuple[str, int] | None:
    """A numeric literal as (significant digits without leading or trailing
    zeros, power of ten): its value is int(digits) * 10**power ("" for 0).
    None when the exponent has more than 9 digits. Never converts a long
    digit string to int (Python refuses over 4300 digits, and is slow)."""
    mant, _, exp = text.lower().partition("e")
    whole, _, frac = mant.partition(".")
    sign = -1 if exp.startswith("-") else 1
    exp = exp.lstrip("+-").lstrip("0")
    if len(exp) > 9:
        return None
    digits = (whole + frac).lstrip("0")
    significant = digits.rstrip("0")
    return significant, sign * int(exp or "0") - len(frac) + len(digits) - len(significant)


def exact_literal(text: str) -> Fraction | None:
    """The exact value of a numeric literal, or None when it is absurdly
    large or small (beyond 10^±4000) or long (over 4000 significant digits)."""
    parts = decimal_parts(text)
    if parts is None:
        return None
    digits, e = parts
    if not digits:
        return Fraction(0)
    if len(digits) > 4000 or abs(e + len(digits)) > 4000:
        return None
    n = int(digits)
    return Fraction(n * 10**e) if e >= 0 else Fraction(n, 10**-e)
