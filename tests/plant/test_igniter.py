"""The rocket plant's igniters (scenario.Igniter): a pyro channel whose
[drogue]/[main] table names a `continuity_channel` drives that analog input
with `intact_volts` until the plant fires its charge (the pin high for
`fire_ms`), `open_volts` after; `--fault open-igniter` has the drogue's open
from boot and keeps the vehicle on the pad, where it must refuse to arm. A
plant.toml without continuity inputs flies exactly as before.

The inputs are checked on the scenario alone, stepped by hand; one short
closed-loop run of the fault (a copy of examples/rocket with continuity
inputs, 3 simulated seconds) checks its report."""

from __future__ import annotations

import os
import re
import shutil
from pathlib import Path

import pytest

from fswkit.plant.run import SetupError, execute, prepare
from fswkit.plant.scenario import RocketScenario
from rocket_continuity import continuity_project

BOTH = {"drogue": 'continuity_channel = "A2"', "main": 'continuity_channel = "A3"\nintact_volts = 4.0\nopen_volts = 0.5'}


@pytest.fixture(scope="module")
def project(tmp_path_factory) -> Path:
    return continuity_project(tmp_path_factory.mktemp("igniter") / "rocket", BOTH)


def _line(path: Path, pattern: str) -> int:
    return next(i for i, line in enumerate(path.read_text().splitlines(), 1) if re.match(pattern, line))


def _step(sc, t0: float, t1: float, edges=()):
    """One plant step as the co-simulation makes it: the inputs at t0, then the step."""
    analog, _ = sc.inputs(t0)
    sc.advance(t0, t1, list(edges))
    return analog


@pytest.fixture(scope="module")
def plain(tmp_path_factory) -> Path:
    """The example with no continuity keys in its plant.toml."""
    return continuity_project(tmp_path_factory.mktemp("plain") / "rocket")


def test_without_continuity_inputs_nothing_changes(plain):
    _app, _layout, sc = prepare(str(plain), "rocket", seed=3)
    assert sc.igniters == {}
    assert sc.columns == RocketScenario.columns and sc.columns[-2:] == ("baro_v", "accel_v")
    analog, digital = sc.inputs(0.0)
    assert set(analog) == {"A0", "A1"} and set(digital) == {2}
    assert len(sc.record()) == len(sc.columns)


def test_the_same_sensors_with_continuity_inputs(plain, project):
    _app, _layout, plain = prepare(str(plain), "rocket", seed=3)
    _app, _layout, sc = prepare(str(project), "rocket", seed=3)
    for k in range(200):
        a, _ = plain.inputs(k / 1000)
        b, _ = sc.inputs(k / 1000)
        assert {ch: b[ch] for ch in a} == a  # the igniters draw no noise of the sensors'


def test_intact_until_the_charge_fires_then_open(project):
    _app, _layout, sc = prepare(str(project), "rocket", seed=1)
    assert set(sc.igniters) == {"drogue", "main"}
    assert sc.columns == RocketScenario.columns + ("drogue_cont_v", "main_cont_v")
    drogue_pin, main_pin = sc.p["pins"]["drogue"], sc.p["pins"]["main"]
    fire_s = sc.p["drogue"]["fire_ms"] / 1000
    rate = 1000
    seen = []
    for k in range(1500):  # 1.5 s on the pad, the drogue's pin high from 1.0005 s to 1.2 s
        t0, t1 = k / rate, (k + 1) / rate
        edges = [(1.0005, drogue_pin, True)] if k == 1000 else [(1.2, drogue_pin, False)] if k == 1199 else []
        analog = _step(sc, t0, t1, edges)
        seen.append((t0, analog["A2"], analog["A3"]))
        row = dict(zip(sc.columns, sc.record()))
        assert (row["drogue_cont_v"], row["main_cont_v"]) == (analog["A2"], analog["A3"])
    fired = sc.pyros[drogue_pin].fired_at
    assert fired == pytest.approx(1.0005 + fire_s)
    assert all(a2 == 2.5 for t, a2, _ in seen if t < fired)  # the default intact_volts
    assert all(a2 == 0.0 for t, a2, _ in seen if t >= fired + 1 / rate)  # open_volts: the bridge wire is gone
    assert [a2 for t, a2, _ in seen if fired <= t < fired + 1 / rate] == [0.0]  # from the step after it fired
    assert {a3 for _, _, a3 in seen} == {4.0}  # the main's own intact_volts, its charge not fired
    assert sc.pyros[main_pin].fired_at is None


def test_a_pulse_shorter_than_fire_ms_leaves_the_igniter_intact(project):
    _app, _layout, sc = prepare(str(project), "rocket", seed=1)
    pin = sc.p["pins"]["main"]
    for k in range(100):
        edges = [(0.0101, pin, True)] if k == 10 else [(0.0201, pin, False)] if k == 20 else []
        _step(sc, k / 1000, (k + 1) / 1000, edges)
    assert sc.inputs(0.1)[0]["A3"] == 4.0 and sc.pyros[pin].fired_at is None


def test_open_igniter_fault(project):
    _app, _layout, sc = prepare(str(project), "rocket", seed=1, fault="open-igniter")
    analog, digital = sc.inputs(0.0)
    assert analog["A2"] == 0.0 and analog["A3"] == 4.0  # the drogue's open from boot, the main's intact
    assert sc.ignition_s is None and sc.max_s == sc.p["scenario"]["hold_s"]  # on the pad, never lit
    assert not digital[2] and sc.inputs(sc.p["scenario"]["arm_s"])[1][2]  # the arming key still turns
    for k in range(100):
        _step(sc, k / 1000, (k + 1) / 1000)
    assert sc.inputs(0.1)[0]["A2"] == 0.0 and sc.rocket.h == 0.0


def test_open_igniter_needs_the_drogues_continuity_input(plain):
    with pytest.raises(SetupError) as e:
        prepare(str(plain), "rocket", seed=1, fault="open-igniter")
    line = _line(plain / "plant.toml", r"\[drogue\]")
    assert str(e.value).startswith(f"{plain / 'plant.toml'}:{line}: [drogue] continuity_channel: missing: "
                                   "--fault open-igniter opens the drogue's igniter")


@pytest.mark.parametrize("keys, key, message", [
    ({"drogue": 'continuity_channel = "A0"'}, "continuity_channel",
     "[drogue] continuity_channel: pin A0 is already driven by [barometer] channel"),
    ({"drogue": 'continuity_channel = "A2"', "main": 'continuity_channel = "A2"'}, "continuity_channel",
     "[main] continuity_channel: pin A2 is already driven by [drogue] continuity_channel"),
    ({"drogue": 'continuity_channel = "A5"'}, "continuity_channel",
     "[drogue] continuity_channel: pin A5 is not an analog input of the project"),
    ({"drogue": 'continuity_channel = 5'}, "continuity_channel",
     "[drogue] continuity_channel: pin 5 is not an analog input of the project"),
    ({"main": "intact_volts = 3.0"}, "intact_volts",
     "[main] intact_volts: needs continuity_channel"),
    ({"drogue": 'continuity_channel = "A2"\nopen_volts = 6'}, "open_volts",
     "[drogue] open_volts: 6 is out of range (0 to 5)"),
])
def test_bad_continuity_keys_are_located(tmp_path, keys, key, message):
    proj = continuity_project(tmp_path / "rocket", keys)
    with pytest.raises(SetupError) as e:
        prepare(str(proj), "rocket", seed=1)
    table = message.split("]")[0][1:]
    text = (proj / "plant.toml").read_text().splitlines()
    start = next(i for i, line in enumerate(text) if line.startswith(f"[{table}]"))
    line = next(i for i, x in enumerate(text[start:], start + 1) if x.startswith(key))
    assert f"{proj / 'plant.toml'}:{line}: {message}" in str(e.value), str(e.value)


needs_board = pytest.mark.skipif(shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                 reason="gcc-avr and libsimavr-dev are needed (make setup)")


@needs_board
def test_open_igniter_closed_loop(project, tmp_path):
    """The fault flown for 3 s against the project's firmware: the checks
    are the pinned faults' with `refused to arm` for `was armed`. Whether
    the firmware does refuse is its own business (the example's firmware
    is getting its continuity checks): the check says what telemetry saw."""
    from fswkit.sim.command import build

    built = build(str(project), out=str(tmp_path / "build"))
    assert not isinstance(built, int), "the continuity copy of examples/rocket did not build"
    elf, board = built
    _app, layout, sc = prepare(str(project), "rocket", seed=1, fault="open-igniter")
    sc.max_s = 3.0
    fl = execute(sc, elf, board, layout, None, quiet=True)
    checks = {c.name: c for c in fl.report.checks}
    assert checks["no pyro channel fired"].passed
    assert checks["the vehicle stayed in its pad states (Safe, Armed)"].passed
    refused = checks["the vehicle refused to arm with the drogue's igniter open (never in state Armed)"]
    armed = [t for t, _, n in fl.run.transitions if n == "Armed"]
    assert refused.passed == (not armed)
    assert refused.detail == (f"armed at {armed[0]:.3f} s" if armed else "never armed")
    assert "the vehicle was armed (state Armed)" not in checks
    cols = fl.run.columns
    assert {r[cols.index("drogue_cont_v")] for r in fl.run.rows} == {0.0}
    assert {r[cols.index("main_cont_v")] for r in fl.run.rows} == {4.0}
