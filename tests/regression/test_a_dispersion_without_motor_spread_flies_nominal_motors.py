"""A dispersion file's `[motor] impulse_sd` replaces plant.toml's motor-to-
motor spread (docs/sim.md, "The dispersion file"), yet `impulse_sd = 0`,
written to fly every run of a study on the nominal motor, was taken as if
the key were absent: each run still flew plant.toml's spread (the
example's 2 %), and the study's CSV said nothing of it.

Now a written `impulse_sd`, 0 included, is the study's spread: 0 flies the
nominal curve in every run (impulse factor 1 in the CSV); a file without
the key leaves plant.toml's spread, as before. No flight is flown here:
each run's scenario is built as the study builds it."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import EXAMPLES

from fswkit.plant import study
from fswkit.plant.dispersion import draw, load
from fswkit.plant.run import prepare

ROCKET = EXAMPLES / "rocket"


def _motors(tmp_path: Path, text: str) -> list[tuple]:
    d = tmp_path / "d.toml"
    d.write_text(text)
    disp = load(str(d))
    app, layout, _sc = prepare(str(ROCKET), "rocket", seed=1)
    setup = study.Setup(app, layout, str(ROCKET / "plant.toml"), "", None, disp, 1)
    out = []
    for i in range(8):
        dr = draw(disp, 1, i)
        sc = study.scenario_for(setup, dr)
        out.append((sc.motor.total / sc.nominal_impulse, dr.row()["impulse_factor"]))
    return out


def test_a_written_zero_flies_the_nominal_motor(tmp_path: Path):
    for ratio, factor in _motors(tmp_path, "[motor]\nimpulse_sd = 0\n"):
        assert ratio == 1.0 and factor == 1.0


def test_no_key_leaves_the_plants_spread(tmp_path: Path):
    runs = _motors(tmp_path, "[vehicle]\nmass_sd = 0.01\n")
    assert all(factor is None for _, factor in runs)
    assert len({round(ratio, 12) for ratio, _ in runs}) == len(runs)  # plant.toml's 2 %: each run its own motor
    assert all(abs(ratio - 1) < 0.1 for ratio, _ in runs)


def test_a_written_spread_is_the_draws(tmp_path: Path):
    for ratio, factor in _motors(tmp_path, "[motor]\nimpulse_sd = 0.05\n"):
        assert ratio == pytest.approx(factor) and factor != 1.0
