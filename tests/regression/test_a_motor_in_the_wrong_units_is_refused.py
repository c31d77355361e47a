"""A motor's numbers in the wrong unit flew: a RASP file with its masses in
grams (`62.5 125.2` for 62.5 g of propellant in a 125.2 g motor) was read
as 62.5 kg of propellant, one with its times in milliseconds as a burn
1,000 times as long (and its impulse 1,000 times as large), a curve of
nothing but zero thrust as a motor; a plant.toml's `propellant_kg` written
in grams likewise. Only a vehicle then too heavy to leave the pad was
refused, with a message about its weight; a short, strong motor flew with
150 kg of propellant to burn.

Now the impulse and the propellant mass are held to each other: their
ratio, the specific impulse (N·s per kg, divided by g0), is that of a
rocket motor, 20 to 500 s (black powder about 80, composites and hybrids
up to about 250, liquid engines up to about 450), or the motor is refused:
in a motor file at its header's propellant mass (file:line:col), in a
plant.toml at its `propellant_kg` line, saying what the ratio is and
which unit is likely wrong. A curve with no impulse is refused as such."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import EXAMPLES, run_fsw

from fswkit.plant.motor import EngError, parse
from fswkit.plant.run import SetupError, prepare

ROCKET = EXAMPLES / "rocket"
G80T_CURVE = "0.02 95\n0.10 104\n0.30 100\n0.60 92\n0.90 82\n1.20 68\n1.35 45\n1.45 15\n1.50 0\n"


@pytest.mark.parametrize("text, col, message", [
    # masses in grams: 118.6 N·s from 62.5 "kg"
    ("G80T 29 124 4-7-10 62.5 125.2 AT\n" + G80T_CURVE, 20,
     "motor G80T: 118.6 N·s from 62.5 kg of propellant is a specific impulse of 0.193 s"),
    # times in milliseconds: an A8's half-second burn as 500 s
    ("A8 18 70 3 0.00312 0.0163 Estes\n20 10\n250 5\n500 0\n", 12,
     "motor A8: 2,450 N·s from 0.00312 kg of propellant is a specific impulse of 80,074 s"),
])
def test_a_motor_file_in_the_wrong_units_is_located(text, col, message):
    with pytest.raises(EngError) as e:
        parse(text, "m.eng")
    (first,) = e.value.errors
    assert first.startswith(f"m.eng:1:{col}: "), first
    assert message in first, first
    assert "a rocket motor's is 20 to 500 s" in first, first
    assert ("a mass in grams" in first) == ("62.5" in text), first
    assert ("milliseconds" in first) == ("A8" in text), first


@pytest.mark.parametrize("points", ["0 0\n0.5 0\n", "1 0\n"])
def test_a_curve_without_impulse_is_no_motor(points):
    with pytest.raises(EngError) as e:
        parse("X 29 124 P 0.05 0.1 M\n" + points, "m.eng")
    assert e.value.errors == ["m.eng:1:1: motor X: its thrust curve delivers no impulse (every point is 0 N)"]


def test_real_motors_pass():
    for f in (ROCKET / "motors").iterdir():
        parse(f.read_text(), str(f))  # black powder (C6, about 82 s) and composites (about 190 s)


def _plant(tmp_path: Path, motor: str) -> tuple[Path, int]:
    text = (ROCKET / "plant.toml").read_text()
    start, end = text.index("[motor]"), text.index("[drogue]")
    p = tmp_path / "plant.toml"
    p.write_text(text[:start] + motor + "\n" + text[end:])
    (tmp_path / "G80T.eng").write_text((ROCKET / "motors" / "G80T.eng").read_text())
    line = p.read_text().splitlines().index(next(x for x in motor.splitlines() if x.startswith("propellant_kg"))) + 1
    return p, line


@pytest.mark.parametrize("motor, message", [
    # a short, strong motor whose 0.15 kg of propellant is written in grams: light enough to leave the pad
    ("[motor]\nthrust_curve = [[0, 0], [0.02, 2000], [0.15, 2000], [0.17, 0]]\npropellant_kg = 150\n",
     "[motor] propellant_kg: 300 N·s from 150 kg of propellant is a specific impulse of 0.204 s"),
    ('[motor]\nfile = "G80T.eng"\npropellant_kg = 62.5\n',
     "[motor] propellant_kg: 118.6 N·s from 62.5 kg of propellant is a specific impulse of 0.193 s"),
])
def test_a_plant_files_propellant_in_grams_is_located(tmp_path: Path, motor, message):
    p, line = _plant(tmp_path, motor)
    with pytest.raises(SetupError) as e:
        prepare(str(ROCKET), "rocket", params=str(p), seed=1)
    assert f"{p}:{line}: {message}" in str(e.value), str(e.value)
    assert ": a mass in grams" in str(e.value)


def test_the_command_says_so_before_building(tmp_path: Path):
    p, line = _plant(tmp_path, "[motor]\nthrust_curve = [[0, 0], [0.02, 2000], [0.15, 2000], [0.17, 0]]\n"
                               "propellant_kg = 150\n")
    r = run_fsw("sim", str(ROCKET), "--plant", "rocket", "--params", str(p), "--out", str(tmp_path / "out"))
    assert r.code == 2, r.err
    assert f"{p}:{line}: [motor] propellant_kg:" in r.err and "specific impulse" in r.err
    assert "Traceback" not in r.err and not (tmp_path / "out" / "flight.csv").exists()


def test_no_propellant_is_still_a_motor_of_constant_mass(tmp_path: Path):
    p, _ = _plant(tmp_path, "[motor]\nthrust_curve = [[0, 0], [0.1, 100], [1.3, 70], [1.6, 0]]\npropellant_kg = 0\n")
    assert prepare(str(ROCKET), "rocket", params=str(p), seed=1)[2].propellant_kg == 0.0
