"""Tape replays drive each igniter's continuity input (docs/sim.md,
"Replaying real flights": `[igniters]`): plant.toml's `[drogue]`/`[main]`
`continuity_channel`, `intact_volts` and `open_volts` by default, tape.toml's
`[igniters]` over them, each channel checked and located; the input reads
`intact_volts` the whole replay (open loop), the interpreter's element the
board's quantised reading; a `[pyro]` continuity input no igniter drives is
a note; and the rocket example, which arms only on intact igniters, arms
and flies a synthetic tape on the board and in the interpreter."""

from __future__ import annotations

import csv
import shutil

import pytest

from conftest import EXAMPLES, run_fsw
from test_tape_replay import CONFIG, ROCKET, _write_tape, needs_sim


def _load(project, params=None):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.link.layout import from_app
    from fswkit.plant import tape_replay as tr
    from fswkit.target.build import load

    app = load(str(project), Diagnostics(), None)
    layout = from_app(app)
    return app, layout, tr.load_config(app, layout, None if params is None else str(params))


def _config(tmp_path, text, name="tape.toml"):
    path = tmp_path / name
    path.write_text(CONFIG + text)
    return path


def _rocket_copy(tmp_path, edit):
    """examples/rocket copied, its plant.toml edited: (project, plant.toml)."""
    dst = tmp_path / "rocket"
    shutil.copytree(ROCKET, dst, ignore=shutil.ignore_patterns("build"))
    plant = dst / "plant.toml"
    plant.write_text(edit(plant.read_text()))
    return dst, plant


def _line(path, text):
    return next(n for n, line in enumerate(path.read_text().splitlines(), 1) if text in line)


def test_igniters_default_from_plant_toml(tmp_path):
    app, _layout, cfg = _load(ROCKET, _config(tmp_path, ""))
    assert {r: (ig.sensor.pin, ig.sensor.element, ig.volts, ig.open_volts) for r, ig in cfg.igniters.items()} == {
        "drogue": ("A2", "drogueSense", 2.5, 0.0), "main": ("A3", "mainSense", 2.5, 0.0)}
    assert cfg.notes == []  # every [pyro] continuity input is driven
    ig = cfg.igniters["drogue"]
    assert ig.counts == 512  # floor(2.5 * 1024 / 5), as the sensors are counted
    assert ig.millivolts * 1023 // 5000 == 512 and (ig.millivolts - 1) * 1023 // 5000 == 511
    assert ig.reading() >= float(app.pyro[0].continuity_min)
    # each chute's own volts, from its table of plant.toml
    project, _plant = _rocket_copy(tmp_path, lambda t: t.replace(
        'continuity_channel = "A3"', 'continuity_channel = "A3"\nintact_volts = 3.0\nopen_volts = 0.4'))
    _app, _layout, cfg = _load(project, _config(tmp_path, ""))
    assert (cfg.igniters["drogue"].volts, cfg.igniters["drogue"].open_volts) == (2.5, 0.0)
    assert (cfg.igniters["main"].volts, cfg.igniters["main"].open_volts) == (3.0, 0.4)
    assert cfg.igniters["main"].counts == 614  # floor(3.0 * 1024 / 5)


def test_hpr_has_no_igniters():
    _app, _layout, cfg = _load(EXAMPLES / "hpr")
    assert cfg.igniters == {} and cfg.notes == []


def test_tape_toml_overrides_and_undriven_continuity_is_a_note(tmp_path):
    from fswkit.plant import tape_replay as tr

    cfg_path = _config(tmp_path, '[igniters]\ndrogue_channel = "none"\nmain_channel = "A2"\nintact_volts = 3.3\n'
                       'open_volts = 0.2\n')
    _app, _layout, cfg = _load(ROCKET, cfg_path)
    assert list(cfg.igniters) == ["main"]
    ig = cfg.igniters["main"]
    assert (ig.sensor.pin, ig.sensor.element, ig.volts, ig.open_volts) == ("A2", "drogueSense", 3.3, 0.2)
    # A3 (mainSense) is driven by nothing now: a note, in the summary and the perturbed runs' text
    assert len(cfg.notes) == 1
    note = cfg.notes[0]
    assert note.startswith("NOTE  continuity: pyro channel `main` reads its igniter on A3 (`mainSense`, min=1)")
    assert "may refuse to arm" in note
    tape = _write_tape(tmp_path, "notes", end=9.0)
    tp, _truth = tr.load_tape(str(tape), cfg)
    results = [tr.PerturbResult(0, {}, [], "x", list(cfg.notes)), tr.PerturbResult(1, {}, [], "y", list(cfg.notes))]
    text, _ok = tr.robustness_text(results, tp, 2, 1, 0.0)
    assert text.count(note) == 1
    # an intact reading below the channel's min= is a note too
    _app, _layout, cfg = _load(ROCKET, _config(tmp_path, "[igniters]\nintact_volts = 0.5\n", "low.toml"))
    assert len(cfg.notes) == 2 and all("below its min=1" in n for n in cfg.notes)
    # both "none": both continuity inputs undriven
    _app, _layout, cfg = _load(ROCKET, _config(
        tmp_path, '[igniters]\ndrogue_channel = "none"\nmain_channel = "none"\n', "none.toml"))
    assert cfg.igniters == {} and len(cfg.notes) == 2


def test_bad_igniter_channels_are_located(tmp_path):
    from fswkit.plant.tape_replay import ReplayError

    cfg_path = _config(tmp_path, '[igniters]\ndrogue_channel = "A0"\nmain_channel = 2\nintact_volts = 7\n')
    base = CONFIG.count("\n")
    with pytest.raises(ReplayError) as e:
        _load(ROCKET, cfg_path)
    errors = str(e.value).splitlines()
    assert f"{cfg_path}:{base + 2}: [igniters] drogue_channel: pin A0 is already driven by the tape's pressure_pa: " \
           "each sensor and igniter needs its own analog input" in errors
    assert any(m.startswith(f"{cfg_path}:{base + 3}: [igniters] main_channel: pin 2 is not an analog input of the "
                            "project (") and "armSwitch" in m for m in errors)
    assert f"{cfg_path}:{base + 4}: [igniters] intact_volts: 7 V is beyond the converter's 0..5 V" \
        in errors
    cfg_path = _config(tmp_path, '[igniters]\ndrogue_channel = "A3"\nmain_channel = "A3"\n', "twice.toml")
    with pytest.raises(ReplayError, match=rf"{cfg_path}:{base + 3}: \[igniters\] main_channel: pin A3 is already "
                       r"driven by \[igniters\] drogue_channel"):
        _load(ROCKET, cfg_path)
    # the command says so, exit status 2, before anything is built
    tape = _write_tape(tmp_path, "bad")
    cfg_path = _config(tmp_path, '[igniters]\nmain_channel = "A4"\n', "cli.toml")
    r = run_fsw("sim", str(ROCKET), "--tape", str(tape), "--params", str(cfg_path))
    assert r.code == 2, r.out + r.err
    assert f"fsw sim: {cfg_path}:{base + 2}: [igniters] main_channel: pin A4 is not an analog input of the project" \
        in r.err
    # a default from plant.toml is located in plant.toml
    project, plant = _rocket_copy(tmp_path, lambda t: t.replace('continuity_channel = "A2"',
                                                                'continuity_channel = "A1"').replace(
        'continuity_channel = "A3"', 'continuity_channel = "A3"\nintact_volts = "high"'))
    with pytest.raises(ReplayError) as e:
        _load(project, _config(tmp_path, "", "plain.toml"))
    errors = str(e.value).splitlines()
    at_a1, at_high = _line(plant, 'continuity_channel = "A1"'), _line(plant, 'intact_volts = "high"')
    assert f"{plant}:{at_a1}: [igniters] drogue_channel: pin A1 is already driven by the tape's accel_g: each " \
           "sensor and igniter needs its own analog input" in errors
    assert f'{plant}:{at_high}: [igniters] intact_volts: expected a number (volts), found a string "high"' in errors


def test_interpreter_reads_the_boards_quantised_value_and_perturbation_leaves_igniters(tmp_path):
    from fswkit.autocode.iotables import analog_gain, analog_value
    from fswkit.autocode.numeric import F32MODE
    from fswkit.plant import tape_interp as ti
    from fswkit.plant import tape_replay as tr
    from fswkit.sim.sensors import from_channel

    app, _layout, cfg = _load(ROCKET, _config(tmp_path, "[igniters]\nintact_volts = 2.2\n"))
    tape, _truth = tr.load_tape(str(_write_tape(tmp_path, "interp", end=9.0)), cfg)
    series, constant = ti.analog_inputs(cfg, tr._columns(tape))
    for role, element, pin in (("drogue", "drogueSense", "A2"), ("main", "mainSense", "A3")):
        ig = cfg.igniters[role]
        counts = int(2.2 * 1024 // 5)  # 450: the AVR converter's count of 2.2 V
        assert ig.counts == counts
        assert ig.millivolts * 1023 // 5000 == counts  # what simavr converts the board's millivolts to
        ch = next(c for c in app.channels if c.pin == pin)
        board = from_channel(ch, app.board)  # the firmware's multiply-add in the board's arithmetic
        assert constant[element] == board.reading(counts) == ig.reading()
        assert constant[element] == analog_value(counts, analog_gain(1.0, 5.0, 10, F32MODE),
                                                  F32MODE.literal("0.0"), F32MODE)
    # the barometer's values are computed the same way, count by count
    baro = cfg.sensors["pressure_pa"]
    counts = tr.counts_series(tape.pressure, baro, cfg.missing, cfg.silent_volts)
    assert series["pressure"] == [baro.reading(int(k)) for k in counts]
    # --perturb draws on the tape's columns only: the igniters read the same
    import numpy as np

    cols = tr.perturb(tr._columns(tape), tape.time, np.random.default_rng(7))
    series2, constant2 = ti.analog_inputs(cfg, cols)
    assert constant2 == constant and series2["pressure"] != series["pressure"]


def test_interpreter_arms_only_with_the_igniters_driven(tmp_path):
    from fswkit.plant import tape_interp as ti
    from fswkit.plant import tape_replay as tr

    app, _layout, cfg = _load(ROCKET, _config(tmp_path, ""))
    tape, truth = tr.load_tape(str(_write_tape(tmp_path, "fly")), cfg)
    rp = ti.replay(app, cfg, tape, truth=truth)
    names = [n for _t, _id, n in rp.run.transitions]
    assert names == ["Safe", "Armed", "Boost", "Coast", "Apogee", "Drogue", "Main", "Descent", "Landed"]
    _nums, checks, _notes = tr.evaluate(rp, cfg, truth, tape)
    assert all(c.passed for c in checks), checks
    _app, _layout, cfg = _load(ROCKET, _config(tmp_path, '[igniters]\nmain_channel = "none"\n', "open.toml"))
    rp = ti.replay(app, cfg, tape, truth=truth)
    assert [n for _t, _id, n in rp.run.transitions] == ["Safe"]  # mainSense reads 0: it never arms
    assert not rp.run.pin_events


@needs_sim
def test_rocket_arms_and_flies_a_synthetic_tape_on_the_board(tmp_path):
    from fswkit.plant import tape_interp as ti

    params = _config(tmp_path, "")
    tape = _write_tape(tmp_path, "board")
    out = tmp_path / "out"
    r = run_fsw("sim", str(ROCKET), "--tape", str(tape), "--params", str(params), "--out", str(out))
    assert r.code == 0, r.out + r.err
    assert "igniter drogue → A2 (`drogueSense` = V × 1 + 0): intact, 2.5 V (count 512, read as 2.50244)" in r.out
    assert "igniter main → A3 (`mainSense` = V × 1 + 0): intact, 2.5 V" in r.out
    assert "NOTE  continuity" not in r.out
    transitions = r.out.split("transitions (telemetry):")[1].split("link:")[0].split()
    states = ["Safe", "Armed", "Boost", "Coast", "Apogee", "Drogue", "Main", "Descent", "Landed"]
    assert [w for w in transitions if w in states] == states
    from fswkit.plant import tape_replay as tr

    _app, _layout, cfg = _load(ROCKET, params)
    tp, _truth = tr.load_tape(str(tape), cfg)
    _series, constant = ti.analog_inputs(cfg, tr._columns(tp))
    with open(out / "flight.csv") as f:
        rows = list(csv.DictReader(f))
    # the board's reading, telemetered (6 digits in the CSV), is the interpreter's value, the whole replay
    for element in ("drogueSense", "mainSense"):
        seen = {float(row[f"tm_{element}"]) for row in rows if row[f"tm_{element}"]}
        assert len(seen) == 1 and seen.pop() == pytest.approx(constant[element], abs=5e-6)
