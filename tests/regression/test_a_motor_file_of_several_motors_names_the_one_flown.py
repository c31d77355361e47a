"""A RASP file may hold several motors (a maker's catalogue, a club's
collection, several data sets of one motor), and plant.toml's `[motor]
file` flew the first of them without a word: naming `AeroTech.eng` for its
H128W flew whatever motor the file began with.

Now a file of more than one motor needs `[motor] name`, the designation of
the one to fly (an error at the `file` line lists the file's motors
otherwise); a name the file does not hold, or holds more than once, is an
error at the `name` line naming what the file holds. A file of one motor
flies it, as before, and a `name` given for it must be its name."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import EXAMPLES

from fswkit.plant.motor import load
from fswkit.plant.run import SetupError, prepare

ROCKET = EXAMPLES / "rocket"
MOTORS = ROCKET / "motors"
G80T, H128W = (MOTORS / "G80T.eng").read_text(), (MOTORS / "H128W.eng").read_text()


def _plant(tmp_path: Path, motor: str, eng: str) -> Path:
    text = (ROCKET / "plant.toml").read_text()
    start, end = text.index("[motor]"), text.index("[drogue]")
    p = tmp_path / "plant.toml"
    p.write_text(text[:start] + motor + "\n" + text[end:])
    (tmp_path / "AT.eng").write_text(eng)
    return p


def _line(p: Path, key: str) -> int:
    return next(i for i, x in enumerate(p.read_text().splitlines(), 1) if x.startswith(key + " "))


def _error(p: Path) -> str:
    with pytest.raises(SetupError) as e:
        prepare(str(ROCKET), "rocket", params=str(p), seed=1)
    return str(e.value)


def test_a_file_of_several_motors_needs_a_name(tmp_path: Path):
    p = _plant(tmp_path, '[motor]\nfile = "AT.eng"\n', G80T + H128W)
    h128w_line = (G80T + H128W).splitlines().index(next(x for x in H128W.splitlines() if x.startswith("H128W"))) + 1
    assert f"{p}:{_line(p, 'file')}: [motor] file: {tmp_path / 'AT.eng'} holds 2 motors (G80T at line 5, " \
           f"H128W at line {h128w_line}): name the one to fly, [motor] name = \"G80T\"" in _error(p)


def test_the_named_motor_is_flown(tmp_path: Path):
    p = _plant(tmp_path, '[motor]\nfile = "AT.eng"\nname = "H128W"\n', G80T + H128W)
    sc = prepare(str(ROCKET), "rocket", params=str(p), seed=1)[2]
    (h128w,) = load(str(MOTORS / "H128W.eng"))
    assert sc.nominal_impulse == pytest.approx(h128w.total_impulse) and sc.propellant_kg == h128w.propellant_kg


@pytest.mark.parametrize("eng, name, message", [
    (G80T + H128W, "K550", "AT.eng holds no motor named K550 (it holds G80T, H128W)"),
    (G80T, "H128W", "AT.eng holds no motor named H128W (it holds G80T)"),
    (G80T + G80T, "G80T", "AT.eng holds 2 motors named G80T (at lines 5 and 19): keep the one to fly"),
])
def test_a_name_the_file_does_not_hold_once_is_located(tmp_path: Path, eng, name, message):
    p = _plant(tmp_path, f'[motor]\nfile = "AT.eng"\nname = "{name}"\n', eng)
    assert f"{p}:{_line(p, 'name')}: [motor] name: {tmp_path / message}" in _error(p)


def test_a_name_without_a_file_is_located(tmp_path: Path):
    p = _plant(tmp_path, '[motor]\nthrust_curve = [[0, 0], [0.1, 100], [1.3, 70], [1.6, 0]]\n'
               'propellant_kg = 0.08\nname = "G80T"\n', G80T)
    assert f"{p}:{_line(p, 'name')}: [motor] name: names a motor of the motor file (`file`)" in _error(p)


def test_a_file_of_one_motor_flies_it_as_before(tmp_path: Path):
    p = _plant(tmp_path, '[motor]\nfile = "AT.eng"\n', G80T)
    assert prepare(str(ROCKET), "rocket", params=str(p), seed=1)[2].nominal_impulse == pytest.approx(118.56)


def test_a_curve_written_by_an_extending_file_drops_the_bases_name(tmp_path: Path):
    p = _plant(tmp_path, '[motor]\nfile = "AT.eng"\nname = "H128W"\n', G80T + H128W)
    v = tmp_path / "v.toml"
    v.write_text('extends = "plant.toml"\n\n[motor]\nthrust_curve = [[0, 0], [0.1, 100], [1.3, 70], [1.6, 0]]\n'
                 "propellant_kg = 0.08\n")
    sc = prepare(str(ROCKET), "rocket", params=str(v), seed=1)[2]
    assert sc.nominal_impulse == pytest.approx(0.1 * 50 + 1.2 * 85 + 0.3 * 35)
