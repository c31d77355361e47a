"""A Featherweight Raven log's channel time cell that was not a finite
number (`NaN`, `inf`) was read as NaN and the row dropped as `a time not
after the previous row` -- counted as a clock's glitch, not refused --
while every other converter refuses such a time at its cell, as
docs/tapes.md says (`a time that is not a finite number ... errors
LOG:LINE:COL`). It is now a located error in every channel, like any
other log's time."""

from __future__ import annotations

import pytest

from conftest import run_fsw

HEAD = "Time-Axial Accel (Gs), Axial Accel (Gs), bILBA, Time (s), Altitude (Ft-AGL), bILBA\n"


def rows(bad_row: int, bad: str, channel: int) -> str:
    out = []
    for i in range(200):
        ta = f"{i * 0.0025:.4f}"
        th = f"{i * 0.05:.3f}"
        if i == bad_row:
            ta, th = (bad, th) if channel == 0 else (ta, bad)
        h = 0.0 if i < 40 else (i - 39) * 20.0
        out.append(f"{ta},{1.0 if i < 40 else 6.0},b0000,{th},{h},b0000\n")
    return HEAD + "".join(out)


@pytest.mark.parametrize("bad", ["NaN", "inf", "nan"])
@pytest.mark.parametrize("channel", [0, 1])
def test_a_channel_time_that_is_no_number_is_refused_at_its_cell(tmp_path, bad, channel):
    text = rows(100, bad, channel)
    log = tmp_path / "raven.csv"
    log.write_text(text)
    out = tmp_path / "t.csv"
    r = run_fsw("tape", "import", "raven", str(log), "-o", str(out))
    assert r.code == 1, r.err
    line = text.splitlines()[101]
    col = 1 if channel == 0 else line.index(bad) + 1
    assert f"{log}:102:{col}: " in r.err and f"`{bad}` is not a finite number" in r.err, r.err
    assert "Traceback" not in r.err and not out.exists()
