"""RASP motor files (fswkit.plant.motor): the example's curves load with the
published figures they were shaped from, a plant.toml may fly one instead
of its written curve, and every kind of bad file is an error located at
file:line:col."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import EXAMPLES
from fswkit.plant.motor import EngError, load, parse
from fswkit.plant.run import SetupError, prepare

MOTORS = EXAMPLES / "rocket" / "motors"
ROCKET = EXAMPLES / "rocket"


@pytest.mark.parametrize("name, impulse, average, burn", [
    ("G80T", 120, 80, 1.5), ("H128W", 176, 128, 1.4), ("C6", 10, 5.4, 1.85)])
def test_example_curves_match_the_figures_they_were_shaped_from(name, impulse, average, burn):
    (m,) = load(str(MOTORS / f"{name}.eng"))
    assert m.name == name
    assert m.burn_time == burn
    assert m.total_impulse == pytest.approx(impulse, rel=0.03)
    assert m.total_impulse / m.burn_time == pytest.approx(average, rel=0.05)
    assert m.curve()[0] == (0.0, 0.0) and m.curve()[-1][1] == 0.0
    assert 0 < m.propellant_kg < m.total_kg


GOOD = """; a comment line
; another
X10 29 124 4-7 0.005 0.010 Maker   ; a trailing comment
  0.1 10.0
  0.5 12.0 ; mid-curve comment
  1.0 0.0
"""


def test_a_good_file_with_comments_and_two_motors():
    two = GOOD + "Y20 29 124 P 0.05 0.10 Other\n0 0\n0.5 40\n1 0\n"
    a, b = parse(two, "m.eng")
    assert (a.name, a.delays, a.maker, a.diameter_mm, a.length_mm) == ("X10", "4-7", "Maker", 29.0, 124.0)
    assert a.points == ((0.1, 10.0), (0.5, 12.0), (1.0, 0.0))
    assert a.curve()[0] == (0.0, 0.0)
    assert b.name == "Y20" and b.curve() == ((0.0, 0.0), (0.5, 40.0), (1.0, 0.0))


@pytest.mark.parametrize("text, line, col, message", [
    ("X10 29 124 4-7 0.05 0.10\n0.1 1\n1 0\n", 1, 25, "a motor's header has 7 fields"),
    ("X10 29 124 4-7 0.05 0.10 Big Maker\n0.1 1\n1 0\n", 1, 30, "this one has 8"),
    ("X10 29 long 4-7 0.05 0.10 M\n0.1 1\n1 0\n", 1, 8, "`long`: expected the motor's length in mm"),
    ("X10 29 124 4-7 0.5 0.10 M\n0.1 1\n1 0\n", 1, 16, "the propellant (0.5 kg) weighs more than the whole motor"),
    ("; only a curve\n0.1 1\n1 0\n", 2, 1, "a thrust point before any motor header"),
    ("X10 29 124 4-7 0.05 0.10 M\n0.1 1 2\n1 0\n", 2, 7, "a thrust point is two numbers"),
    ("X10 29 124 4-7 0.05 0.10 M\n0.1 lots\n1 0\n", 2, 5, "`lots`: expected the thrust in newtons"),
    ("X10 29 124 4-7 0.05 0.10 M\n-0.1 1\n1 0\n", 2, 1, "never negative"),
    ("X10 29 124 4-7 0.05 0.10 M\n0.1 -1\n1 0\n", 2, 5, "thrust is never negative"),
    ("X10 29 124 4-7 0.05 0.10 M\n0.5 1\n0.4 2\n1 0\n", 3, 1, "times must increase: 0.4 s after 0.5 s"),
    ("X10 29 124 4-7 0.05 0.10 M\n0.1 1\n1 3\n", 3, 3, "must end at zero thrust"),
    ("X10 29 124 4-7 0.05 0.10 M\n0.1 1\n1 0\n2 5\n", 4, 1, "a point after the curve ended at zero thrust"),
    ("X10 29 124 4-7 0.05 0.10 M\n; no points\n", 1, 1, "motor X10 has no thrust points"),
    ("; nothing but comments\n\n", 1, 1, "no motor in this file"),
    ("X10 29 124 4-7 0.05 0.10 M\n0.1 nan\n1 0\n", 2, 5, "expected the thrust in newtons"),
    # the limits of a plant file's thrust_curve hold for a motor file's too
    ("X10 29 124 4-7 0.05 0.10 M\n0.1 1e300\n1 0\n", 2, 5, "1e300 N: a thrust curve's points are at most 1e+06 N"),
    ("X10 29 124 4-7 0.05 0.10 M\n0.1 1e9\n0.2 0\n", 2, 5, "at most 1e+06 N"),
    ("X10 29 124 4-7 0.05 0.10 M\n0.1 1\n700 0\n", 3, 1, "700 s: a thrust curve lasts at most 600 s"),
    ("X10 29 124 4-7 2000 3000 M\n0.1 1\n1 0\n", 1, 16, "2000 kg: the motor's propellant mass is at most 1000 kg"),
    ("X10 29 124 4-7 0.05 0.10 M\n0.1 1_0\n1 0\n", 2, 5, "`1_0`: expected the thrust in newtons"),
])
def test_each_kind_of_bad_file_is_located(text, line, col, message):
    with pytest.raises(EngError) as e:
        parse(text, "bad.eng")
    first = e.value.errors[0]
    assert first.startswith(f"bad.eng:{line}:{col}: "), first
    assert message in first, first


def test_unreadable_files(tmp_path: Path):
    with pytest.raises(EngError, match="no such motor file"):
        load(str(tmp_path / "missing.eng"))
    binary = tmp_path / "b.eng"
    binary.write_bytes(b"X10 29\n\0\0\1")
    with pytest.raises(EngError, match=r"b.eng:2:1: a binary file"):
        load(str(binary))
    latin = tmp_path / "l.eng"
    latin.write_bytes("; Fabriqu\xe9\nX10 29 124 4-7 0.05 0.10 M\n0.1 100\n1 0\n".encode("latin-1"))
    assert load(str(latin))[0].name == "X10"


def _plant(tmp_path: Path, motor_table: str) -> Path:
    text = (ROCKET / "plant.toml").read_text()
    start = text.index("[motor]")
    end = text.index("[drogue]")
    p = tmp_path / "plant.toml"
    p.write_text(text[:start] + motor_table + "\n" + text[end:])
    (tmp_path / "motors").mkdir(exist_ok=True)
    for f in MOTORS.iterdir():
        (tmp_path / "motors" / f.name).write_text(f.read_text())
    (tmp_path / "motors" / "weak.eng").write_text("W1 18 70 0 0.01 0.02 M\n0.1 5\n1 0\n")
    return p


def test_plant_toml_flies_a_motor_file(tmp_path: Path):
    p = _plant(tmp_path, '[motor]\nfile = "motors/G80T.eng"\n')
    _app, _layout, sc = prepare(str(ROCKET), "rocket", params=str(p), seed=1)
    assert sc.nominal_impulse == pytest.approx(118.6, abs=0.1)
    assert sc.propellant_kg == 0.0625
    p = _plant(tmp_path, '[motor]\nfile = "motors/G80T.eng"\npropellant_kg = 0.07\n')
    assert prepare(str(ROCKET), "rocket", params=str(p), seed=1)[2].propellant_kg == 0.07


def test_default_flight_keeps_its_written_curve():
    _app, _layout, sc = prepare(str(ROCKET), "rocket", seed=1)
    assert sc.nominal_impulse == pytest.approx(122.6, abs=0.1)
    assert sc.propellant_kg == 0.08


@pytest.mark.parametrize("table, message", [
    ('[motor]\nfile = "motors/G80T.eng"\nthrust_curve = [[0, 0], [1, 100], [2, 0]]\n',
     "[motor] file: a motor file or a thrust_curve, not both"),
    ("[motor]\npropellant_kg = 0.08\n", "a thrust_curve, or a RASP motor file"),
    ("[motor]\nthrust_curve = [[0, 0], [1, 100], [2, 0]]\n", "propellant_kg: missing"),
    ('[motor]\nfile = "motors/none.eng"\n', "none.eng: no such motor file"),
    ('[motor]\nfile = "motors/weak.eng"\n', "[motor] file: the peak thrust (5 N) never exceeds the vehicle's weight"),
])
def test_bad_motor_tables(tmp_path: Path, table, message):
    p = _plant(tmp_path, table)
    with pytest.raises(SetupError) as e:
        prepare(str(ROCKET), "rocket", params=str(p), seed=1)
    assert message in str(e.value)
    assert str(p) in str(e.value) or "none.eng" in str(e.value)


def test_a_bad_motor_file_named_by_plant_toml_is_located_in_both(tmp_path: Path):
    p = _plant(tmp_path, '[motor]\nfile = "motors/bad.eng"\n')
    (tmp_path / "motors" / "bad.eng").write_text("X10 29 124 4-7 0.05 0.10 M\n0.1 1\n1 3\n")
    with pytest.raises(SetupError) as e:
        prepare(str(ROCKET), "rocket", params=str(p), seed=1)
    msg = str(e.value)
    assert f"{p}:" in msg and "[motor] file: the motor file" in msg
    assert "bad.eng:3:3: the thrust curve of X10 must end at zero thrust" in msg


def test_a_motor_file_inherited_through_extends_is_the_one_its_file_names(tmp_path: Path):
    """A `file` that a base plant file gives is relative to that file, not to
    the one extending it: a motors folder beside the extending file (here
    holding another motor under the same name) is not looked at."""
    base = _plant(tmp_path, '[motor]\nfile = "motors/G80T.eng"\n')
    sub = tmp_path / "sub"
    (sub / "motors").mkdir(parents=True)
    (sub / "motors" / "G80T.eng").write_text((MOTORS / "H128W.eng").read_text())  # the wrong motor, same name
    variant = sub / "variant.toml"
    variant.write_text(f'extends = "../{base.name}"\n\n[scenario]\nmax_s = 60\n')
    sc = prepare(str(ROCKET), "rocket", params=str(variant), seed=1)[2]
    assert sc.nominal_impulse == pytest.approx(118.6, abs=0.1)  # the G80T, not the H128W
    assert sc.propellant_kg == 0.0625


def test_a_motor_file_replaces_an_inherited_thrust_curve_and_its_propellant(tmp_path: Path):
    """The example's plant writes a thrust curve and its propellant mass; a
    file extending it that names a motor file flies that motor, with the
    file's propellant mass (the curve's is dropped with the curve), or with
    the one it writes itself."""
    (tmp_path / "motors").mkdir()
    (tmp_path / "motors" / "G80T.eng").write_text((MOTORS / "G80T.eng").read_text())
    variant = tmp_path / "variant.toml"
    variant.write_text(f'extends = "{ROCKET / "plant.toml"}"\n\n[motor]\nfile = "motors/G80T.eng"\n')
    sc = prepare(str(ROCKET), "rocket", params=str(variant), seed=1)[2]
    assert sc.nominal_impulse == pytest.approx(118.6, abs=0.1)
    assert sc.propellant_kg == 0.0625  # the file's, not the example's 0.08
    variant.write_text(f'extends = "{ROCKET / "plant.toml"}"\n\n[motor]\nfile = "motors/G80T.eng"\n'
                       "propellant_kg = 0.07\n")
    assert prepare(str(ROCKET), "rocket", params=str(variant), seed=1)[2].propellant_kg == 0.07
    # and the other way: a propellant mass alone keeps the base's motor file
    (tmp_path / "b").mkdir()
    _plant(tmp_path / "b", '[motor]\nfile = "motors/G80T.eng"\n')
    over = tmp_path / "b" / "over.toml"
    over.write_text('extends = "plant.toml"\n\n[motor]\npropellant_kg = 0.05\n')
    sc = prepare(str(ROCKET), "rocket", params=str(over), seed=1)[2]
    assert sc.nominal_impulse == pytest.approx(118.6, abs=0.1) and sc.propellant_kg == 0.05
