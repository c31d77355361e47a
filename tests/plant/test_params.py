"""Plant parameter files: the examples' files load, values come from the
compiled machine where the file names a local, and every bad file or option
is a located error (`plant.toml:LINE: ...`) with exit status 2 — before
anything is built — never a traceback."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from conftest import EXAMPLES, run_fsw
from fswkit.plant.params import Field, ParamsError, Table, load, locate
from fswkit.plant.run import SetupError, prepare
from support.configs import edit, example_copy

ROCKET_TOML = (EXAMPLES / "rocket" / "plant.toml").read_text()
TANK_TOML = (EXAMPLES / "tank" / "plant.toml").read_text()


def variant(tmp_path: Path, old: str, new: str, base: str = ROCKET_TOML, name: str = "plant.toml") -> Path:
    assert old in base, old
    p = tmp_path / name
    p.write_text(base.replace(old, new, 1))
    return p


def line_of(path: Path, text: str) -> int:
    lines = path.read_text().splitlines()
    return next(i for i, line in enumerate(lines, 1) if text in line)


def located(err: str, path: Path, line: int, message: str) -> bool:
    """Whether one line of `err` is `path:line: ...message...`."""
    return any(f"{path}:{line}: " in ln and message in ln for ln in err.splitlines())


def sim(*args: str):
    r = run_fsw("sim", *args)
    assert "Traceback" not in r.err and "internal error" not in r.err, r.err
    return r


def rocket_sim(params: Path, *extra: str):
    return sim(str(EXAMPLES / "rocket"), "--plant", "rocket", "--params", str(params),
               "--out", str(params.parent / "out"), *extra)


# ---- the examples ------------------------------------------------------------------------

def test_the_examples_load_and_read_the_machines_locals():
    _app, _lay, sc = prepare(str(EXAMPLES / "rocket"), "rocket", seed=3)
    assert sc.main_alt == 150.0  # mission.sm's MAIN_ALT, not a number in plant.toml
    assert sc.backup_s == pytest.approx(11.0)  # APOGEE_BACKUP = 11000 ms
    assert "150" not in ROCKET_TOML.split("[firmware]")[1].split("[checks]")[0]
    assert sc.rate == 1000 and sc.outputs == (5, 6) and sc.arm_pin == 2
    assert sc.accel_element == "accel" and sc.baro_element == "pressure"
    _app, _lay, tank = prepare(str(EXAMPLES / "tank"), "tank")
    assert tank.abort_psi == 825.0  # tank.sm: P_AbortThreshold = P_WarnThreshold + 25
    assert tank.vent_psi == 775.0


def test_a_changed_local_changes_the_check(tmp_path):
    proj = example_copy("rocket", tmp_path)
    edit(proj / "mission.sm", "F32 MAIN_ALT      = 150", "F32 MAIN_ALT      = 120")
    _app, _lay, sc = prepare(str(proj), "rocket")
    assert sc.main_alt == 120.0


# ---- located errors ----------------------------------------------------------------------

@pytest.mark.parametrize("old, new, marker, message", [
    ("dry_mass_kg     = 1.25", 'dry_mass_kg     = "heavy"', "dry_mass_kg",
     '[vehicle] dry_mass_kg: expected a number, found a string "heavy"'),
    ("noise_pa    = 12", "noise_pa    = -1", "noise_pa", "[barometer] noise_pa: -1 is out of range (0 to 100000)"),
    ("rate_hz = 1000", "rate_hz = 500", "rate_hz", "rate_hz: 500 is out of range (1000 to 100000)"),
    ("rate_hz = 1000", "rate_hz = true", "rate_hz", "rate_hz: expected a number, found a boolean true"),
    ("rate_hz = 1000", "rate_hz = 1000.5", "rate_hz", "rate_hz: expected a whole number, found 1000.5"),
    ("rate_hz = 1000", "rate_hz = 3000", "rate_hz", "rate_hz: 3000 Hz does not divide the uno's clock"),
    ("body_cd_area_m2 = 0.0011", "body_cd_area_m2 = 0.0011\ncolour = \"red\"", "colour",
     "[vehicle] unknown key `colour` (known: dry_mass_kg, body_cd_area_m2)"),
    ("[atmosphere]", "[wind]\nspeed = 3\n\n[atmosphere]", "[wind]", "unknown table [wind]"),
    ("    [1.30,  70.0],", "    [0.20,  70.0],", "thrust_curve", "[motor] thrust_curve: point 4: times must increase"),
    ("dry_mass_kg     = 1.25", "dry_mass_kg     = 20", "thrust_curve",
     "[motor] thrust_curve: the peak thrust (102.5 N) never exceeds the vehicle's weight (196.9 N)"),
    ('main_altitude    = "MAIN_ALT"', 'main_altitude    = "MAIN_ALTITUDE"', "main_altitude",
     "[firmware] main_altitude: machine `mission` has no local `MAIN_ALTITUDE`"),
    ('landed_state     = "Landed"', 'landed_state     = "Down"', "landed_state",
     "[firmware] landed_state: machine `mission` has no state `Down`"),
    ('sequence = ["Safe",', 'sequence = ["Safe", "Hover",', "sequence",
     "[checks] sequence: machine `mission` has no state `Hover`"),
    ('altitude_element = "altitude"', 'altitude_element = "padPressure"', "altitude_element",
     "`padPressure` is not in any telemetry stream"),
    ('state_element    = "state"', 'state_element    = "navState"', "state_element",
     "`navState` is not machine `mission`'s state"),
    ("drogue = 5", "drogue = 2", "drogue = 2", "[pins] drogue: pin 2 is not a digital output of the project"),
    ("main   = 6", "main   = 7", "main   = 7", "pin 7 is not a digital output of the project (its I/O tables"),
    ('channel      = "A1"', 'channel      = "A4"', 'channel      = "A4"', "[accelerometer] channel: pin A4 is not"),
])
def test_bad_values_are_located(tmp_path, old, new, marker, message):
    p = variant(tmp_path, old, new)
    r = rocket_sim(p)
    assert r.code == 2, r.err
    assert located(r.err, p, line_of(p, marker), message), r.err
    assert not (tmp_path / "out").exists()  # nothing was built or flown


def test_a_missing_key_is_located_at_its_table(tmp_path):
    p = variant(tmp_path, "ignition_s = 3.0                # the motor lights\n", "")
    r = rocket_sim(p)
    assert r.code == 2
    assert f"{p}:{line_of(p, '[scenario]')}: [scenario] ignition_s: missing (the motor is lit at this " in r.err


def test_toml_syntax_errors_give_line_and_column(tmp_path):
    p = variant(tmp_path, "dry_mass_kg     = 1.25", "dry_mass_kg     = 1.2.5")
    r = rocket_sim(p)
    assert r.code == 2
    assert f"{p}:{line_of(p, 'dry_mass_kg')}:22: Expected newline" in r.err


def test_every_error_of_a_file_is_reported(tmp_path):
    p = variant(tmp_path, "noise_g      = 0.05", "noise_g      = \"lots\"",
                base=ROCKET_TOML.replace("fire_ms    = 20 ", "fire_ms    = -20", 1))
    r = rocket_sim(p)
    assert r.code == 2
    assert f"{p}:{line_of(p, 'noise_g')}: [accelerometer] noise_g: expected a number" in r.err
    assert f"{p}:{line_of(p, 'fire_ms    = -20')}: [drogue] fire_ms: -20 is out of range" in r.err


def test_a_file_for_the_other_plant(tmp_path):
    p = tmp_path / "plant.toml"
    p.write_text(TANK_TOML)
    r = rocket_sim(p)
    assert r.code == 2
    # the schema refuses the tank's tables first; the kind is named on the `plant` line if the tables fit
    assert f"{p}:{line_of(p, '[tank]')}: unknown table [tank]" in r.err
    only_kind = tmp_path / "kind.toml"
    only_kind.write_text(ROCKET_TOML.replace('plant   = "rocket"', 'plant   = "tank"'))
    r = sim(str(EXAMPLES / "rocket"), "--plant", "rocket", "--params", str(only_kind))
    assert r.code == 2
    assert f"{only_kind}:{line_of(only_kind, 'plant   =')}: plant: this file describes a `tank` plant, not a " \
           "`rocket`" in r.err


def test_tank_values_are_checked_too(tmp_path):
    p = variant(tmp_path, "gamma               = 1.4", "gamma               = 0.9", base=TANK_TOML)
    r = sim(str(EXAMPLES / "tank"), "--plant", "tank", "--params", str(p))
    assert r.code == 2
    assert f"{p}:{line_of(p, 'gamma')}: [tank] gamma: 0.9 is out of range (above 1)" in r.err
    p = variant(tmp_path, 'abort_limit      = "P_AbortThreshold"', 'abort_limit      = "counter2"', base=TANK_TOML)
    r = sim(str(EXAMPLES / "tank"), "--plant", "tank", "--params", str(p))
    assert r.code == 2 and "machine `tank` has no local `counter2`" in r.err


def test_a_missing_params_file(tmp_path):
    r = rocket_sim(tmp_path / "nope.toml")
    assert r.code == 2
    assert f"{tmp_path / 'nope.toml'}: no such file" in r.err


# ---- options -------------------------------------------------------------------------------

@pytest.mark.parametrize("args, message", [
    (("examples/tank", "--plant", "tank", "--fault", "stuck-baro"), "--fault stuck-baro is a fault of the rocket"),
    (("examples/rocket", "--plant", "rocket", "--duration", "5"), "--duration is for the free-running board"),
    (("examples/rocket", "--plant", "rocket", "--analog", "A0=3"), "--analog is for the free-running board"),
    (("examples/rocket", "--seed", "3"), "--params, --seed and --fault need --plant rocket|tank"),
    (("examples/rocket", "--fault", "pinned-baro"), "--params, --seed and --fault need --plant"),
    (("examples/rocket", "--plant", "rocket", "--seed", "-1"), "expected a whole number >= 0"),
    (("examples/rocket", "--plant", "rocket", "--fault", "wet-baro"), "--fault wet-baro: one of stuck-baro"),
    (("examples/rocket", "--plant", "kite"), "invalid choice: 'kite'"),
    (("examples/rocket/build/uno/rocket.elf", "--plant", "rocket"), "--plant needs the project"),
])
def test_bad_options(args, message):
    r = sim(*[str(EXAMPLES.parent / a) if a.startswith("examples/") else a for a in args])
    assert r.code == 2
    assert message in r.err


# ---- the parameter reader itself -------------------------------------------------------------

def test_locate_finds_keys_in_their_tables_and_skips_multiline_values():
    text = 'a = 1\n[t]\nx = [\n  [1, 2],\n  [3, 4],\n]\ny = "[z]"  # [w]\n[u.v]\nk = 2\n'
    w = locate(text)
    assert w[("", "a")] == 1 and w[("t", "")] == 2 and w[("t", "x")] == 3 and w[("t", "y")] == 7
    assert w[("u.v", "")] == 8 and w[("u.v", "k")] == 9
    assert ("t", "[1, 2]") not in w and ("z", "") not in w


def test_load_fills_defaults_and_refuses_non_finite_numbers(tmp_path):
    schema = {"": Table("top", {"plant": Field("str", "p")}),
              "s": Table("s", {"a": Field("float", "a", lo=0, hi=10), "b": Field("int", "b", default=4)})}
    p = tmp_path / "x.toml"
    p.write_text('plant = "x"\n[s]\na = 2\n')
    values, _ = load(str(p), schema)
    assert values["s"] == {"a": 2.0, "b": 4}
    p.write_text('plant = "x"\n[s]\na = nan\n')
    with pytest.raises(ParamsError) as e:
        load(str(p), schema)
    assert e.value.errors == [f"{p}:3: [s] a: expected a finite number, found nan"]


def test_prepare_refuses_unknown_plants_and_faults():
    with pytest.raises(SetupError):
        prepare(str(EXAMPLES / "rocket"), "glider")
    with pytest.raises(SetupError):
        prepare(str(EXAMPLES / "rocket"), "rocket", fault="loose-nut")


def test_the_command_line_offers_every_fault_of_the_plant():
    from fswkit.plant.scenario import FAULTS, PART_FAULTS

    r = run_fsw("sim", "--help")
    assert r.code == 0, r.err
    text = re.sub(r"-\s+", "-", " ".join(r.out.split()))  # argparse wraps lines after a hyphen
    for fault in (*FAULTS, *PART_FAULTS):
        assert fault in text, fault
