"""The trace's rows (`fsw test --trace`, and the native runner's traces as
the differential tests convert them): each line is what the csv module
writes for the step and the variables in the trace's column order — a bool
as true/false, a float by repr (nan, inf, -0.0 included), an integer as it
is, CR LF at the end — though the rows are formatted without it (one
format call a row)."""

from __future__ import annotations

import csv
import io
import math
import random

from fswkit.run.script import _row_maker


def _csv_line(row) -> str:
    buf = io.StringIO(newline="")
    csv.writer(buf).writerow(row)
    return buf.getvalue()


def test_a_row_is_what_the_csv_module_writes():
    kinds = ("bool", "float", "int", "float", "int", "bool")
    places = (5, 0, 1, 2, 3, 4)
    row_of = _row_maker(kinds, places)
    floats = [0.0, -0.0, math.nan, math.inf, -math.inf, 1e300, 5e-324, 0.1, -3.5, 2.0 ** 60]
    ints = [0, -1, (1 << 64) - 1, -(1 << 63), 7, True, False]
    rng = random.Random(3)
    for step in range(2000):
        v = [rng.choice(floats), rng.choice(ints), rng.choice(floats + [rng.random()]), rng.choice(ints),
             rng.choice([0, 1, True, False, 2]), rng.choice([0, 1])]
        want = [step] + [("true" if v[p] else "false") if k == "bool" else repr(v[p]) if k == "float" else v[p]
                         for k, p in zip(kinds, places)]
        assert row_of(step, v) == _csv_line(want), v
    assert row_of(3, [1.5, 2, 3.0, 4, 1, 0]) == "3,false,1.5,2,3.0,4,true\r\n"
