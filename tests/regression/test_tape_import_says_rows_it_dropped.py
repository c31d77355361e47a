"""A log whose clock restarted mid-flight (a recorder's brown-out at
ejection) lost every row after the restart until its time passed the last
one before it: dropped as rows whose time is not after the previous one,
as documented, but said only in the tape's header. `fsw tape import`
said `N rows` and nothing else, so a tape that had lost most of its
descent looked whole. The count is said on standard error too."""

from __future__ import annotations

from conftest import run_fsw


def test_rows_dropped_are_said_by_the_command(tmp_path):
    rows = [f"{t / 10:.1f},{t},{9.81}" for t in range(-5, 50)]  # 0 to 4.9 s
    rows += [f"{t / 10:.1f},{100 - t},{9.81}" for t in range(0, 30)]  # the clock starts again at 0
    log = tmp_path / "log.csv"
    log.write_text("ts,filtered_altitude_AGL,filtered_acceleration\n" + "\n".join(rows) + "\n")
    out = tmp_path / "t.csv"
    r = run_fsw("tape", "import", "cats", str(log), "-o", str(out))
    assert r.code == 0, r.err
    assert "55 rows" in r.err
    assert "30 rows of the log dropped: their time is not after the previous row's" in r.err, r.err
    r = run_fsw("tape", "import", "cats", str(log), "-o", "-")
    assert "30 rows of the log dropped" in r.err


def test_one_row_dropped_is_said_in_the_singular(tmp_path):
    """It said `1 rows of the log dropped: their time is ...`."""
    log = tmp_path / "log.csv"
    log.write_text("ts,filtered_altitude_AGL,filtered_acceleration\n-0.1,0,0\n0,0.5,30\n0.1,3,30\n0.1,3,30\n")
    r = run_fsw("tape", "import", "cats", str(log), "-o", str(tmp_path / "t.csv"))
    assert r.code == 0, r.err
    assert "fsw tape import: 1 row of the log dropped: its time is not after the previous row's" in r.err, r.err
