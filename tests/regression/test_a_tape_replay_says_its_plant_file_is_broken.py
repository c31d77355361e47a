"""`fsw sim PROJECT --tape` takes defaults (the sensors' channels, the pyro
pins, the mission machine) from the project's `plant.toml`. A plant.toml
that could not be read -- not TOML, or an `extends` naming no file -- was
passed over without a word: the replay then said that the pins and the
machine were "not named" and told the user to set them in plant.toml,
which already did. The replay now refuses the run with plant.toml's own
located error, and says the replay reads its defaults there."""

from __future__ import annotations

import shutil

import pytest

from conftest import EXAMPLES, run_fsw

TAPE = "# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n" + "\n".join(
    f"{i / 10:g},{100000 - 50 * max(i - 10, 0)},1" for i in range(50)) + "\n"


def _vehicle_line(text: str) -> str:
    return f":{text[:text.index('[vehicle]')].count(chr(10)) + 1}:"


@pytest.mark.parametrize("edit, where", [
    (lambda t: t.replace("[vehicle]", "[vehicle", 1), _vehicle_line),   # not TOML
    (lambda t: 'extends = "no-such.toml"\n' + t, lambda t: ":1:"),     # a base that is not there
])
def test_a_broken_plant_file_is_said_with_its_place(tmp_path, edit, where):
    proj = tmp_path / "hpr"
    shutil.copytree(EXAMPLES / "hpr", proj, ignore=shutil.ignore_patterns("build"))
    plant = proj / "plant.toml"
    text = plant.read_text()
    plant.write_text(edit(text))
    tape = tmp_path / "t.csv"
    tape.write_text(TAPE)
    (tmp_path / "t.truth.toml").write_text('name = "t"\napogee_s = 3.0\nburnout_s = 1.0\n')
    r = run_fsw("sim", str(proj), "--tape", str(tape), "--out", str(tmp_path / "out"))
    assert r.code == 2, r.err
    assert f"{plant}{where(text)}" in r.err, r.err
    assert "defaults" in r.err and "not named" not in r.err, r.err
    assert "internal error" not in r.err
    assert not (tmp_path / "out").exists()


def test_a_project_without_a_plant_file_is_not_refused_for_it(tmp_path):
    proj = tmp_path / "hpr"
    shutil.copytree(EXAMPLES / "hpr", proj, ignore=shutil.ignore_patterns("build"))
    (proj / "plant.toml").unlink()
    tape = tmp_path / "t.csv"
    tape.write_text(TAPE)
    (tmp_path / "t.truth.toml").write_text('name = "t"\napogee_s = 3.0\nburnout_s = 1.0\n')
    r = run_fsw("sim", str(proj), "--tape", str(tape), "--out", str(tmp_path / "out"))
    assert r.code == 2, r.err
    assert "plant.toml:" not in r.err and "not named" in r.err, r.err
