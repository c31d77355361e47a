"""plant.toml with digital sensor parts and `extends`: `[barometer] part`
/ `[accelerometer] part` + `axis` instead of an analog channel (the parts
of the project's `.sns` tables), a variant's file starting from another's
(`extends`, key by key, the analog keys dropped where a part replaces
them), the digital parts' failures (`--fault baro-nack@T`, `[scenario]
part_fail`), and every mistake a located error."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import EXAMPLES
from fswkit.plant.params import ParamsError, load, resolve
from fswkit.plant.run import SetupError, prepare
from fswkit.plant.scenario import ROCKET_SCHEMA, parse_fault

HPR = EXAMPLES / "hpr"
DIGITAL = EXAMPLES / "hpr_digital"
BASE = HPR / "plant.toml"

pytestmark = pytest.mark.skipif(not (DIGITAL / "hpr_digital.sns").exists(),
                                reason="examples/hpr_digital (the digital-sensor example) is not there")


def write(tmp_path: Path, text: str, name: str = "plant.toml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def digital(tmp_path: Path, extra: str = "", baro: str = 'part = "bmp280@0x76"',
            accel: str = 'part = "adxl345@0x53"\naxis = "z"') -> Path:
    return write(tmp_path, f'extends = "{BASE}"\n{extra}\n[barometer]\n{baro}\nnoise_pa = 2.5\n\n'
                           f'[accelerometer]\n{accel}\nnoise_g = 0.01\n')


def errors_of(project: Path, params: Path, fault: str | None = None) -> str:
    with pytest.raises(SetupError) as e:
        prepare(str(project), "rocket", params=str(params), fault=fault)
    return str(e.value)


def line_of(path: Path, text: str) -> int:
    return next(i for i, ln in enumerate(path.read_text().splitlines(), 1) if text in ln)


# ---- extends ------------------------------------------------------------------------------

def test_the_digital_example_extends_the_analog_one():
    _app, _lay, sc = prepare(str(DIGITAL), "rocket")
    assert (sc.baro_part.part, sc.baro_part.address) == ("bmp280", 0x76)
    assert (sc.accel_part.part, sc.accel_part.address) == ("adxl345", 0x53)
    assert sc.accel_axis == ("z", 1.0)
    assert sc.channels == (None, None)  # the base's channel = "A0"/"A1" dropped for the parts
    assert sc.p["barometer"]["pa_per_volt"] is None and sc.p["barometer"]["noise_pa"] == 2.5
    _app, _lay, analog = prepare(str(HPR), "rocket")
    for table in ("vehicle", "motor", "pins", "firmware", "checks"):  # the rest is the base's
        assert sc.p[table] == analog.p[table], table
    assert sc.baro_element == "pressure" and sc.accel_element == "accel"  # the .sns rows' elements
    assert sc.columns[-2:] == ("baro_pa", "accel_g")


def test_extends_overrides_key_by_key_and_locates_each_key_in_its_file(tmp_path):
    base = write(tmp_path, BASE.read_text().replace("max_s      = 400", "max_s      = 300"), "base.toml")
    p = write(tmp_path, 'extends = "base.toml"\n\n[scenario]\nlinger_s = 2.5\n')
    values, where = resolve(str(p), ROCKET_SCHEMA)
    assert values["scenario"]["max_s"] == 300 and values["scenario"]["linger_s"] == 2.5
    assert values["scenario"]["arm_s"] == 1.0
    assert where[("scenario", "linger_s")] == 4 and not hasattr(where[("scenario", "linger_s")], "path")
    assert where[("scenario", "max_s")].path == str(base)
    assert where[("scenario", "max_s")] == line_of(base, "max_s      = 300")
    # an error in a key the file inherits is located in the base
    write(tmp_path, base.read_text().replace("dry_mass_kg", "dry_mass_kg = \"heavy\"\n#", 1), "base.toml")
    with pytest.raises(ParamsError) as e:
        load(str(p), ROCKET_SCHEMA)
    line = line_of(base, 'dry_mass_kg = "heavy"')
    assert f"{base}:{line}: [vehicle] dry_mass_kg: expected a number" in str(e.value)


def test_a_chain_of_extends(tmp_path):
    (tmp_path / "a").mkdir()
    write(tmp_path, f'extends = "{BASE}"\n[scenario]\nmax_s = 250\n', "a/mid.toml")
    p = write(tmp_path, 'extends = "a/mid.toml"\n[scenario]\nlinger_s = 3.0\n')
    values, where = resolve(str(p), ROCKET_SCHEMA)
    assert (values["scenario"]["max_s"], values["scenario"]["linger_s"]) == (250, 3.0)
    assert where[("scenario", "max_s")].path == str(tmp_path / "a" / "mid.toml")
    assert where[("vehicle", "dry_mass_kg")].path == str(BASE)


@pytest.mark.parametrize("text, message", [
    ('extends = "nowhere.toml"\n', "1: extends: no such file"),
    ("extends = 3\n", '1: extends: expected the path of another parameters file ("../hpr/plant.toml"), found a '
                      "number 3"),
    ('\nextends = "plant.toml"\n', "2: extends: "),
])
def test_bad_extends_are_located(tmp_path, text, message):
    p = write(tmp_path, text)
    with pytest.raises(ParamsError) as e:
        resolve(str(p), ROCKET_SCHEMA)
    assert f"{p}:{message}" in str(e.value)


def test_a_cycle_of_extends_is_an_error(tmp_path):
    write(tmp_path, 'extends = "b.toml"\n', "a.toml")
    write(tmp_path, 'extends = "a.toml"\n', "b.toml")
    with pytest.raises(ParamsError) as e:
        resolve(str(tmp_path / "a.toml"), ROCKET_SCHEMA)
    assert "(a cycle)" in str(e.value) and f"{tmp_path / 'b.toml'}:1: extends" in str(e.value)


# ---- parts ----------------------------------------------------------------------------------

def test_parts_by_kind_alone_and_a_negative_axis(tmp_path):
    p = digital(tmp_path, baro='part = "bmp280"', accel='part = "adxl345"\naxis = "-z"')
    _app, _lay, sc = prepare(str(DIGITAL), "rocket", params=str(p))
    assert sc.baro_part.part == "bmp280" and sc.accel_axis == ("z", -1.0)
    sc.inputs(0.0)
    vals = sc.part_values
    assert vals[sc.accel_part]["z"] == pytest.approx(-1.0, abs=0.05)  # on the pad: +1 g, axis pointing down
    pa = vals[sc.baro_part]["pressure"]
    assert pa == pytest.approx(85600, abs=50)  # 1400 m ISA
    assert vals[sc.baro_part]["temperature"] == pytest.approx(15.0 - 0.0065 * 1400)


@pytest.mark.parametrize("baro, accel, table, marker, message", [
    ('part = "bmp280@0x77"', None, "barometer", "bmp280@0x77",
     '[barometer] part: "bmp280@0x77" is not in the project\'s sensor tables (its parts: bmp280@0x76, adxl345@0x53)'),
    ('part = "ms5611"', None, "barometer", "ms5611", "[barometer] part: the project's sensor tables have no ms5611"),
    ('part = "adxl345@0x53"', None, "barometer", "adxl345@0x53",
     '[barometer] part: "adxl345@0x53": a part of kind bmp280 or ms5611'),
    ('part = "bmp280"\nchannel = "A0"', None, "barometer", 'part = "bmp280"',
     "[barometer] part: an analog `channel` or a digital `part`, not both"),
    ('part = "bmp280"\npa_per_volt = 100', None, "barometer", "pa_per_volt",
     "[barometer] pa_per_volt: belongs to an analog `channel`; this sensor is a digital `part`"),
    (None, 'part = "adxl345"\naxis = "w"', "accelerometer", 'axis = "w"',
     '[accelerometer] axis: "w": one of x, y, z'),
    (None, 'part = "mpu6050"', "accelerometer", "mpu6050",
     "[accelerometer] part: the project's sensor tables have no mpu6050"),
])
def test_part_mistakes_are_located(tmp_path, baro, accel, table, marker, message):
    kw = {}
    if baro is not None:
        kw["baro"] = baro
    if accel is not None:
        kw["accel"] = accel
    p = digital(tmp_path, **kw)
    err = errors_of(DIGITAL, p)
    assert f"{p}:{line_of(p, marker)}: {message}" in err, err


def test_a_table_with_neither_channel_nor_part(tmp_path):
    p = write(tmp_path, BASE.read_text().replace('channel     = "A0"\n', "").replace("pa_per_volt = 22222.22\n", "")
              .replace("pa_at_0v    = 10555.56\n", ""))
    err = errors_of(HPR, p)
    assert f"{p}:{line_of(p, '[barometer]   ')}: [barometer] : missing: channel (the analog input it drives, with " \
           "pa_per_volt and pa_at_0v) or part" in err, err


def test_an_analog_channel_needs_its_transfer_function(tmp_path):
    p = write(tmp_path, BASE.read_text().replace("volts_per_g  = 0.0627\n", ""))
    err = errors_of(HPR, p)
    assert "[accelerometer] volts_per_g: missing (with channel: its slope, V per g)" in err, err


# ---- failures -------------------------------------------------------------------------------

def test_parse_fault():
    assert parse_fault("stuck-baro") == ("stuck-baro", None)
    assert parse_fault("baro-nack@12.5") == ("baro-nack", 12.5)
    assert parse_fault("accel-stuck") == ("accel-stuck", None)
    for bad in ("stuck-baro@3", "baro-nack@soon", "baro-nack@-1", "loose-nut"):
        with pytest.raises(ValueError):
            parse_fault(bad)


def test_part_faults_make_a_plan(tmp_path):
    _app, _lay, sc = prepare(str(DIGITAL), "rocket", fault="baro-nack@12.5")
    assert [(t, part.part, mode) for t, part, mode in sc.part_fail_plan] == [(12.5, "bmp280", "nack")]
    _app, _lay, sc = prepare(str(DIGITAL), "rocket", fault="accel-stuck")
    assert [(t, part.part, mode) for t, part, mode in sc.part_fail_plan] == [(5.0, "adxl345", "stuck")]  # ignition
    _app, _lay, sc = prepare(str(DIGITAL), "rocket", fault="stuck-baro")  # the analog fault, on the part
    assert [(t, part.part, mode) for t, part, mode in sc.part_fail_plan] == [(5.0, "bmp280", "stuck")]
    p = digital(tmp_path, '[scenario]\npart_fail = "adxl345@0x53"\npart_fail_s = 7.25\npart_fail_mode = "stuck"\n')
    _app, _lay, sc = prepare(str(DIGITAL), "rocket", params=str(p))
    assert [(t, part.part, mode) for t, part, mode in sc.part_fail_plan] == [(7.25, "adxl345", "stuck")]
    assert sc.p["scenario"]["max_s"] == 400  # the base's, the rest of [scenario] kept


def test_a_noisy_part_reads_the_plants_extra_noise_and_nothing_else():
    """`baro-noisy`: the plant adds NOISY_PA of noise to what it feeds the
    barometer part (the part itself keeps working: nothing is asked of the
    board); the accelerometer and the rest of the draws are the nominal
    run's."""
    import numpy as np

    from fswkit.plant.scenario import NOISY_PA

    _app, _lay, sc = prepare(str(DIGITAL), "rocket", fault="baro-noisy@2")
    assert [(t, part.part, mode) for t, part, mode in sc.part_fail_plan] == [(2.0, "bmp280", "noisy")]
    _app, _lay, nominal = prepare(str(DIGITAL), "rocket")
    sc.noisy_parts.add(sc.baro_part)  # as the co-simulation does when the plan says so
    diff, accel = [], []
    for k in range(2000):  # on the pad: the plant does not move
        sc.inputs(k / 1000)
        nominal.inputs(k / 1000)
        diff.append(sc.part_values[sc.baro_part]["pressure"] - nominal.part_values[nominal.baro_part]["pressure"])
        accel.append(sc.part_values[sc.accel_part] == nominal.part_values[nominal.accel_part])
    assert 0.9 * NOISY_PA < float(np.std(diff)) < 1.1 * NOISY_PA
    assert all(accel)


@pytest.mark.parametrize("extra, marker, message", [
    ('[scenario]\npart_fail = "bmp280"\n', "[scenario]",  # a key not written: located at its table
     "[scenario] part_fail_s: missing: the simulated second the part fails at"),
    ('[scenario]\npart_fail = "bmp280"\npart_fail_s = 3\npart_fail_mode = "smoke"\n', "smoke",
     '[scenario] part_fail_mode: "smoke": one of "nack", "stuck", "noisy"'),
    ('[scenario]\npart_fail_s = 3\n', "part_fail_s", "[scenario] part_fail_s: needs part_fail"),
    ('[scenario]\npart_fail = "ms5611@0x77"\npart_fail_s = 3\n', "ms5611",
     '[scenario] part_fail: "ms5611@0x77" is not in the project\'s sensor tables (its parts: bmp280@0x76, '
     'adxl345@0x53)'),
])
def test_part_fail_mistakes_are_located(tmp_path, extra, marker, message):
    p = digital(tmp_path, extra)
    err = errors_of(DIGITAL, p)
    assert f"{p}:{line_of(p, marker)}: {message}" in err, err


def test_faults_of_the_other_kind_of_sensor_are_refused(tmp_path):
    err = errors_of(HPR, BASE, fault="baro-nack@10")
    assert "[barometer] channel: --fault baro-nack@10 fails a digital part; this barometer is analog" in err, err
    err = errors_of(DIGITAL, DIGITAL / "plant.toml", fault="pinned-baro")
    assert "[barometer] part: --fault pinned-baro pins an analog sensor's output at full scale" in err, err
    with pytest.raises(SetupError) as e:
        prepare(str(DIGITAL), "rocket", fault="baro-nack@later")
    assert "`@later` must be a simulated second" in str(e.value)


# ---- a short flight on the pad ----------------------------------------------------------------

needs_sim = pytest.mark.skipif(
    __import__("shutil").which("avr-gcc") is None
    or not __import__("os").path.exists("/usr/include/simavr/sim_avr.h"),
    reason="gcc-avr and libsimavr-dev are needed (make setup)")


@needs_sim
def test_the_firmware_reads_the_parts_the_plant_feeds_and_sees_one_fail(tmp_path):
    """examples/hpr_digital's firmware on the pad for 5 s: its telemetry's
    pressure and acceleration are the plant's (the BMP280's and ADXL345's
    counts through the drivers), then the barometer stops answering at 3 s
    and the health frames say so."""
    from fswkit.plant.cosim import fly
    from support.simfw import kept_sim

    elf, board = kept_sim(DIGITAL)  # built into build/sim-tests/, once for every test file
    p = digital(tmp_path, '[scenario]\npart_fail = "bmp280@0x76"\npart_fail_s = 3.0\n')
    _app, layout, sc = prepare(str(DIGITAL), "rocket", params=str(p))
    sc.max_s = 5.0  # on the pad: the motor lights at 5 s
    run = fly(sc, elf, board, layout)
    assert run.part_failures == [(3.0, "bmp280@0x76", "nack")]
    truth_pa = sc.rocket.static_pressure()
    before = [row for t, row in run.samples if 1.0 < t < 2.9 and "pressure" in row]
    assert len(before) > 20
    for row in before:
        assert abs(row["pressure"] - truth_pa) < 12.0  # noise_pa 2.5
        assert abs(row["accel"] - 1.0) < 0.06  # noise_g 0.01, one count 3.9 mg
    health = {s["name"]: s["words"] for s in run.session.health["sensors"]}
    assert health["adxl345@0x53"] == "ok"
    assert health["bmp280@0x76"] != "ok"
    after = [row for t, row in run.samples if t > 3.5 and "baroFault" in row]
    if after:  # when the fault flag is streamed
        assert all(row["baroFault"] for row in after)


def test_a_dispersion_draw_errs_a_parts_physical_values(tmp_path):
    """A study's sensor errors on a digital part: the bias and spikes in Pa
    and g on what the part is fed (the axis's sign kept), a dropout holding
    the part's last value."""
    from fswkit.plant.dispersion import Draw, SensorDraw, apply

    p = digital(tmp_path, accel='part = "adxl345"\naxis = "-z"').read_text()
    p = p.replace("noise_pa = 2.5", "noise_pa = 0").replace("noise_g = 0.01", "noise_g = 0")
    path = write(tmp_path, p)
    _app, _lay, sc = prepare(str(DIGITAL), "rocket", params=str(path))
    truth = sc.rocket.static_pressure()
    d = Draw(seed=1, index=0, noise_seed=1, baro=SensorDraw(bias=100.0, spikes=[(-4.0, -3.0, 500.0)]),
             accel=SensorDraw(bias=0.5, dropouts=[(-2.0, -1.0)]))
    apply(sc, d)  # errors at seconds from ignition (5 s)
    sc.inputs(0.5)
    assert sc.part_values[sc.baro_part]["pressure"] == pytest.approx(truth + 100.0)
    assert sc.part_values[sc.accel_part]["z"] == pytest.approx(-(1.0 + 0.5))
    sc.inputs(1.5)  # the baro's spike
    assert sc.part_values[sc.baro_part]["pressure"] == pytest.approx(truth + 600.0)
    sc.inputs(3.2)  # the accelerometer's dropout (3 to 4 s) holds the value fed as it started
    assert sc.part_values[sc.accel_part]["z"] == pytest.approx(-(1.0 + 0.5))
    sc.rocket.a = 2.0 * 9.80665
    sc.inputs(3.5)
    assert sc.part_values[sc.accel_part]["z"] == pytest.approx(-(1.0 + 0.5))
    sc.inputs(4.5)  # after the dropout: the true value again
    assert sc.part_values[sc.accel_part]["z"] == pytest.approx(-(3.0 + 0.5))
