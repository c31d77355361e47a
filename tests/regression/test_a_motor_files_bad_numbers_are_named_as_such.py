"""A thrust point whose time was not a plain number was taken for a motor's
header: `nan 10`, `inf 10`, `1_0 10`, a decimal comma `0,5 10` or a
spreadsheet's `0.5,10` were each reported as "a motor's header has 7
fields ...; this one has 2" at the end of the line, after "motor X has no
thrust points" at the real header; a decimal comma in a thrust or a mass
was "expected a number" with no word of the comma; and a RockSim `.rse`
file (XML) was a header error on every line.

Now such a line is the thrust point it is meant to be: its time is the
error, at its column, saying what is wrong with it (not finite, written as
Python would, a comma where a decimal point or a space goes); a comma in
any number of the file says so; and an XML file is one error at its first
`<`, naming the RASP file to download instead."""

from __future__ import annotations

import pytest

from fswkit.plant.motor import EngError, parse

HEADER = "X10 29 124 4-7 0.005 0.010 M\n"
COMMA = "(a decimal point, not a comma; the fields of a line are separated by spaces)"


@pytest.mark.parametrize("text, line, col, message", [
    (HEADER + "nan 10\n1 0\n", 2, 1, "`nan`: expected the time in seconds, a finite number"),
    (HEADER + "0.1 10\n-inf 10\n1 0\n", 3, 1, "`-inf`: expected the time in seconds, a finite number"),
    (HEADER + "1_0 10\n20 0\n", 2, 1, "`1_0`: expected the time in seconds, a plain number (no `_`)"),
    (HEADER + "0,1 10\n1 0\n", 2, 1, f"`0,1`: expected the time in seconds, a number {COMMA}"),
    (HEADER + "0.1,10\n1,0\n", 2, 1, f"`0.1,10`: expected the time in seconds, a number {COMMA}"),
    (HEADER + "  0.1 10,5\n1 0\n", 2, 7, f"`10,5`: expected the thrust in newtons, a number {COMMA}"),
    ("X10 29 124 4-7 0,005 0,010 M\n0.1 10\n1 0\n", 1, 16,
     f"`0,005`: expected the motor's propellant mass in kg, a positive number {COMMA}"),
    ("nan 10\n", 1, 1, "`nan`: expected the time in seconds, a finite number"),
])
def test_a_bad_time_is_the_error_at_its_column(text, line, col, message):
    with pytest.raises(EngError) as e:
        parse(text, "bad.eng")
    first = e.value.errors[0]
    assert first == f"bad.eng:{line}:{col}: {message}", e.value.errors
    assert not any("header has 7 fields" in x or "no thrust points" in x for x in e.value.errors), e.value.errors


def test_a_rocksim_file_is_said_to_be_one():
    rse = ('\n  <engine-database>\n  <engine-list>\n    <engine code="G80T" mfg="AeroTech" propWt="62.5">\n'
           '      <data><eng-data t="0.0" f="0.0"/></data>\n    </engine>\n  </engine-list>\n</engine-database>\n')
    with pytest.raises(EngError) as e:
        parse(rse, "G80T.eng")
    assert e.value.errors == ["G80T.eng:2:3: an XML file (a RockSim .rse motor file?), not a RASP .eng motor file: "
                              "download the motor's RASP (.eng) file instead"]


def test_motors_named_like_numbers_are_still_motors():
    # Estes's fractional motors, and a name Python would read as a number: headers of seven fields
    a, b = parse("1/2A3T 13 45 2-4 0.0015 0.0056 Estes\n0.1 4\n0.3 0\n"
                 "Inf 13 45 2-4 0.0015 0.0056 Estes\n0.1 4\n0.3 0\n", "m.eng")
    assert (a.name, b.name) == ("1/2A3T", "Inf")
