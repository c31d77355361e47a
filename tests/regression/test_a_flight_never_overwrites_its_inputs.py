"""A single flight, a tape replay and `--run I` write their set of files
(telemetry.log, flight.csv, flight.png, record.log, summary.txt) into
`--out`, and replaced whatever was there: a dispersion file, a plant file or
a sensor tape named like one of them in that folder was lost (`fsw sim
--run 0 --dispersion out/summary.txt --out out` wrote the flight's summary
over the dispersion file, and its replay command then failed). The study
refused it already; every path that writes a flight's files now does, before
any work, and the input is left as it was."""

from __future__ import annotations

import hashlib
import shutil

import pytest

from conftest import EXAMPLES, SHARED

ROCKET = EXAMPLES / "rocket"


def _digest(path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _refused(r, path) -> None:
    assert r.code == 2, r.out + r.err
    assert f"{path}: the flight's {path.name} would overwrite an input of this command" in r.err, r.err
    assert "Traceback" not in r.err


def test_run_of_a_study_keeps_its_dispersion_file(fsw, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    disp = out / "summary.txt"  # a dispersion file under the summary's name
    shutil.copy(ROCKET / "dispersion.toml", disp)
    before = _digest(disp)
    r = fsw("sim", str(ROCKET), "--plant", "rocket", "--run", "0", "--dispersion", str(disp), "--out", str(out))
    _refused(r, disp)
    assert _digest(disp) == before


def test_a_flight_keeps_its_plant_file(fsw, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    plant = out / "flight.csv"  # a plant file under the CSV's name
    plant.write_text(f'extends = "{ROCKET / "plant.toml"}"\n\n[scenario]\nmax_s = 5\n')
    before = _digest(plant)
    r = fsw("sim", str(ROCKET), "--plant", "rocket", "--params", str(plant), "--out", str(out))
    _refused(r, plant)
    assert _digest(plant) == before


@pytest.mark.skipif(not (SHARED / "flights" / "hedy_cats.csv").is_file(), reason="the shared flight tapes are absent")
def test_a_replay_keeps_its_tape(fsw, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    tape = out / "flight.csv"  # the tape under the replay's CSV's name
    shutil.copy(SHARED / "flights" / "hedy_cats.csv", tape)
    shutil.copy(SHARED / "flights" / "hedy_cats.truth.toml", out / "flight.truth.toml")
    before = _digest(tape)
    r = fsw("sim", str(EXAMPLES / "hpr"), "--tape", str(tape), "--out", str(out))
    _refused(r, tape)
    assert _digest(tape) == before
