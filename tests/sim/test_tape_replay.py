"""Tape replays (fsw sim PROJECT --tape FLIGHT.csv): the sensor model
exactly (inverse calibration, rails, the converter's counts, hold), then the
rocket example's real firmware on the simulated Uno driven by a synthetic
300 m flight written here (its sensors do not saturate): events and checks;
the FAIL path's exit status; located errors for bad inputs; and
`--perturb` deterministic for its seed."""

from __future__ import annotations

import math
import os
import shutil

import numpy as np
import pytest

from conftest import EXAMPLES, run_fsw
from fswkit.sim.sensors import AnalogSensor

ROCKET = EXAMPLES / "rocket"
needs_sim = pytest.mark.skipif(shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                               reason="gcc-avr and libsimavr-dev are needed (make setup)")

# ---- the sensor model ----------------------------------------------------------------------

BARO = AnalogSensor("A0", "pressure", 6250.0, 76875.0, 5.0, 10)  # rocket.aio: Pa = V * 6250 + 76875


def test_inverse_calibration_clips_and_counts_as_an_avr_adc():
    assert BARO.volts(76875 + 6250 * 2.5) == 2.5
    assert BARO.counts(2.5) == 512  # floor(2.5 * 1024 / 5)
    assert BARO.count_of(76875 + 6250 * 2.5) == 512
    assert BARO.counts(4.999) == 1023 and BARO.counts(5.0) == 1023  # clamped at 2^bits - 1
    assert BARO.volts(1e6) == 5.0 and BARO.count_of(1e6) == 1023  # the rail
    assert BARO.volts(0.0) == 0.0 and BARO.count_of(0.0) == 0
    assert BARO.counts(5.0 / 1024 - 1e-12) == 0 and BARO.counts(5.0 / 1024) == 1
    assert BARO.reading(512) == 512 * 5.0 / 1023 * 6250 + 76875
    assert BARO.range() == (76875.0, 108125.0)
    neg = AnalogSensor("A1", "x", -2.0, 10.0, 5.0, 10)  # a falling transfer function inverts too
    assert neg.volts(4.0) == 3.0 and neg.range() == (0.0, 10.0)
    with pytest.raises(ValueError, match="no inverse"):
        AnalogSensor("A2", "y", 0.0, 1.0, 5.0, 10)


def test_millivolts_give_exactly_the_count_on_the_simulated_converter():
    for counts in range(1024):
        mv = BARO.millivolts(counts)
        assert mv * 1023 // 5000 == counts  # simavr: floor(mV * 1023 / 5000)
        assert (mv - 1) * 1023 // 5000 < counts or counts == 0  # the smallest such input
    assert BARO.millivolts(0) == 0 and BARO.millivolts(1023) == 5000


def test_hold_and_silent_for_empty_cells():
    from fswkit.plant.tape_replay import counts_series, missing_spans

    p = np.array([math.nan, 90000.0, math.nan, math.nan, 95000.0, math.nan])
    c90, c95 = BARO.count_of(90000.0), BARO.count_of(95000.0)
    assert counts_series(p, BARO, "hold", 0.0).tolist() == [c90, c90, c90, c90, c95, c95]
    assert counts_series(p, BARO, "silent", 0.0).tolist() == [0, c90, 0, 0, c95, 0]
    assert counts_series(p, BARO, "silent", 5.0).tolist() == [1023, c90, 1023, 1023, c95, 1023]
    t = np.arange(6) * 0.5
    assert missing_spans(t, p) == [(0.0, 0.0, 1), (1.0, 1.5, 2), (2.5, 2.5, 1)]
    assert missing_spans(t, np.zeros(6)) == []


def test_perturbation_is_seeded_and_keeps_empty_cells_empty():
    from fswkit.plant.tape_replay import perturb

    t = np.arange(2000) * 0.01
    cols = {"pressure_pa": np.full(2000, 95000.0), "accel_g": np.full(2000, 1.0)}
    cols["accel_g"][100:200] = math.nan
    a = perturb(cols, t, np.random.default_rng(5))
    b = perturb(cols, t, np.random.default_rng(5))
    c = perturb(cols, t, np.random.default_rng(6))
    for k in cols:
        assert np.array_equal(a[k], b[k], equal_nan=True)
        assert not np.array_equal(a[k], c[k], equal_nan=True)
    assert np.isnan(a["accel_g"][100:200]).all()
    assert np.nanstd(a["pressure_pa"]) > 5  # noise and spikes are there


# ---- a synthetic flight --------------------------------------------------------------------

PAD_PA = 98945.0  # about 200 m above sea level
TOUCHDOWN = 18.0


def _flight(t: float) -> tuple[float, float]:
    """Altitude above the pad (m) and axial specific force (g) of a small
    rocket to about 300 m: 1.4 s of 55 m/s² boost, a 12 m/s² coast, free
    fall to a 40 m/s drogue descent, 20 m/s under the main below 150 m."""
    if t < 0:
        return 0.0, 1.0
    if t < 1.4:
        return 27.5 * t * t, (55 + 9.80665) / 9.80665
    v0, h0 = 77.0, 27.5 * 1.4 * 1.4
    tc = v0 / 12.0
    if t < 1.4 + tc:
        s = t - 1.4
        return h0 + v0 * s - 6 * s * s, -(12 - 9.80665) / 9.80665
    apogee = h0 + v0 * tc - 6 * tc * tc
    s = t - 1.4 - tc
    fall = 9.80665 * s * s / 2 if s < 40 / 9.80665 else 40 * 40 / (2 * 9.80665) + 40 * (s - 40 / 9.80665)
    h = apogee - fall
    if h > 150:
        return h, 0.0
    # under the main from 150 m at 20 m/s
    s150 = (apogee - 150 - 40 * 40 / (2 * 9.80665)) / 40 + 40 / 9.80665
    return max(0.0, 150 - 20 * (s - s150)), 1.0


APOGEE_S = 1.4 + 77.0 / 12.0
APOGEE_M = 27.5 * 1.96 + 77.0 * 77.0 / 24.0


def _write_tape(folder, name, end=27.0, truth_overrides=None, accel_gap=None):
    from fswkit.tape import isa_altitude, isa_pressure

    pad_h = float(isa_altitude(PAD_PA))
    lines = ["# fswkit sensor tape v1", "# source: synthetic (written by tests/sim/test_tape_replay.py)",
             "# flight: a synthetic 300 m flight", "# derived: pressure from the altitude through the ISA",
             "time_s,pressure_pa,accel_g"]
    landing = None
    for k in range(-50, int(end * 50) + 1):
        t = k / 50
        h, g = _flight(t)
        if landing is None and t > APOGEE_S and h == 0.0:
            landing = t
        acc = "" if accel_gap and accel_gap[0] <= t < accel_gap[1] else f"{g:.4f}"
        lines.append(f"{t:g},{float(isa_pressure(pad_h + h)):.1f},{acc}")
    path = folder / f"{name}.csv"
    path.write_text("\n".join(lines) + "\n")
    truth = {"name": f'"{name}"', "recorder": '"synthetic"', "liftoff_s": 0.0, "burnout_s": 1.4,
             "pad_pressure_pa": PAD_PA, "apogee_s": round(APOGEE_S, 3), "apogee_m_agl": round(APOGEE_M, 1),
             "recorder_apogee_event_s": round(APOGEE_S + 0.3, 3)}
    if landing is not None:
        truth["landing_s"] = landing
    truth.update(truth_overrides or {})
    (folder / f"{name}.truth.toml").write_text("".join(f"{k} = {v}\n" for k, v in truth.items() if v is not None))
    return path


CONFIG = """\
[tape]
pad_s = 1.5
arm_s = 0.5
run_on_s = 1.0
"""


@pytest.fixture(scope="module")
def flights(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("tapes")
    (tmp / "tape.toml").write_text(CONFIG)
    return tmp


@needs_sim
def test_synthetic_flight_replayed_events_and_checks(flights):
    tape = _write_tape(flights, "hop", accel_gap=(5.0, 6.0))
    out = flights / "out-hop"
    r = run_fsw("sim", str(ROCKET), "--tape", str(tape), "--params", str(flights / "tape.toml"), "--out", str(out))
    assert r.code == 0, r.out + r.err
    for name in ("telemetry.log", "flight.csv", "flight.png", "summary.txt"):
        assert (out / name).exists()
    text = (out / "summary.txt").read_text()
    assert text == r.out
    assert "missing accel_g: 5–5.98 s (50 rows); held at the last value" in text
    for check in ("no pyro pin before liftoff or during boost", "drogue pin within -0.5/+1 s",
                  "main pin within ±15 m of mission.MAIN_ALT = 150 m", "landing detected"):
        assert f"PASS  {check}" in text
    assert "events (tape time" in text and "recorder: synthetic" in text
    for event in ("launch", "burnout", "apogee", "main", "landing"):
        assert any(line.split()[:1] == [event] and "never" not in line for line in text.splitlines()), event
    import csv

    with open(out / "flight.csv") as f:
        rows = list(csv.DictReader(f))
    pad = next(r for r in rows if r["tm_pressure"] and float(r["time_s"]) < -0.5)
    # the firmware's pressure on the pad is that count's calibrated reading (the CSV keeps 6 digits)
    assert float(pad["tm_pressure"]) == pytest.approx(BARO.reading(int(pad["pressure_counts"])), abs=0.06)


@needs_sim
def test_fail_path_exit_status_and_log_ending_in_the_air(flights):
    tape = _write_tape(flights, "early", end=10.0, truth_overrides={"apogee_s": 5.0})  # a wrong truth: FAIL
    r = run_fsw("sim", str(ROCKET), "--tape", str(tape), "--params", str(flights / "tape.toml"),
                "--out", str(flights / "out-early"))
    assert r.code == 1, r.out + r.err
    assert "FAIL  drogue pin within -0.5/+1 s of the barometric apogee (5 s)" in r.out
    assert "SKIP  landing: the tape ends in the air" in r.out


def test_options_that_do_not_go_with_a_tape(tmp_path):
    tape = _write_tape(tmp_path, "opts")
    r = run_fsw("sim", str(ROCKET), "--perturb", "3")
    assert r.code == 2 and "--perturb needs --tape FLIGHT.csv" in r.err
    r = run_fsw("sim", str(ROCKET), "--tape", str(tape), "--plant", "rocket")
    assert r.code == 2 and "--plant does not go with --tape" in r.err
    r = run_fsw("sim", str(ROCKET), "--tape", str(tape), "--seed", "4")
    assert r.code == 2 and "--seed with --tape needs --perturb N" in r.err


def test_bad_inputs_are_located(flights, tmp_path):
    tape = _write_tape(tmp_path, "lonely")
    os.unlink(tmp_path / "lonely.truth.toml")
    r = run_fsw("sim", str(ROCKET), "--tape", str(tape), "--params", str(flights / "tape.toml"))
    assert r.code == 2 and f"{tape}: no truth file beside it" in r.err
    tape = _write_tape(tmp_path, "twocols")
    cfg = tmp_path / "nope.toml"
    cfg.write_text('[tape]\naccel_g = ""\n')  # no input for the tape's accelerometer column
    r = run_fsw("sim", str(ROCKET), "--tape", str(tape), "--params", str(cfg))
    assert r.code == 2 and f"fsw sim: {tape}:5: column `accel_g` has values but feeds no analog input" in r.err
    cfg.write_text('[tape]\npressure_pa = "A5"\n')
    r = run_fsw("sim", str(ROCKET), "--tape", str(tape), "--params", str(cfg))
    assert r.code == 2
    assert f"fsw sim: {cfg}:2: [tape] pressure_pa: pin A5 is not an analog input of the project" in r.err
    cfg.write_text('[tape]\nmissing = "zero"\n[firmware]\nmain_alt = "mission.NOPE"\n')
    r = run_fsw("sim", str(ROCKET), "--tape", str(tape), "--params", str(cfg))
    assert r.code == 2
    assert f'{cfg}:2: [tape] missing: "zero": one of "hold", "silent"' in r.err
    assert f"{cfg}:4: [firmware] main_alt: machine `mission` has no local `NOPE`" in r.err


@needs_sim
def test_perturbed_replays_are_deterministic_per_seed(flights, tmp_path):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.link.layout import from_app
    from fswkit.plant import tape_replay as tr
    from fswkit.target.build import load
    from support.simfw import kept_sim

    app = load(str(ROCKET), Diagnostics(), None)
    layout = from_app(app)
    cfg = tr.load_config(app, layout, str(flights / "tape.toml"))
    tape, truth = tr.load_tape(str(_write_tape(tmp_path, "short", end=9.0)), cfg)
    elf, board = kept_sim(ROCKET)  # built into build/sim-tests/, once for every test file
    a = tr.robustness(tape, truth, cfg, elf, board, layout, 2, seed=3, workers=2)
    b = tr.robustness(tape, truth, cfg, elf, board, layout, 1, seed=3)  # run i is the seed's i-th child: N aside
    strip = [{k: v for k, v in r.numbers.items() if k != "speed"} for r in a]
    assert strip[:1] == [{k: v for k, v in r.numbers.items() if k != "speed"} for r in b]
    assert [c.passed for c in a[0].checks] == [c.passed for c in b[0].checks]
    assert [c.detail for c in a[0].checks] == [c.detail for c in b[0].checks]
    assert strip[0] != strip[1]  # two runs, two perturbations
    text, _ok = tr.robustness_text(a, tape, 2, 3, 1.0)
    assert "event errors (min / median / max" in text and "drogue pin − apogee_s" in text
    assert "checks (share of runs meeting each):" in text
    assert tr.robustness_csv(a).splitlines()[0].startswith("run,launch_err_s,")
