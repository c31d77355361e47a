"""A motor file's errors were all reported, each echoing the text at
fault: a spreadsheet's CSV saved as `.eng` (60,000 lines of `0.5,10`
under the 1 MiB a file may hold) printed 60,000 errors, and a number
100,000 characters long was printed whole in its message.

Now a motor file shows at most PER_FILE (100) errors, as a config does,
and counts the rest ("N more errors not shown"); a token shown in a
message is cut to 40 characters (`...`)."""

from __future__ import annotations

import pytest

from fswkit.autocode.diagnostics import PER_FILE
from fswkit.plant.motor import EngError, parse


def test_at_most_a_hundred_errors_shown():
    text = "X10 29 124 4-7 0.005 0.010 M\n" + "0.5,10\n" * 5000
    with pytest.raises(EngError) as e:
        parse(text, "m.eng")
    errors = e.value.errors
    assert len(errors) == PER_FILE + 1, len(errors)
    assert errors[0].startswith("m.eng:2:1: `0.5,10`: expected the time in seconds")
    assert errors[-1] == f"m.eng: {5000 - PER_FILE:,} more errors not shown (at most {PER_FILE} a file are)"


def test_a_long_token_is_cut():
    long = "1" * 50_000 + "x"
    with pytest.raises(EngError) as e:
        parse(f"X10 29 124 4-7 {long} 0.010 M\n0.1 10\n1 0\n0.1 {long}\n", "m.eng")
    assert all(len(x) < 300 for x in e.value.errors), [len(x) for x in e.value.errors]
    assert e.value.errors[0].startswith("m.eng:1:16: `" + "1" * 40 + "...`: expected the motor's propellant mass")
