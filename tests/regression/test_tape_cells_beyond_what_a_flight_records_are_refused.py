"""A tape took any finite number in any cell: an acceleration of 1e308 g
(`fsw tape truth` wrote `max_accel_g = 1e+308`, `fsw tape show` its
`max 1e+308`), a pressure of 1e308 Pa (`fsw sim --tape` flew it and
reported an altitude error of 1e59 m RMS), a last time of 1e308 s (the
truth's `log_end_s = 1e+308`), rows 1e-300 s apart (a whole flight in
3.5e-297 s: "no apogee"), and a clock that jumped 3,000 s in the descent
(the truth's landing at 3,085 s; the replay flew 50 simulated minutes for
a FAIL). Every cell of a tape now has a physical range, checked by the
reader (`fsw tape show`, `fsw tape truth`, `fsw sim --tape`) and refused at
its line and column, naming the column, the value, the range and what to
do: time_s from -3,600 to 3,600 s, rows 1 µs to 60 s apart, pressure_pa
1,000 to 120,000 Pa, accel_g -250 to 250 g (docs/tapes.md, "Ranges")."""

from __future__ import annotations

import pytest

from conftest import SHARED, run_fsw

HEAD = "# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n"


def good_rows() -> list[str]:
    return [f"{i / 100 - 0.5:.2f},{95000 - 40 * max(i - 50, 0)},{1 if i < 50 else 5}" for i in range(200)]


def tape(tmp_path, rows: list[str]) -> str:
    p = tmp_path / "t.csv"
    p.write_text(HEAD + "\n".join(rows) + "\n")
    return str(p)


def cell(rows, i, k, value):
    cells = rows[i].split(",")
    cells[k] = value
    rows[i] = ",".join(cells)
    return rows


CASES = [  # (row, cell, value, the column named, words of the range)
    (120, 2, "1e308", "accel_g 1e+308", "-250 to 250 g"),
    (120, 2, "-1e308", "accel_g -1e+308", "-250 to 250 g"),
    (120, 2, "1000", "accel_g 1000", "-250 to 250 g"),
    (120, 1, "1e308", "pressure_pa 1e+308", "1,000 to 120,000 Pa"),
    (120, 1, "1e7", "pressure_pa 1e+07", "1,000 to 120,000 Pa"),
    (120, 1, "1e-300", "pressure_pa 1e-300", "1,000 to 120,000 Pa"),
    (199, 0, "1e308", "time_s 1e+308", "-3,600 to 3,600 s"),
    (0, 0, "-1e308", "time_s -1e+308", "-3,600 to 3,600 s"),
    (199, 0, "3601", "time_s 3601", "-3,600 to 3,600 s"),
]


@pytest.mark.parametrize("row, k, value, said, span", CASES)
def test_a_cell_beyond_its_range_is_refused_at_its_line_and_column(tmp_path, row, k, value, said, span):
    rows = cell(good_rows(), row, k, value)
    path = tape(tmp_path, rows)
    col = sum(len(c) + 1 for c in rows[row].split(",")[:k]) + 1
    for command in (("tape", "show", path), ("tape", "truth", path, "-o", "-")):
        r = run_fsw(*command)
        assert r.code == 1, (command, r.out, r.err)
        assert f"{path}:{row + 3}:{col}: {said} " in r.err, r.err
        assert span in r.err and "Traceback" not in r.err and "Warning" not in r.err, r.err
        assert "max_accel_g" not in r.out


def test_a_clock_that_jumps_is_refused_at_the_row_after_the_jump(tmp_path):
    rows = good_rows()
    rows = rows[:150] + [f"{float(r.split(',')[0]) + 3000:.2f},{r.split(',', 1)[1]}" for r in rows[150:]]
    path = tape(tmp_path, rows)
    r = run_fsw("tape", "truth", path, "-o", "-")
    assert r.code == 1, r.out
    assert f"{path}:153:1: time_s 3001 is 3,000.01 s after the previous row's 0.99 s" in r.err, r.err
    assert "60 s apart" in r.err and "landing_s" not in r.out


def test_rows_closer_than_a_microsecond_are_refused(tmp_path):
    rows = [f"{i * 1e-300:g},{r.split(',', 1)[1]}" for i, r in enumerate(good_rows())]
    path = tape(tmp_path, rows)
    r = run_fsw("tape", "truth", path, "-o", "-")
    assert r.code == 1, r.out
    assert f"{path}:4:1: time_s 1e-300 is 1e-300 s after the previous row's 0 s" in r.err, r.err
    assert "1 µs apart" in r.err


def test_a_replay_refuses_a_tape_cell_beyond_its_range_before_the_build(tmp_path):
    from conftest import EXAMPLES

    rows = cell(good_rows(), 120, 2, "1e308")
    path = tape(tmp_path, rows)
    (tmp_path / "t.truth.toml").write_text('name = "t"\napogee_s = 1.0\nburnout_s = 0.5\n')
    r = run_fsw("sim", str(EXAMPLES / "hpr"), "--tape", path, "--out", str(tmp_path / "out"))
    assert r.code != 0 and f"{path}:123:" in r.err and "accel_g 1e+308" in r.err, r.err
    assert not (tmp_path / "out").exists()


def test_the_shared_flights_are_within_every_range():
    from fswkit.tape import read_tape

    flights = SHARED / "flights"
    if not flights.is_dir():
        pytest.skip(f"{flights} is absent")
    assert len(sorted(flights.glob("*.csv"))) == 8
    for p in sorted(flights.glob("*.csv")):
        read_tape(str(p))  # raises TapeError on a cell beyond its range


@pytest.mark.parametrize("time, pressure, accel, said", [
    ([0.0, 1e308], [9e4, 9e4], [1.0, 1.0], "row 2: time_s 1e+308 is beyond -3,600 to 3,600 s"),
    ([0.0, 0.1], [9e4, 1.0], [1.0, 1.0], "row 2: pressure_pa 1 is beyond 1,000 to 120,000 Pa"),
    ([0.0, 0.1], [9e4, 9e4], [1.0, -300.0], "row 2: accel_g -300 is beyond -250 to 250 g"),
    ([0.0, 100.0], [9e4, 9e4], [1.0, 1.0], "row 2: time_s 100 is 100 s after the previous row's 0 s"),
    ([0.0, 1e-9], [9e4, 9e4], [1.0, 1.0], "row 2: time_s 1e-09 is 1e-09 s after the previous row's 0 s"),
])
def test_the_writer_writes_no_cell_the_reader_refuses(tmp_path, time, pressure, accel, said):
    import numpy as np

    from fswkit.tape import Tape, TapeError, write_tape

    out = tmp_path / "w.csv"
    tape = Tape(str(out), np.array(time), np.array(pressure), np.array(accel))
    with pytest.raises(TapeError) as e:
        write_tape(str(out), tape)
    assert said in str(e.value), str(e.value)
    assert not out.exists()
