"""A plant file's (plant.toml's, tape.toml's) independent errors are all
reported in one run.

What was wrong: the file was checked in two passes. A value of the wrong
type or out of range stopped the run before the names and pins were
checked against the project, so a file with a type error and an unknown
element name showed only the first; the user fixed it, ran again, and
only then met the second.

What is true now: one run reports both, each at its line (in the file that
gave the key, through `extends`), exit status 2. Only the checks that
depend on the bad value itself are skipped: a `reset_state` of the wrong
type is not also "absent" (no "needs reset_state" for its reset_after_s),
a barometer `channel` of the wrong type does not also make the barometer
"missing", a `max_s` out of range is not compared with the motor's burn.

A study (`--runs`) was the same across its two files: an error in
plant.toml hid every error of the dispersion file, and a value the
dispersion file's schema refused hid its other keys' checks against the
flight (a brown-out window past its end). They too come in one run."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import EXAMPLES, run_fsw

ROCKET_TOML = (EXAMPLES / "rocket" / "plant.toml").read_text()
TANK_TOML = (EXAMPLES / "tank" / "plant.toml").read_text()


def _variant(tmp_path: Path, base: str, *edits: tuple[str, str], name: str = "plant.toml") -> Path:
    text = base
    for old, new in edits:
        assert old in text, old
        text = text.replace(old, new, 1)
    p = tmp_path / name
    p.write_text(text)
    return p


def _line(path: Path, text: str) -> int:
    return next(i for i, ln in enumerate(path.read_text().splitlines(), 1) if text in ln)


def _sim(project: str, plant: str, params: Path):
    r = run_fsw("sim", str(EXAMPLES / project), "--plant", plant, "--params", str(params),
                "--out", str(params.parent / "out"))
    assert "Traceback" not in r.err and "internal error" not in r.err, r.err
    return r


def test_a_type_error_and_an_unknown_element_in_one_run(tmp_path):
    p = _variant(tmp_path, ROCKET_TOML,
                 ("dry_mass_kg     = 1.25", 'dry_mass_kg     = "heavy"'),
                 ('altitude_element = "altitude"', 'altitude_element = "altitud"'))
    r = _sim("rocket", "rocket", p)
    assert r.code == 2
    assert f'{p}:{_line(p, "dry_mass_kg")}: [vehicle] dry_mass_kg: expected a number, found a string "heavy"' \
        in r.err
    assert f"{p}:{_line(p, 'altitude_element')}: [firmware] altitude_element: the project has no element " \
           "`altitud`" in r.err
    assert not (tmp_path / "out").exists()


def test_a_range_error_and_a_wrong_pin_in_one_run(tmp_path):
    p = _variant(tmp_path, ROCKET_TOML, ("drogue = 5", "drogue = 2"), ("max_s", "max_s = -1 #"))
    r = _sim("rocket", "rocket", p)
    assert r.code == 2
    assert f"{p}:{_line(p, 'max_s')}: [scenario] max_s: -1 is out of range" in r.err
    assert f"{p}:{_line(p, 'drogue = 2')}: [pins] drogue: pin 2 is not a digital output of the project" in r.err
    # the checks that need max_s are skipped, not run on a value it does not have
    assert "outlast the motor's burn" not in r.err


def test_a_bad_value_skips_only_the_checks_that_depend_on_it(tmp_path):
    p = _variant(tmp_path, ROCKET_TOML,
                 ("[scenario]\n", '[scenario]\nreset_state = 5\nreset_after_s = 0.5\n'),
                 ('main_altitude    = "MAIN_ALT"', 'main_altitude    = "MAIN_ALTITUDE"'))
    text = p.read_text()
    bar = text.index("[barometer]")
    ch = text.index("channel", bar)
    end = text.index("\n", ch)
    p.write_text(text[:ch] + "channel = 1.5" + text[end:])
    r = _sim("rocket", "rocket", p)
    assert r.code == 2
    assert f"{p}:{_line(p, 'reset_state = 5')}: [scenario] reset_state: expected a non-empty string" in r.err
    assert f"{p}:{_line(p, 'channel = 1.5')}: [barometer] channel: expected a pin" in r.err
    assert f"{p}:{_line(p, 'main_altitude')}: [firmware] main_altitude: machine `mission` has no local " \
           "`MAIN_ALTITUDE`" in r.err
    assert "needs reset_state" not in r.err
    assert "missing: channel" not in r.err
    assert len(r.err.strip().splitlines()) == 3, r.err


def test_the_tank_and_a_base_file_through_extends(tmp_path):
    p = _variant(tmp_path, TANK_TOML, ("gamma               = 1.4", "gamma               = 0.9"),
                 ('abort_limit      = "P_AbortThreshold"', 'abort_limit      = "counter2"'))
    r = _sim("tank", "tank", p)
    assert r.code == 2
    assert f"{p}:{_line(p, 'gamma')}: [tank] gamma: 0.9 is out of range (above 1)" in r.err
    assert f"{p}:{_line(p, 'abort_limit')}: [firmware] abort_limit: machine `tank` has no local `counter2`" in r.err
    # a type error in the base, an unknown state in the file that extends it
    base = _variant(tmp_path, ROCKET_TOML, ("dry_mass_kg     = 1.25", "dry_mass_kg     = true"), name="base.toml")
    child = tmp_path / "child.toml"
    child.write_text('extends = "base.toml"\n\n[firmware]\napogee_state = "Apogy"\n')
    r = _sim("rocket", "rocket", child)
    assert r.code == 2
    assert f"{base}:{_line(base, 'dry_mass_kg')}: [vehicle] dry_mass_kg: expected a number" in r.err
    assert f"{child}:4: [firmware] apogee_state: machine `mission` has no state `Apogy`" in r.err


def test_a_tape_config_type_error_and_an_unknown_local_in_one_run(tmp_path):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.link.layout import from_app
    from fswkit.plant import tape_replay as tr
    from fswkit.target.build import load

    app = load(str(EXAMPLES / "rocket"), Diagnostics(), None)
    cfg = tmp_path / "tape.toml"
    cfg.write_text('[tape]\nsilent_volts = "low"\nmissing = 3\n[firmware]\nmain_alt = "mission.NOPE"\n')
    with pytest.raises(tr.ReplayError) as e:
        tr.load_config(app, from_app(app), str(cfg))
    err = str(e.value)
    assert f'{cfg}:2: [tape] silent_volts: expected a number, found a string "low"' in err
    assert f"{cfg}:3: [tape] missing: expected a non-empty string" in err
    assert f"{cfg}:5: [firmware] main_alt: machine `mission` has no local `NOPE`" in err
    assert len(err.strip().splitlines()) == 3, err


# ---- a study: the plant file and the dispersion file ------------------------------------

def _study(tmp_path: Path, params: Path | None, disp: Path):
    args = ["sim", str(EXAMPLES / "rocket"), "--plant", "rocket", "--runs", "2", "--dispersion", str(disp),
            "--out", str(tmp_path / "study")]
    if params is not None:
        args += ["--params", str(params)]
    r = run_fsw(*args)
    assert "Traceback" not in r.err and "internal error" not in r.err, r.err
    assert not (tmp_path / "study").exists()
    return r


def test_a_studys_plant_file_and_dispersion_file_errors_in_one_run(tmp_path):
    p = _variant(tmp_path, ROCKET_TOML, ('altitude_element = "altitude"', 'altitude_element = "altitud"'))
    d = tmp_path / "d.toml"
    d.write_text("[motor]\nimpulse_sd = \"lots\"\n")
    r = _study(tmp_path, p, d)
    assert r.code == 2
    assert f"{p}:{_line(p, 'altitude_element')}: [firmware] altitude_element: the project has no element" in r.err
    assert f'{d}:2: [motor] impulse_sd: expected a number, found a string "lots"' in r.err


def test_a_dispersion_files_type_error_and_a_window_past_the_flight_in_one_run(tmp_path):
    d = tmp_path / "d.toml"
    d.write_text("[motor]\nimpulse_sd = 0.9\n\n[brownout]\nprobability = 0.5\nwindow_s = [88, 90]\n")
    r = _study(tmp_path, None, d)
    assert r.code == 2
    assert f"{d}:2: [motor] impulse_sd: 0.9 is out of range (0 to 0.2)" in r.err
    assert f"{d}:6: [brownout] window_s: [88, 90] starts after the end of the flight" in r.err
