"""A motor file's number written in digits of another script (Arabic-Indic
`١٠٠`, fullwidth `０.1`, as a localized spreadsheet or an IME may type
them) was read as Python's float() reads it: `0.1 ١٠٠` flew 100 N, where
every other input of the kit (a tape's cells, a log's) takes only ASCII
digits and says so. Now such a number is an error at its column, as
`1_0` is ("written as Python would"); a header's masses too, and a name
that is no number is still a header."""

from __future__ import annotations

import pytest

from fswkit.plant.motor import EngError, parse

HEADER = "X10 29 124 4-7 0.005 0.010 M\n"
ASCII = "a plain number (ASCII digits)"


@pytest.mark.parametrize("text, line, col, message", [
    (HEADER + "0.1 \u0661\u0660\u0660\n1 0\n", 2, 5, f"`\u0661\u0660\u0660`: expected the thrust in newtons, {ASCII}"),
    (HEADER + "\uff10.1 10\n1 0\n", 2, 1, f"`\uff10.1`: expected the time in seconds, {ASCII}"),
    ("X10 29 124 4-7 \u0660.005 0.010 M\n0.1 10\n1 0\n", 1, 16,
     "`\u0660.005`: expected the motor's propellant mass in kg, a positive number"),
])
def test_a_number_in_other_digits_is_an_error_at_its_column(text, line, col, message):
    with pytest.raises(EngError) as e:
        parse(text, "bad.eng")
    assert e.value.errors[0] == f"bad.eng:{line}:{col}: {message}", e.value.errors


def test_ascii_numbers_are_read():
    (m,) = parse(HEADER + "+0.1 1e1\n1 0\n", "ok.eng")
    assert m.points == ((0.1, 10.0), (1.0, 0.0))
