"""Threshold tests on stored float bits, for binary32 R: `R(x) op c` for a
float element x and a constant c, decided by comparing an order-preserving
integer key of x's bytes with one computed here. Rounding to binary32 is
monotonic, so `round32(x) > c` holds exactly for x beyond the midpoint of c
and the next binary32 value (the midpoint itself when its tie rounds up).
Exact rational arithmetic throughout."""

from __future__ import annotations

import functools
import math
import struct
from fractions import Fraction

F32_MAX = Fraction((1 << 24) - 1) * (1 << 104)
TWO128 = Fraction(1 << 128)


def f32_bits(x: float) -> int:
    return struct.unpack("<I", struct.pack("<f", x))[0]


def f32_succ(c: float) -> float:
    """The next binary32 value above c (-0 counts as +0); +inf stays."""
    if c == math.inf:
        return c
    if c == 0:
        return struct.unpack("<f", struct.pack("<I", 1))[0]
    b = f32_bits(c)
    b = b + 1 if c > 0 else b - 1
    return struct.unpack("<f", struct.pack("<I", b))[0]


def f32_pred(c: float) -> float:
    return -f32_succ(-c) if c != 0 else -f32_succ(0.0)


def _exact(v: float) -> Fraction:
    if v == math.inf:
        return TWO128  # rounding treats 2^128 as the (even) neighbour of the max
    if v == -math.inf:
        return -TWO128
    return Fraction(v)


def key64(v: float) -> int:
    bits = struct.unpack("<Q", struct.pack("<d", v))[0]
    return (~bits) & (2**64 - 1) if bits >> 63 else bits | (1 << 63)


def key32(v: float) -> int:
    bits = f32_bits(v)
    return (~bits) & (2**32 - 1) if bits >> 31 else bits | (1 << 31)


@functools.cache  # a machine tests a few constants again and again (-0.0 and 0.0 give the same answer)
def greater(c: float, size: int):
    """How to test `round32(x) > c` for an element x of `size` bytes: True or
    False when no x / every x passes, else (key, inclusive): x passes when
    key(x) > key, or key(x) == key with `inclusive`."""
    if c == math.inf:
        return False
    if size == 4:  # binary32 element: R(x) is x itself
        return (key32(0.0 if c == 0 else c), False)
    s = f32_succ(c)
    m = (_exact(c) + _exact(s)) / 2
    if abs(m) >= TWO128 or m == 0:
        return None  # no binary64 midpoint to compare with: not handled
    even = s == math.inf or f32_bits(s) & 1 == 0
    mf = float(m)
    assert Fraction(mf) == m
    return (key64(mf), even)


def tests(op: str, c: float, size: int):
    """`round32(x) op c` as a list of (negate, greater-test) terms to AND
    together, or None when not expressible."""
    pred = f32_pred(c) if c != -math.inf else None
    if op == ">":
        terms = [(False, greater(c, size))]
    elif op == "<=":
        terms = [(True, greater(c, size))]
    elif op == ">=":
        terms = [(False, greater(pred, size) if pred is not None else True)]
    elif op == "<":
        terms = [(True, greater(pred, size) if pred is not None else True)]
    elif op == "==":
        terms = [(False, greater(pred, size) if pred is not None else True), (True, greater(c, size))]
    else:
        return None
    if any(t is None for _, t in terms):
        return None
    return terms
