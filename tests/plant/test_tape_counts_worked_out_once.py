"""A tape's converter counts (tape_replay.counts_series) are worked out
once for each distinct value of a column, and the interpreter's replay
(tape_interp.replay) reads its Replay's counts from the same series its
inputs were converted from: both must be what the count of each row,
worked out row by row, gives, whatever the column holds (values repeated,
empty cells before, between and after them, zeros of either sign, the
rails)."""

from __future__ import annotations

import math

import numpy as np

from fswkit.sim.sensors import AnalogSensor

BARO = AnalogSensor("A0", "pressure", 6250.0, 76875.0, 5.0, 10)  # rocket.aio: Pa = V * 6250 + 76875
ZERO = AnalogSensor("A1", "accel", 10.0, 0.0, 5.0, 10)  # an offset of 0: -0.0 and 0.0 both read 0 V


def _row_by_row(values, sensor, missing, silent_volts) -> list[int]:
    silent = sensor.counts(silent_volts)
    have = [v for v in values if v == v]
    last = sensor.count_of(have[0]) if have and missing == "hold" else silent
    out = []
    for v in values:
        if v != v:
            out.append(last if missing == "hold" else silent)
        else:
            last = sensor.count_of(v)
            out.append(last)
    return out


def test_counts_series_is_the_row_by_row_count():
    from fswkit.plant.tape_replay import counts_series

    rng = np.random.default_rng(5)
    cases = [
        np.array([math.nan, 90000.0, 90000.0, math.nan, 95000.0, 90000.0, 1e9, -1e9, math.nan]),
        np.array([math.nan, math.nan]),
        np.array([], dtype=float),
        np.round(rng.normal(95000.0, 3000.0, 5000), 1),  # a few thousand values, most repeated
    ]
    for values in cases:
        for missing in ("hold", "silent"):
            for silent_volts in (0.0, 5.0):
                got = counts_series(values, BARO, missing, silent_volts)
                assert got.dtype == np.int64 and got.shape == values.shape
                assert got.tolist() == _row_by_row(values.tolist(), BARO, missing, silent_volts)
    signed = np.array([0.0, -0.0, 0.0, -0.0, -1.0, 1.0, 0.0])
    assert counts_series(signed, ZERO, "hold", 0.0).tolist() == _row_by_row(signed.tolist(), ZERO, "hold", 0.0)


def test_the_interpreters_replay_reports_the_counts_it_converted():
    from types import SimpleNamespace

    from fswkit.plant import tape_interp as ti
    from fswkit.plant.tape_replay import counts_series

    cols = {"pressure_pa": np.array([math.nan, 90000.0, 90000.0, 95000.0, math.nan]),
            "accel_g": np.array([1.0, 1.0, 2.0, math.nan, 3.0])}
    cfg = SimpleNamespace(sensors={"pressure_pa": BARO, "accel_g": None}, missing="hold", silent_volts=0.0)
    series, constant, counts = ti._analog_inputs(cfg, cols)
    assert list(counts) == ["pressure_pa"] and constant == {}
    assert counts["pressure_pa"].tolist() == counts_series(cols["pressure_pa"], BARO, "hold", 0.0).tolist()
    assert (series, constant) == ti.analog_inputs(cfg, cols)
    assert series["pressure"] == [ti._reading(BARO, c) for c in counts["pressure_pa"].tolist()]
