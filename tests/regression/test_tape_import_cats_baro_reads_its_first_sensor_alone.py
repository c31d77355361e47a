"""A CATS barometer log (`ts, id, T, P`) with more than one sensor
interleaved kept `the first sensor id's rows`, as documented, but decided
which rows came too late over every sensor's rows: where another sensor's
row came first at a time, the first sensor's row at the same time was
dropped as `not after the previous row` -- a log of two sensors written
at the same instants gave a tape of one row. The pressure's unit was told
from the median of every sensor's values, and a bad cell of a sensor the
tape does not use refused the log. Now the first sensor's rows are read
on their own: their times, their unit, their cells."""

from __future__ import annotations

import pytest

from conftest import run_fsw
from fswkit.tape import read_tape
from fswkit.tape.formats import convert

HEAD = "ts,id,T,P\n"


def interleaved(other_first: bool, other_p: str = "99700") -> str:
    rows = []
    for i in range(6):
        t = f"{(i - 1) / 100:.2f}"
        mine = f"{t},BARO0,25.0,{99600 - 10 * i}"
        other = f"{t},BARO1,25.1,{other_p}"
        if i == 0:
            rows.append(mine)  # BARO0 is the first id in the file
        else:
            rows += [other, mine] if other_first else [mine, other]
    return HEAD + "\n".join(rows) + "\n"


@pytest.mark.parametrize("other_first", [False, True])
def test_the_first_sensor_keeps_every_row(tmp_path, other_first):
    log = tmp_path / "baro.csv"
    log.write_text(interleaved(other_first))
    t = convert("cats", str(log))
    assert t.time.tolist() == [-0.01, 0.0, 0.01, 0.02, 0.03, 0.04]
    assert t.pressure.tolist() == [99600.0, 99590.0, 99580.0, 99570.0, 99560.0, 99550.0]
    assert not any("rows dropped" in d for d in t.derived)


def test_the_unit_is_the_first_sensors_own(tmp_path):
    # BARO1, at twice BARO0's rate, writes hPa: the median of both sensors' values was
    # hPa-sized, and BARO0's Pa were multiplied by 100 (9,960,000 Pa) without a word
    rows = [f"{i / 100:.3f},BARO0,25.0,{99600 - 10 * i}\n" + "".join(
        f"{i / 100 + k / 300:.3f},BARO1,25.1,997.{k}\n" for k in (1, 2)) for i in range(6)]
    log = tmp_path / "baro.csv"
    log.write_text(HEAD + "".join(rows))
    t = convert("cats", str(log))
    assert t.pressure.tolist() == [99600.0, 99590.0, 99580.0, 99570.0, 99560.0, 99550.0]
    assert any("'P' (Pa) as is" in d for d in t.derived)


def test_a_bad_cell_of_another_sensor_is_not_read(tmp_path):
    log = tmp_path / "baro.csv"
    log.write_text(interleaved(False, "err"))
    out = tmp_path / "t.csv"
    r = run_fsw("tape", "import", "cats", str(log), "-o", str(out))
    assert r.code == 0, r.err
    assert "6 rows" in r.err and "dropped" not in r.err
    assert read_tape(str(out)).rows == 6
