"""A motor file's propellant heavier than the whole motor is an error at
its header, but plant.toml's `propellant_kg`, which replaces the file's,
was taken whatever the motor weighed: 0.3 kg of propellant for a G80T of
0.125 kg flew (a specific impulse of 40 s passes as a motor's). Now a
`propellant_kg` heavier than the file's motor (its total mass) is an
error at its line, naming the motor's mass."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import EXAMPLES

from fswkit.plant.run import SetupError, prepare

ROCKET = EXAMPLES / "rocket"


def _plant(tmp_path: Path, prop: float) -> Path:
    text = (ROCKET / "plant.toml").read_text()
    start, end = text.index("[motor]"), text.index("[drogue]")
    p = tmp_path / "plant.toml"
    p.write_text(text[:start] + f'[motor]\nfile = "G80T.eng"\npropellant_kg = {prop}\n\n' + text[end:])
    (tmp_path / "G80T.eng").write_text((ROCKET / "motors" / "G80T.eng").read_text())
    return p


def test_heavier_than_the_motor(tmp_path: Path):
    p = _plant(tmp_path, 0.3)
    line = p.read_text().splitlines().index("propellant_kg = 0.3") + 1
    with pytest.raises(SetupError) as e:
        prepare(str(ROCKET), "rocket", params=str(p), seed=1)
    assert (f"{p}:{line}: [motor] propellant_kg: 0.3 kg of propellant weighs more than the whole motor G80T "
            f"({tmp_path / 'G80T.eng'}:5: 0.1252 kg)") in str(e.value), str(e.value)


def test_as_heavy_as_the_motor_may_be(tmp_path: Path):
    assert prepare(str(ROCKET), "rocket", params=str(_plant(tmp_path, 0.1)), seed=1)[2].propellant_kg == 0.1
