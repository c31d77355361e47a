"""parse_tape reads a usual row (ASCII, no `_`, each cell a finite number
or empty) in one go and any other cell by cell: both must give each cell
what `number` gives the stripped cell (math.nan for an empty one), and
the same located errors."""

from __future__ import annotations

import math

import pytest

from fswkit.tape.tape import COLUMN_LINE, MAGIC, TapeError, number, parse_tape

PRESSURES = ["101325", " 95000.5", "95000.5 ", "\t9e4", "+90000", "", "\x1c97000.25\x1f", "1.0E5\x0b", "1e+5"]
ACCELS = ["1.5", " 1.5", "1.5 ", "\t2", "+3", "-0", ".5", "1e2", "1E-3", "", "\x1c7.25\x1f", "8.5\x0b", "-0.0"]


def _tape(rows: list[str]) -> str:
    return "\n".join([MAGIC, COLUMN_LINE] + rows) + "\n"


def _value(cell: str) -> float:
    s = cell.strip()
    return math.nan if not s else number(s)


def _same(got: list[float], want: list[float]) -> bool:
    return all((g == w and math.copysign(1, g) == math.copysign(1, w)) or (g != g and w != w)
               for g, w in zip(got, want, strict=True))


def test_every_cell_reads_as_number_reads_it_stripped():
    rows, want_p, want_a = [], [], []
    for p in PRESSURES:
        for a in ACCELS:
            rows.append(f"{len(rows) * 0.01:.2f},{p},{a}")
            want_p.append(_value(p))
            want_a.append(_value(a))
    tape = parse_tape(_tape(rows), "t.csv")
    assert _same(tape.time.tolist(), [round(k * 0.01, 2) for k in range(len(rows))])
    assert _same(tape.pressure.tolist(), want_p) and _same(tape.accel.tolist(), want_a)


@pytest.mark.parametrize("cell,message", [
    ("1_0", "accel_g: `1_0` is not a number"),
    ("nan", "accel_g: `nan` is not a finite number"),
    ("inf", "accel_g: `inf` is not a finite number"),
    ("1e400", "accel_g: `1e400` is not a number"),
    ("\u0661", "accel_g: `\u0661` is not a number"),
])
def test_a_cell_that_is_no_finite_number_is_located(cell, message):
    with pytest.raises(TapeError) as e:
        parse_tape(_tape(["0.00,101325,1.0", f"0.01,101325,{cell}"]), "t.csv")
    assert message in str(e.value), str(e.value)
    assert "t.csv:4:" in str(e.value), str(e.value)


def test_times_out_of_order_and_pressures_not_above_zero_are_located_in_either_way():
    with pytest.raises(TapeError) as e:
        parse_tape(_tape(["0.00,101325,1.0", "0.00,101325,", "0.01, 0,1.0", "0.005,-1,1_0"]), "t.csv")
    text = str(e.value)
    assert "t.csv:4:1: time_s 0.00 is not after the previous row's 0: times increase strictly" in text, text
    assert "t.csv:5:6: pressure_pa 0 is not above 0 Pa" in text, text
    assert "t.csv:6:1: time_s 0.005 is not after the previous row's 0.01: times increase strictly" in text, text
    assert "t.csv:6:7: pressure_pa -1 is not above 0 Pa" in text, text
