"""Plant parameters are held to physically meaningful ranges, each refused
value a located error (`plant.toml:LINE: [table] key: ...`) before anything
is built; and should a plant's state still stop being a finite number
mid-flight, the run ends with a clear message and a non-zero exit, never an
OverflowError traceback or NaN volts sent to the board."""

from __future__ import annotations

import math
import re

import pytest
from conftest import EXAMPLES, run_fsw

import fswkit.plant.cosim as cosim
from fswkit.autocode.board import load_board
from fswkit.plant.cosim import CosimError, fly
from fswkit.plant.rocket import Chute, Motor, Rocket
from fswkit.plant.run import prepare
from fswkit.plant.tank import Tank
from fswkit.sim.board import Batch, RunResult, SimError, pin_map

ROCKET, TANK = EXAMPLES / "rocket", EXAMPLES / "tank"


def _variant(tmp_path, base, old_re, new):
    text = (base / "plant.toml").read_text()
    changed = re.sub(old_re, new, text, count=1, flags=re.M | re.S)
    assert changed != text, old_re
    p = tmp_path / "plant.toml"
    p.write_text(changed)
    line = changed[:changed.index(new)].count("\n") + 1
    return p, line


@pytest.mark.parametrize("base,plant,old,new,key", [
    (ROCKET, "rocket", r"^dry_mass_kg\s*=[^\n]*$", "dry_mass_kg = 1e-300", "[vehicle] dry_mass_kg"),
    (ROCKET, "rocket", r"^thrust_curve\s*=.*?^\]$", "thrust_curve = [[0, 0], [0.1, 1e300], [1.0, 0]]",
     "[motor] thrust_curve"),
    (ROCKET, "rocket", r"^thrust_curve\s*=.*?^\]$", "thrust_curve = [[0, 0], [0.1, 100], [1e9, 0]]",
     "[motor] thrust_curve"),
    (ROCKET, "rocket", r"^pa_per_volt\s*=[^\n]*$", "pa_per_volt = 1e-300", "[barometer] pa_per_volt"),
    (TANK, "tank", r"^volume_l\s*=[^\n]*$", "volume_l = 1e-300", "[tank] volume_l"),
    (TANK, "tank", r"^temperature_k\s*=[^\n]*$", "temperature_k = 1e-300", "[tank] temperature_k"),
])
def test_values_out_of_physical_range_are_located_errors(tmp_path, base, plant, old, new, key):
    p, line = _variant(tmp_path, base, old, new)
    r = run_fsw("sim", str(base), "--plant", plant, "--params", str(p), "--out", str(tmp_path / "out"))
    assert r.code == 2, r.err
    assert f"{p}:{line}: {key}:" in r.err and "out of range" in r.err, r.err
    assert "Traceback" not in r.err and "internal error" not in r.err


def test_the_rocket_integrator_fails_cleanly():
    motor = Motor([(0.0, 0.0), (0.1, 1e300), (1.0, 0.0)])
    r = Rocket(dry_mass=1e-300, propellant_mass=0.0, motor=motor, body_cd_area=0.01, drogue=Chute(0.1, 0.5),
               main=Chute(0.5, 0.5))
    r.ignite(0.0)
    with pytest.raises(ArithmeticError, match="overflowed"):
        for _ in range(10000):
            r.advance(0.001)
            assert math.isfinite(r.h) and math.isfinite(r.v)


def test_the_tank_integrator_fails_cleanly():
    t = Tank(volume=1e-300, temperature=1e-300, gas_constant=1.0, gamma=1.4, initial_pa=1e5, vent_cd_area=1e-6,
             valve_time=0.0)
    with pytest.raises(ArithmeticError, match="overflowed"):
        for _ in range(10000):
            t.advance(1.0, 1e307, False)


class _Board:
    """Stands for the simulated board: every step runs to its target, no
    pin edges, no UART bytes."""

    def __init__(self, elf, board, **kw):
        self.pins = pin_map(board)
        self.board = board

    def adc_channel(self, name):
        return self.pins.analog[name]

    def watch(self, pin):
        pass

    def batch(self, until, analog=None, digital=None, parts=None):
        return Batch(RunResult(until, 0.0, "running", "target"), [], b"")

    def symbol(self, name):
        raise SimError(f"unused.elf: no variable `{name}`")  # so steps go one at a time

    def close(self):
        pass


def test_a_state_that_overflows_in_flight_ends_the_run_cleanly(monkeypatch):
    _app, layout, sc = prepare(str(ROCKET), "rocket", seed=1)
    sc.rocket.dry_mass, sc.rocket.propellant_mass = 1e-300, 0.0  # past the schema, as a plant model could drift
    sc.motor.thrusts[:] = [t * 1e300 for t in sc.motor.thrusts]
    monkeypatch.setattr(cosim, "SimBoard", _Board)
    with pytest.raises(CosimError, match="no longer a finite number"):
        fly(sc, "unused.elf", load_board("uno"), layout)


@pytest.mark.parametrize("digits", [4301, 500000])
def test_an_integer_of_thousands_of_digits_is_a_located_error(tmp_path, digits):
    # Python's TOML reader refuses an integer of more than 4,300 digits
    # with a ValueError, not a TOML error: it was an internal error.
    p, line = _variant(tmp_path, TANK, r"^temperature_k\s*=[^\n]*$", "temperature_k = " + "9" * digits)
    r = run_fsw("sim", str(TANK), "--plant", "tank", "--params", str(p), "--out", str(tmp_path / "out"))
    assert r.code == 2, r.err
    assert f"{p}:{line}:17: an integer of {digits:,} digits" in r.err, r.err
    assert "Traceback" not in r.err and "internal error" not in r.err and len(r.err) < 500, r.err
