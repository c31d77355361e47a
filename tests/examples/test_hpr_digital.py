"""examples/hpr_digital: examples/hpr with a BMP280 and an ADXL345 on I2C.
Its configs check clean with --strict and are examples/hpr's but for the
sensor table; its plant is examples/hpr's (`extends`) with the sensors
being the table's parts. Its flights: tests/safety/test_digital_sensor_faults.py."""

from __future__ import annotations

import os
import tomllib

from conftest import EXAMPLES

DIGITAL = EXAMPLES / "hpr_digital"


def test_configs_check_clean(fsw):
    r = fsw("check", "--strict", str(DIGITAL))
    assert r.code == 0, r.err
    assert "0 errors, 0 warnings" in r.err


def test_it_is_hpr_but_for_its_sensors():
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import load

    diags = Diagnostics()
    digital, hpr = load(str(DIGITAL), diags), load(str(EXAMPLES / "hpr"), diags)
    assert digital is not None and hpr is not None, diags.render()
    same = lambda a, b: os.path.realpath(a) == os.path.realpath(b)  # noqa: E731
    assert all(same(a.path, b.path) for a, b in zip(digital.machines, hpr.machines, strict=True))
    assert same(digital.sv.path, hpr.sv.path)
    assert [c.pin for c in digital.channels] == [c.pin for c in hpr.channels if not c.analog]
    assert [(s.part, s.address, [(q, e.name) for q, e in s.outputs], s.fault.name) for s in digital.sensors] == [
        ("bmp280", 0x76, [("pressure", "pressure")], "baroFault"),
        ("adxl345", 0x53, [("z", "accel")], "accelFault"),
    ]
    # the analog computer's inputs are the digital one's parts' elements
    assert {c.element.name for c in hpr.channels if c.analog} == {"pressure", "accel"}


def test_its_plant_is_hprs_with_the_parts():
    plant = tomllib.loads((DIGITAL / "plant.toml").read_text())
    assert plant["extends"] == "../hpr/plant.toml"
    assert plant["barometer"]["part"] == "bmp280@0x76"
    assert plant["accelerometer"]["part"] == "adxl345@0x53" and plant["accelerometer"]["axis"] == "z"
