"""A motor whose burn is over within a plant step or two (a RASP file of
`0.0002 500000` / `0.0004 0`, 100 N·s in 0.4 ms, or the same curve as
plant.toml's `thrust_curve`) was flown: the plant samples the thrust at
its steps' ends and middles, saw none, and the vehicle sat on the pad
while the summary said `motor: 102.9 N·s` and every check of the firmware
failed. Now a burn shorter than 10 plant steps is an error at the line
that gives the curve (`file` or `thrust_curve`), saying the burn and the
step; a burn of 10 steps flies."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import EXAMPLES

from fswkit.plant.run import SetupError, prepare

ROCKET = EXAMPLES / "rocket"


def _plant(tmp_path: Path, motor: str, eng: str | None = None) -> Path:
    text = (ROCKET / "plant.toml").read_text()
    start, end = text.index("[motor]"), text.index("[drogue]")
    p = tmp_path / "plant.toml"
    p.write_text(text[:start] + f"[motor]\n{motor}\n\n" + text[end:])
    if eng is not None:
        (tmp_path / "Z.eng").write_text(eng)
    return p


def _refused(p: Path, key: str) -> str:
    line = next(i for i, x in enumerate(p.read_text().splitlines(), 1) if x.startswith(key))
    with pytest.raises(SetupError) as e:
        prepare(str(ROCKET), "rocket", params=str(p), seed=1)
    text = str(e.value)
    assert f"{p}:{line}: [motor] {key}: " in text, text
    return text


def test_a_motor_file_of_a_burn_within_a_step(tmp_path: Path):
    p = _plant(tmp_path, 'file = "Z.eng"', "Z1 29 124 0 0.05 0.1 ZZ\n0.0002 500000\n0.0004 0\n")
    text = _refused(p, "file")
    assert "the motor burns 0.0004 s: under 10 plant steps (0.01 s at 1000 Hz)" in text, text


def test_a_thrust_curve_of_a_burn_within_a_step(tmp_path: Path):
    p = _plant(tmp_path, "propellant_kg = 0.05\nthrust_curve = [[0.0, 0.0], [0.0002, 500000], [0.0004, 0.0]]")
    text = _refused(p, "thrust_curve")
    assert "the motor burns 0.0004 s: under 10 plant steps" in text, text


def test_a_late_short_burn_counts_from_its_thrust(tmp_path: Path):
    # (0, 0) to (5, 0) is no burn: the thrust lasts 4 ms
    p = _plant(tmp_path, "propellant_kg = 0.1\nthrust_curve = [[0.0, 0.0], [5.0, 0.0], [5.002, 100000], "
                         "[5.004, 0.0]]")
    text = _refused(p, "thrust_curve")
    assert "the motor burns 0.004 s: under 10 plant steps" in text, text


def test_a_burn_of_ten_steps_flies(tmp_path: Path):
    p = _plant(tmp_path, "propellant_kg = 0.1\nthrust_curve = [[0.0, 0.0], [0.005, 40000], [0.01, 0.0]]")
    sc = prepare(str(ROCKET), "rocket", params=str(p), seed=1)[2]
    assert sc.motor.burn_time == 0.01
