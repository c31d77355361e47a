"""A log or tape of a single row was counted in the plural: `fsw tape
import` said `1 rows, 0.00 to 0.00 s` and `fsw tape show` `pressure_pa:
1 values`. They now say `1 row` and `1 value` (and the plural from 2)."""

from __future__ import annotations

from conftest import run_fsw

LOG = "ts,filtered_altitude_AGL,filtered_acceleration\n0,1,1\n"


def test_one_row_and_one_value(tmp_path):
    log = tmp_path / "log.csv"
    log.write_text(LOG)
    tape = tmp_path / "t.csv"
    r = run_fsw("tape", "import", "cats", str(log), "-o", str(tape))
    assert r.code == 0, r.err
    assert f"{tape}: 1 row, 0.00 to 0.00 s" in r.err, r.err
    r = run_fsw("tape", "show", str(tape))
    assert r.code == 0, r.err
    assert "pressure_pa: 1 value, " in r.out and "accel_g:     1 value, " in r.out, r.out


def test_two_rows_and_two_values(tmp_path):
    log = tmp_path / "log.csv"
    log.write_text(LOG + "0.01,2,1\n")
    tape = tmp_path / "t.csv"
    r = run_fsw("tape", "import", "cats", str(log), "-o", str(tape))
    assert f"{tape}: 2 rows, " in r.err, r.err
    assert "pressure_pa: 2 values, " in run_fsw("tape", "show", str(tape)).out
