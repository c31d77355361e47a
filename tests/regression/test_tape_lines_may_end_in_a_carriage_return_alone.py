"""A log or a tape saved with a carriage return alone at each line's end
(Excel for Mac's "CSV (Macintosh)", old Mac tools) was one long line to
the readers: `fsw tape import` said `LOG:1: no data rows after the column
line` of a log full of rows, and a tape was `not a fswkit sensor tape`
though its first line was the tape's. CR, LF and CRLF now all end a line,
and such a file reads as the same file with LF."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES, run_fsw
from fswkit.tape import TapeError, read_tape
from fswkit.tape.formats import convert

CATS = "ts,filtered_altitude_AGL,filtered_acceleration\n-0.02,0.5,0.0981\n0.0,1.0,98.1\n0.01,2.0,100.0\n"
TAPE = "# fswkit sensor tape v1\n# derived: written for this test\ntime_s,pressure_pa,accel_g\n-0.1,90000,1\n0,89990,5\n"


def test_a_log_of_cr_line_ends_reads_as_with_lf(tmp_path):
    lf, cr = tmp_path / "lf.csv", tmp_path / "cr.csv"
    lf.write_text(CATS)
    cr.write_bytes(CATS.replace("\n", "\r").encode())
    a, b = convert("cats", str(lf)), convert("cats", str(cr))
    assert b.rows == 3 and a.time.tolist() == b.time.tolist() and a.pressure.tolist() == b.pressure.tolist()


def test_a_tape_of_cr_line_ends_reads_as_with_lf(tmp_path):
    lf, cr = tmp_path / "lf.csv", tmp_path / "cr.csv"
    lf.write_text(TAPE)
    cr.write_bytes(TAPE.replace("\n", "\r").encode())
    a, b = read_tape(str(lf)), read_tape(str(cr))
    assert b.rows == 2 and a.time.tolist() == b.time.tolist() and b.derived == ("written for this test",)


def test_an_error_is_located_on_the_cr_line(tmp_path):
    cr = tmp_path / "cr.csv"
    cr.write_bytes(CATS.replace("98.1", "9x.1").replace("\n", "\r").encode())
    with pytest.raises(TapeError) as e:
        convert("cats", str(cr))
    assert str(e.value).startswith(f"{cr}:3:9: filtered_acceleration")


def test_a_replay_locates_a_cr_tapes_rows_too(tmp_path):
    text = TAPE + "5000,80000,\n"  # row 6, beyond the tapes' -3,600 to 3,600 s
    p = tmp_path / "cr.csv"
    p.write_bytes(text.replace("\n", "\r").encode())
    (tmp_path / "cr.truth.toml").write_text('name = "cr"\napogee_s = 3.0\nburnout_s = 1.0\n')
    r = run_fsw("sim", str(EXAMPLES / "hpr"), "--tape", str(p), "--out", str(tmp_path / "out"))
    assert r.code == 2 and r.err.startswith(f"fsw sim: {p}:6:1: time_s 5000 is beyond -3,600 to 3,600 s"), r.err
