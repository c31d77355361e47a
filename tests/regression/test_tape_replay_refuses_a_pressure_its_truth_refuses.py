"""`fsw tape truth` refused a tape holding a pressure beyond the ISA
troposphere (-1 to 11 km ASL: a glitch row the import keeps, as the Juno
III RRC3 log's 191 hPa), but `fsw sim --tape` flew the same tape against a
truth file written beside it: the replay's altitude of truth, worked out
from every pressure of the tape, moved by hundreds of metres around the
row (one such row of 5,000 Pa in the NDRT Raven flight's descent: an
altitude error of 230 m "largest", and every check passed). A replay now
refuses such a tape before the build, at the row's line, with the truth's
own message."""

from __future__ import annotations

import shutil

import pytest

from conftest import EXAMPLES, SHARED, run_fsw

NDRT = SHARED / "flights" / "ndrt2020_raven.csv"
pytestmark = pytest.mark.skipif(not NDRT.exists(), reason=f"{NDRT} is not there")


def test_a_replay_refuses_a_pressure_beyond_the_troposphere_at_its_line(tmp_path):
    lines = NDRT.read_text().splitlines(keepends=True)
    first = next(i for i, x in enumerate(lines) if x.startswith("time_s")) + 1
    row = first + 1500
    cells = lines[row].split(",")
    cells[1] = "5000"
    lines[row] = ",".join(cells)
    tape = tmp_path / "ndrt.csv"
    tape.write_text("".join(lines))
    shutil.copy(NDRT.with_suffix("").with_suffix(".truth.toml"), tmp_path / "ndrt.truth.toml")
    r = run_fsw("sim", str(EXAMPLES / "hpr"), "--tape", str(tape), "--out", str(tmp_path / "out"))
    assert r.code != 0, r.out
    assert f"{tape}:{row + 1}: pressure_pa 5000 is " in r.err and "beyond the ISA troposphere" in r.err, r.err
    assert not (tmp_path / "out").exists()
