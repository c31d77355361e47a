"""The high-power example (examples/hpr; its configs and scripts are held
with the other flight examples' in test_flight_examples.py): the firmware
fits its budget; the navigation's polynomial for
the ISA altitude, read from nav.sm and run by the interpreter, is within
its stated error from 35 to 105 kPa; and plant.toml's sensors are hpr.aio's.
(A closed-loop flight takes about 35 s of wall time: `fsw sim examples/hpr
--plant rocket` is left to the reader and to the benchmarks.)"""

from __future__ import annotations

import re
import shutil
import tomllib

import pytest

from conftest import EXAMPLES
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.evaluate import local_values
from fswkit.autocode.numeric import F32MODE, F64MODE
from fswkit.autocode.project import load_machine
from fswkit.run.interp import OK, MachineRun

HPR = EXAMPLES / "hpr"


def isa(p: float) -> float:
    """The ISA troposphere's altitude, m, at pressure p, Pa (the tapes' formula)."""
    return 44330.77 * (1 - (p / 101325.0) ** 0.190263)


@pytest.mark.skipif(shutil.which("avr-g++") is None, reason="needs avr-g++ (make setup)")
def test_firmware_fits_its_budget(fsw, tmp_path):
    r = fsw("build", str(HPR), "--out", str(tmp_path))
    assert r.code == 0, r.out + r.err
    app = (HPR / "hpr.app").read_text()
    flash_budget = int(re.search(r"^flash\s+(\d+)", app, re.M).group(1))
    ram_budget = int(re.search(r"^ram\s+(\d+)", app, re.M).group(1))
    flash = int(re.search(r"flash\s+([\d,]+) /", r.out).group(1).replace(",", ""))
    ram = int(re.search(r"RAM\s+([\d,]+) /", r.out).group(1).replace(",", ""))
    assert flash <= flash_budget and (tmp_path / "hpr.elf").exists()
    # data + bss, with room left for the stack (about 220 B measured in closed-loop flights)
    assert ram + 256 <= ram_budget, r.out


def nav_machine():
    diags = Diagnostics()
    m = load_machine(str(HPR / "nav.sm"), diags)
    assert m is not None, diags.render()
    return m


def test_isa_polynomial_constants_are_within_3_cm():
    """The coefficients as nav.sm declares them, evaluated by Horner's rule
    in binary64, against the ISA formula every 1 Pa."""
    m = nav_machine()
    vals = {m.vars[i].name: v for i, v in local_values(m, F64MODE).items()}
    c = [vals[f"C{k}"] for k in range(8)]
    worst = 0.0
    for p in range(35000, 105001):
        u = (p - vals["PC"]) / vals["PS"]
        h = 0.0
        for ck in reversed(c):
            h = h * u + ck
        worst = max(worst, abs(h - isa(p)))
    assert worst < 0.035, worst


@pytest.mark.parametrize("real", [F64MODE, F32MODE], ids=["f64", "f32"])
def test_navigation_altitude_matches_the_isa_from_35_to_105_kpa(real):
    """The interpreter runs nav.sm: the pad at 101325 Pa (ISA 0 m), then
    launched (phase 1, the pad pressure frozen), one pressure per step from
    105 kPa down to 35 kPa; each step's measured altitude above the pad is
    the ISA altitude within 7 cm (two fit errors; binary32 rounding adds
    about 1 mm at 8 km)."""
    m = nav_machine()
    run = MachineRun(m, real)
    idx = {v.name: v.index for v in m.vars}
    g = 0

    def step(p: float, phase: int) -> None:
        nonlocal g
        run.v[idx["time"]] = g
        run.v[idx["pressure"]] = real.read(m.vars[idx["pressure"]].type, p)
        run.v[idx["accel"]] = 1.0
        run.v[idx["phase"]] = phase
        assert run.step() == OK
        g += 10

    for _ in range(30):
        step(101325.0, 0)
    assert run.v[idx["padPressure"]] == 101325.0
    worst = 0.0
    for p in range(105000, 34999, -50):
        step(float(p), 1)
        worst = max(worst, abs(run.v[idx["baroAlt"]] - isa(p)))
    assert worst < 0.07, worst


def test_plant_sensors_are_the_io_tables():
    """plant.toml's barometer and accelerometer are hpr.aio's A0 and A1,
    with the same transfer functions; its pins are hpr.dio's (a tape replay
    finds the channels and pyro pins there)."""
    plant = tomllib.loads((HPR / "plant.toml").read_text())
    aio = {}
    for line in (HPR / "hpr.aio").read_text().splitlines():
        f = line.split("#")[0].split()
        if len(f) >= 3 and f[0] == "i":
            cal = dict(kv.split("=") for kv in f[3:])
            aio[f[1]] = (f[2], float(cal["scale"]), float(cal["offset"]))
    baro, acc = plant["barometer"], plant["accelerometer"]
    assert aio[baro["channel"]][0] == "pressure"
    assert aio[baro["channel"]][1:] == (baro["pa_per_volt"], baro["pa_at_0v"])
    name, scale, offset = aio[acc["channel"]]
    assert name == "accel"
    assert scale == pytest.approx(1 / acc["volts_per_g"], rel=1e-4)
    assert offset == pytest.approx(-acc["zero_g_volts"] / acc["volts_per_g"], rel=1e-4)
    dio = {}
    for line in (HPR / "hpr.dio").read_text().splitlines():
        f = line.split("#")[0].split()
        if len(f) == 3:
            dio[f[2]] = int(f[1])
    assert plant["pins"] == {"arm": dio["armSwitch"], "drogue": dio["drogue"], "main": dio["main"]}
    assert plant["atmosphere"]["pad_altitude_m"] == 1400
