"""A parameter file's value is a TOML integer, float or boolean of the
parameter's type (docs/parameters.md), but the reader passed a TOML string
to the checker of typed text: `OPEN_AT = "650"` loaded 650 and
`VENT = "1"` loaded true, where a quoted value is the sign of a file
written for something else; a date was refused in Python's words
(`datetime.date(1979, 5, 27)`), and a whole-number parameter given
500.0000000000001 was told "not 500". Now a string, a date or time and
an array are refused, located, in the file's words, and a number is shown
as it was written."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import run_fsw

RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"


@pytest.mark.parametrize("text, words", [
    ('OPEN_AT = "650"\n', '1:11: `OPEN_AT` is F32: "650" is text; give the number without quotes'),
    ('\nVENT = "1"\n', '2:8: `VENT` is bool: "1" is text; give true or false without quotes'),
    ("HOLD_MS = 1979-05-27\n", "1:11: `HOLD_MS` is U16: a date is not a value of it"),
    ("HOLD_MS = 07:32:00\n", "1:11: `HOLD_MS` is U16: a time is not a value of it"),
    ("HOLD_MS = [500]\n", "1:11: `HOLD_MS` is U16: an array is not a value of it"),
    ("HOLD_MS = 500.0000000000001\n", "1:11: `HOLD_MS` is U16: give a whole number, not 500.0000000000001"),
])
def test_a_value_that_is_not_of_the_type_is_refused_located(tmp_path, text, words):
    f = tmp_path / "p.toml"
    f.write_text(text)
    # diff reads the file before it opens the port: the port is never reached
    r = run_fsw("param", str(RIG), "diff", str(f), "--port", str(tmp_path / "no-port"))
    assert r.code == 2, r.out + r.err
    assert f"{f}:{words}" in r.err, r.err
    assert "datetime" not in r.err and "Traceback" not in r.err


def test_numbers_and_booleans_still_load(tmp_path):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.params import app_parameters
    from fswkit.param.files import read_params
    from fswkit.target.build import load

    f = tmp_path / "p.toml"
    f.write_text("OPEN_AT = 650\nHOLD_MS = 1e3\nTRIM = -7\nVENT = false\n")
    assert read_params(str(f), app_parameters(load(str(RIG), Diagnostics()))) == {
        "OPEN_AT": 650.0, "HOLD_MS": 1000, "TRIM": -7, "VENT": False}
