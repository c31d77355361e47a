"""Tape replays into digital sensor parts: a tape column feeds a part of
the project's `.sns` tables (tape.toml `[tape] pressure_pa =
"bmp280@0x76"`, or plant.toml's `[barometer] part` by default, through its
`extends`): the tape's Pa and g become the part's raw counts by the
datasheet's inverse with the part's calibration; held values keep their
lowest bit moving so that the driver's stuck check is not set off; the
firmware reads the tape's pressure."""

from __future__ import annotations

import csv
import os
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import EXAMPLES, run_fsw
from fswkit.plant.tape_replay import PART_DITHER_S, ReplayError, _part_changes, load_config
from fswkit.sim import parts as P
from fswkit.sim.sensors import PartFeed

DIGITAL = EXAMPLES / "hpr_digital"
pytestmark = pytest.mark.skipif(not (DIGITAL / "hpr_digital.sns").exists(),
                                reason="examples/hpr_digital (the digital-sensor example) is not there")
needs_sim = pytest.mark.skipif(shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                               reason="gcc-avr and libsimavr-dev are needed (make setup)")


def _app():
    from fswkit.plant.run import prepare

    app, layout, _sc = prepare(str(DIGITAL), "rocket")
    return app, layout


def test_plant_toml_parts_are_the_replays_defaults():
    app, layout = _app()
    cfg = load_config(app, layout, None)
    assert set(cfg.parts) == {"pressure_pa", "accel_g"} and cfg.sensors == {}
    assert (cfg.parts["pressure_pa"].sensor.part, cfg.parts["pressure_pa"].quantity) == ("bmp280", "pressure")
    assert (cfg.parts["accel_g"].sensor.part, cfg.parts["accel_g"].quantity, cfg.parts["accel_g"].sign) == \
        ("adxl345", "z", 1.0)
    assert cfg.accel_element == "accel"
    assert [s.part for s in cfg.app_sensors] == ["bmp280", "adxl345"]
    assert cfg.arm_pin == 2 and cfg.drogue_pin == 5  # examples/hpr/plant.toml's, through `extends`


@pytest.mark.parametrize("text, message", [
    ('[tape]\npressure_pa = "bmp280@0x77"\n',
     '2: [tape] pressure_pa: "bmp280@0x77" is not in the project\'s sensor tables'),
    ('[tape]\naccel_g = "bmp280@0x76"\n', '2: [tape] accel_g: "bmp280@0x76": a part of kind adxl345 or mpu6050'),
    ('[tape]\naccel_axis = "-q"\n', '2: [tape] accel_axis: "-q": one of x, y, z'),
])
def test_bad_parts_in_tape_toml_are_located(tmp_path, text, message):
    app, layout = _app()
    p = tmp_path / "tape.toml"
    p.write_text(text)
    with pytest.raises(ReplayError) as e:
        load_config(app, layout, str(p))
    assert f"{p}:{message}" in str(e.value), str(e.value)


class _Board:
    """What _part_changes asks of a SimBoard: its clock and the parts' calibration."""

    f_cpu = 16_000_000

    def part_calibration(self, where):
        return P.bmp280_calib_bytes(P.BMP280_EXAMPLE[0]) if where == 0x76 else b"\0\0\0"


def test_part_counts_per_row_and_the_dither_of_held_values(tmp_path):
    app, layout = _app()
    p = tmp_path / "tape.toml"
    p.write_text('[tape]\naccel_axis = "-z"\n')
    cfg = load_config(app, layout, str(p))
    f = 16_000_000
    pressure = np.array([85000.0, np.nan, 84000.0, 83000.0])
    accel = np.array([1.0, 2.0, np.nan, -0.5])
    cyc = [f * 2, f * 2 + f // 50, f * 2 + 2 * f // 50, f * 2 + 3 * f // 50]
    end = f * 4
    counts: dict = {}
    where = {s: (0x76 if s.part == "bmp280" else 0x53) for s in cfg.app_sensors}
    changes = _part_changes(_Board(), cfg, {"pressure_pa": pressure, "accel_g": accel}, cyc, end, where, counts)
    baro = PartFeed(cfg.parts["pressure_pa"].sensor, 0x76, _Board().part_calibration(0x76))
    want = [baro.raw(pressure=v, temperature=15.0 - 0.0065 * _isa_h(v))["adc_P"] for v in (85000, 85000, 84000, 83000)]
    assert counts["pressure_pa"].tolist() == want  # an empty cell holds the last value
    assert counts["accel_g"].tolist() == [-256, -512, -512, 128]  # axis -z: the negated g, 256 counts a g
    # replayed: from reset the first row's counts (lowest bit dithered), each later row at its cycle
    state: dict = {}
    seen = {0x76: [], 0x53: []}
    for c in sorted(changes):
        for w, raw in changes[c].items():
            state.setdefault(w, {}).update(raw)
        for w in seen:
            seen[w].append((c, dict(state.get(w, {}))))
    assert 0 in changes and set(changes[0]) == {0x76, 0x53}
    for c, raw in seen[0x76]:
        row = max([0] + [i for i, rc in enumerate(cyc) if rc <= c and i > 0])
        assert raw["adc_P"] in (want[row], want[row] ^ 1), (c, row)
    # a value held for 2 s (reset to the first row) is never 50 dither steps without a change
    held = [raw["adc_P"] for c, raw in seen[0x76] if c < cyc[1]]
    assert len(held) > 2.0 / PART_DITHER_S / 4 and len(set(held)) == 2
    grid = sorted(c for c in changes if c < cyc[1] and 0x76 in changes[c])
    assert max(np.diff(grid)) < 50 * f // 100  # a 100 Hz driver sees a change long before 50 reads


def _isa_h(pa: float) -> float:
    from fswkit.plant.atmosphere import altitude

    return altitude(pa)


@needs_sim
def test_the_firmware_reads_the_tapes_pressure_through_the_part(tmp_path):
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "sim"))
    import test_tape_replay as T

    tape = T._write_tape(tmp_path, "hop", end=12.0)
    (tmp_path / "tape.toml").write_text(T.CONFIG)
    out = tmp_path / "out"
    r = run_fsw("sim", str(DIGITAL), "--tape", str(tape), "--params", str(tmp_path / "tape.toml"), "--out", str(out))
    assert "Traceback" not in r.err, r.err
    text = (out / "summary.txt").read_text()
    assert "sensor pressure_pa → part bmp280@0x76 (pressure)" in text
    assert "sensor bmp280@0x76 (last health frame): ok" in text  # never stuck on the tape's held values
    assert "sensor adxl345@0x53 (last health frame): ok" in text
    assert "PASS  drogue pin within" in text
    with open(out / "flight.csv") as f:
        rows = [row for row in csv.DictReader(f) if row["tm_pressure"]]
    pad = [row for row in rows if float(row["time_s"]) < -0.3]
    assert pad
    for row in pad:  # the BMP280's compensation of the fed counts: within a count (0.16 Pa) and binary32
        assert float(row["tm_pressure"]) == pytest.approx(float(row["pressure_pa"]), abs=0.5)


def test_the_interpreter_replay_reads_the_parts_as_the_drivers_convert(tmp_path):
    """tape_interp (the machines in the reference interpreter) gives each
    part's elements the driver's reading of the counts fed: the tape's
    pressure within a count, the axis in 3.9 mg counts."""
    from fswkit.plant import tape_interp

    app, layout = _app()
    cfg = load_config(app, layout, None)
    cols = {"pressure_pa": np.array([85000.0, np.nan, 84123.4]), "accel_g": np.array([1.0, 2.5, np.nan])}
    got = tape_interp.part_inputs(cfg, cols)
    assert set(got) == {"pressure", "accel"}
    assert [round(x, 0) for x in got["pressure"]] == [85000.0, 85000.0, 84123.0]
    for x, want in zip(got["pressure"], (85000.0, 85000.0, 84123.4)):
        assert abs(x - want) < 0.2
    assert got["accel"] == [1.0, 2.5, 2.5]
