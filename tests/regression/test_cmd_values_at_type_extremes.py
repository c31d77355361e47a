"""`fsw cmd set` accepts every element type's documented extreme values
(docs/languages.md §2: the integers' ranges, ±3.4028235e38 and ±inf for
F32, ±1.7976931348623157e308 and ±inf for F64) and refuses the first value
past each, with the type's range in the message: the F32 test is against
the exact binary32 maximum as a decimal rounds to it, not a truncation."""

from __future__ import annotations

import struct

import pytest
from conftest import EXAMPLES, run_fsw

from fswkit.autocode.types import TYPES
from fswkit.link.layout import Element, LayoutError, encode_value

F32_MAX = struct.unpack("<f", b"\xff\xff\x7f\x7f")[0]  # 3.4028234663852886e38


def _el(t):
    return Element(0, "x", t, 0, "R")


@pytest.mark.parametrize("t", sorted(n for n, t in TYPES.items() if t.is_int))
def test_integer_extremes(t):
    lo, hi = TYPES[t].lo, TYPES[t].hi
    size = {"8": 1, "16": 2, "32": 4, "64": 8}[t[1:]]
    for v in (lo, hi, hex(hi)):
        assert len(encode_value(_el(t), str(v))) == size
    for v in (lo - 1, hi + 1):
        with pytest.raises(LayoutError, match=f"outside {lo}..{hi}"):
            encode_value(_el(t), str(v))


@pytest.mark.parametrize("t,accepted,refused", [
    ("F32", ["3.4028235e38", "-3.4028235e38", repr(F32_MAX), "3.40282356e38", "inf", "-inf", "1e-46"],
     ["3.4028236e38", "-3.4028236e38", "3.4028235677973366e38", "1e39"]),
    ("F64", ["1.7976931348623157e308", "-1.7976931348623157e308", "inf", "-inf", "5e-324"],
     ["1.7976931348623159e308", "-1.7976931348623159e308", "1e309"]),
])
def test_float_extremes(t, accepted, refused):
    fmt = "<f" if t == "F32" else "<d"
    for text in accepted:
        got = struct.unpack(fmt, encode_value(_el(t), text))[0]
        assert got == float(text) or got == struct.unpack(fmt, struct.pack(fmt, float(text)))[0], text
    for text in refused:
        with pytest.raises(LayoutError, match="out of its range"):
            encode_value(_el(t), text)


def test_bool_values():
    assert encode_value(_el("bool"), "true") == b"\x01" and encode_value(_el("bool"), "0") == b"\x00"
    with pytest.raises(LayoutError):
        encode_value(_el("bool"), "2")


def test_cmd_set_documented_f32_maximum():
    # the value is checked before the port is opened: a refused value never reaches it
    r = run_fsw("cmd", "set", "padPressure", "3.4028235e38", "--port", "/dev/no-such-port",
                "-p", str(EXAMPLES / "rocket"))
    assert r.code == 1 and "cannot open /dev/no-such-port" in r.err, r.err
    r = run_fsw("cmd", "set", "padPressure", "3.4028236e38", "--port", "/dev/no-such-port",
                "-p", str(EXAMPLES / "rocket"))
    assert r.code == 2 and "out of its range" in r.err and "cannot open" not in r.err, r.err  # bad input


@pytest.mark.parametrize("value", ["-3.4028235e38", "-inf", "-1e-46", "-.5e3", "-Infinity", "-nan", "-0x7f"])
def test_cmd_set_negative_values_are_values_not_options(value):
    # the documented minimum of F32 and -inf are values of `set`, not unknown options,
    # wherever the options stand: before the command or after its arguments
    for argv in (("cmd", "set", "padPressure", value, "--port", "/dev/no-such-port", "-p", str(EXAMPLES / "rocket")),
                 ("cmd", "--port", "/dev/no-such-port", "-p", str(EXAMPLES / "rocket"), "set", "padPressure", value)):
        r = run_fsw(*argv)
        assert "unrecognized arguments" not in r.err, r.err
        if value == "-0x7f":  # a hex integer is no F32 value: refused as a value, by fsw cmd
            assert r.code == 2 and "is not a number" in r.err and "cannot open" not in r.err, r.err
        else:
            assert r.code == 1 and "cannot open /dev/no-such-port" in r.err, r.err
