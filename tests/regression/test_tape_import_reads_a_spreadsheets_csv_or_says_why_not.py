"""A recorder's log saved again by a spreadsheet: quoted cells
(`"ts","filtered_altitude_AGL",...`, what LibreOffice writes with "quote
all text cells", and any program for a cell holding a comma) were not
read: the column line was not recognised (`no line names its columns`,
though it did), and a quoted number was `not a finite number`. A log
whose cells a spreadsheet separated with `;` (its CSV in a locale with
decimal commas) or tabs got the same `no line names its columns` at 1:1,
without a word of why. Quoted cells are now read as CSV reads them (the
quotes are not part of the name or number, a comma inside quotes does not
split the cell); a column line separated by `;` or tabs is an error at
that line that says so and what to do."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import run_fsw
from fswkit.tape import TapeError
from fswkit.tape.formats import convert

CATS = ["ts,filtered_altitude_AGL,filtered_acceleration", "-0.02,0.5,0.0981", "0.0,1.0,98.1",
        "0.01,2.0,100.0"]


def write(tmp_path, lines, name="log.csv"):
    p = tmp_path / name
    p.write_text("\n".join(lines) + "\n")
    return str(p)


def test_quoted_names_and_numbers_are_read(tmp_path):
    plain = convert("cats", write(tmp_path, CATS, "plain.csv"))
    quoted = ['"' + line.replace(",", '","') + '"' for line in CATS]
    t = convert("cats", write(tmp_path, quoted))
    assert t.time.tolist() == plain.time.tolist()
    assert t.pressure.tolist() == plain.pressure.tolist() and t.accel.tolist() == plain.accel.tolist()
    # LibreOffice's "quote all text cells": the names quoted, the numbers not
    t = convert("cats", write(tmp_path, [quoted[0]] + CATS[1:], "names.csv"))
    assert t.pressure.tolist() == plain.pressure.tolist()


def test_a_comma_inside_quotes_does_not_split_the_cell(tmp_path):
    head = "time,altitude,pressure,velocity,temperature,events,voltages"
    rows = [head]
    for i in range(60):
        t = i * 0.05
        h = 0.0 if t < 1.0 else (t - 1.0) * 200.0
        events = '"Drogue, Main"' if i == 30 else "-"
        # an RRC3-like log whose events column comes before the columns used
        rows.append(f'{t:.2f},{h:.1f},{events},{900.0 - h / 30:.3f},0,20,3.8')
    rows[0] = "time,altitude,events,pressure,velocity,temperature,voltages"
    t = convert("rrc3", write(tmp_path, rows))
    assert t.rows == 60
    assert t.pressure[30] == pytest.approx((900.0 - (30 * 0.05 - 1.0) * 200.0 / 30) * 100)


def test_a_quoted_cell_that_is_no_number_is_located_at_its_quote(tmp_path):
    lines = CATS[:2] + ['0.0,"1,0",98.1'] + CATS[3:]
    with pytest.raises(TapeError) as e:
        convert("cats", write(tmp_path, lines))
    assert str(e.value).endswith(':3:5: filtered_altitude_AGL (`filtered_altitude_AGL`): `1,0` is not a '
                                 'finite number (a decimal comma: save the log with `.` as the decimal point)')


@pytest.mark.parametrize("sep,said", [(";", "`;`"), ("\t", "tabs")])
def test_a_column_line_of_another_separator_is_said(tmp_path, sep, said):
    lines = ["exported by a spreadsheet"] + [l.replace(",", sep).replace(".", ",") for l in CATS]
    p = write(tmp_path, lines)
    out = tmp_path / "t.csv"
    r = run_fsw("tape", "import", "cats", p, "-o", str(out))
    assert r.code == 1 and not out.exists()
    assert r.err.startswith(f"fsw tape import: {p}:2:1: ") and said in r.err, r.err
    assert "`,` between cells and `.` as the decimal point" in r.err, r.err
