"""`fsw sim PROJECT --plant rocket` without `--out` writes the flight into
the project's build folder (build/BOARD/rocket-flight). On a project never
built before, the command made that folder first, and then the build
refused its own build folder: "holds files a build of fswkit did not write
(rocket-flight)". A newcomer's first flight failed, and so did a first
study, a study's run replayed and a tape replayed without `--out` (each
makes its folder there). The build folder is now made the kit's (its
`.lock`, as the build writes it) before a command's folder is made in it;
a build folder holding the user's files is still refused, before anything
is written there."""

from __future__ import annotations

import pytest

from conftest import run_fsw
from support.closed_loop import needs_avr_sim
from support.configs import example_copy

pytestmark = needs_avr_sim


def test_a_first_tank_flight_without_out(tmp_path):
    tank = example_copy("tank", tmp_path)
    assert not (tank / "build").exists()
    r = run_fsw("sim", str(tank), "--plant", "tank")
    assert r.code == 0, r.err
    out = tank / "build" / "uno" / "tank-flight"
    assert (out / "summary.txt").is_file() and (out / "flight.csv").is_file(), sorted(out.iterdir())
    r = run_fsw("sim", str(tank), "--plant", "tank")  # and again, into the same folders
    assert r.code == 0, r.err


def test_a_first_study_run_replayed_without_out(tmp_path):
    rocket = example_copy("rocket", tmp_path)
    r = run_fsw("sim", str(rocket), "--plant", "rocket", "--dispersion", str(rocket / "dispersion.toml"),
                "--run", "1")
    assert r.code == 0, r.err
    assert (rocket / "build" / "uno" / "rocket-run-1" / "summary.txt").is_file()


@pytest.mark.parametrize("how", [["--plant", "tank"], ["--plant", "rocket", "--runs", "2"]])
def test_a_build_folder_of_the_users_is_still_refused_and_left_alone(tmp_path, how):
    project = example_copy("tank" if "tank" in how else "rocket", tmp_path)
    mine = project / "build" / "uno"
    mine.mkdir(parents=True)
    (mine / "notes.txt").write_text("mine\n")
    if "--runs" in how:
        how = how + ["--dispersion", str(project / "dispersion.toml")]
    r = run_fsw("sim", str(project), *how)
    assert r.code == 2, r.out + r.err
    assert "the project's build folder, holds files a build of fswkit did not write (notes.txt)" in r.err, r.err
    assert sorted(p.name for p in mine.iterdir()) == ["notes.txt"]
