"""Digital sensor parts fed physical values (fswkit.sim.sensors.PartFeed)
through `batch` (`@ID:NAME=V,...` words; SimBoard.batch(parts=...)): the
raw counts a part holds are the datasheet's inverse (fswkit.sim.parts) of
the values fed, with the calibration the board holds for it; firmware reads
them (tests/sim/twi_probe/probe.c, a TWI and SPI master run by scripts over
the UART); a bad `@` word is refused before anything is applied."""

from __future__ import annotations

import os
import random
import shutil
from pathlib import Path

import pytest

from support.uartprobe import build_probe

from fswkit.autocode.model import Element, ElemType, Sensor
from fswkit.sim import parts as P
from fswkit.sim.board import SimBoard, SimError
from fswkit.sim.sensors import PartFeed, board_parts, find_part, part_name

HAVE_SIM = shutil.which("avr-gcc") is not None and os.path.exists("/usr/include/simavr/sim_avr.h")
needs_sim = pytest.mark.skipif(not HAVE_SIM, reason="gcc-avr and libsimavr-dev are needed (make setup)")

PROBE_C = Path(__file__).resolve().parent / "twi_probe" / "probe.c"
F32 = ElemType("F32", 4, "float", False, 0, 0)


def sensor(part: str, bus: str = "i2c", address: int | None = None, cs_pin: int | None = None,
           outputs=(), **settings) -> Sensor:
    defaults = {"bmp280": {"osrs_p": 4, "osrs_t": 1}, "ms5611": {"osr": 1024}, "adxl345": {"range": 16, "rate": 400},
                "mpu6050": {"range": 16, "dlpf": 3}}[part]
    defaults.update(settings)
    defaults.update(stuck=50, timeout=3)
    outs = tuple((q, Element(el, F32, "Flight", 0, 1)) for q, el in outputs)
    return Sensor(part, bus, address, cs_pin, f"0x{address:02x}" if address is not None else str(cs_pin),
                  tuple(defaults.items()), outs, None, None, "t.sns", 1)


BMP = sensor("bmp280", address=0x76, outputs=[("pressure", "p")])
MS = sensor("ms5611", address=0x77, outputs=[("pressure", "p2")])
ADXL_I2C = sensor("adxl345", address=0x53, outputs=[("z", "a")])
ADXL_SPI = sensor("adxl345", "spi", cs_pin=9, outputs=[("-z", "a2")])
MPU = sensor("mpu6050", address=0x68, range=8, outputs=[("x", "ax")])


@pytest.fixture(scope="module")
def probe(tmp_path_factory) -> str:
    if not HAVE_SIM:
        pytest.skip("gcc-avr and libsimavr-dev are needed (make setup)")
    return build_probe(PROBE_C, tmp_path_factory.mktemp("feed"))


# ---- the inverse path, without a board -------------------------------------------------

def test_barometer_counts_are_the_datasheet_inverse():
    """PartFeed's counts equal parts.py's full-search inverse for a falling,
    noisy pressure and a changing temperature, with jumps (its
    secant-and-gallop search finds the same answer), and
    the firmware's forward formula reads them back within a count's worth."""
    c = P.BMP280_EXAMPLE[0]
    feed = PartFeed(BMP, 0x76, P.bmp280_calib_bytes(c))
    rng = random.Random(5)
    for i in range(400):
        pa, t_c = 101325.0 - 40.0 * i + rng.gauss(0, 30), 15.0 - 0.01 * i + (5.0 if i % 97 == 0 else 0.0)
        raw = feed.raw(pressure=pa, temperature=t_c)
        assert raw["adc_T"] == P.bmp280_adc_T_for(c, t_c)
        t_fine = P.bmp280_compensate_T(c, raw["adc_T"])[1]
        assert raw["adc_P"] == P.bmp280_adc_P_for(c, pa, t_fine)
        assert abs(P.bmp280_compensate_P64(c, raw["adc_P"], t_fine) / 256.0 - pa) < 0.2
    m = P.MS5611_EXAMPLE[0]
    prom = b"".join(w.to_bytes(2, "big") for w in P.ms5611_prom_words(m))
    feed = PartFeed(MS, 0x77, prom)
    for i in range(200):  # the temperature through both second-order corrections (below 20 and -15 degC)
        pa, t_c = 100000.0 - 55.0 * i + rng.gauss(0, 10), 25.0 - 0.22 * i + rng.gauss(0, 0.05)
        raw = feed.raw(pressure=pa, temperature=t_c)
        assert raw["D2"] == P.ms5611_D2_for(m, t_c)
        assert raw["D1"] == P.ms5611_D1_for(m, pa / 100.0, raw["D2"])
        assert abs(P.ms5611_compensate(m, raw["D1"], raw["D2"]).P - pa) <= 0.5


def test_a_temperature_met_again_reads_the_count_a_full_search_gives():
    """PartFeed keeps the raw temperature it found by the half-count of the
    target (a compensated temperature is a whole number of 0.01 degC): a
    temperature wandering back and forth across a few counts, through their
    halves and onto them exactly, reads what parts.py's full search gives
    each time, on both barometers."""
    rng = random.Random(7)
    temps = [20.0 + 0.0001 * i + rng.gauss(0, 0.006) for i in range(300)]
    temps += [20.0 + k * 0.005 for k in range(-6, 7)] * 2  # the half-counts and the counts themselves
    c = P.BMP280_EXAMPLE[0]
    feed = PartFeed(BMP, 0x76, P.bmp280_calib_bytes(c))
    for t_c in temps:
        assert feed.raw(pressure=101325.0, temperature=t_c)["adc_T"] == P.bmp280_adc_T_for(c, t_c), t_c
    m = P.MS5611_EXAMPLE[0]
    feed = PartFeed(MS, 0x77, b"".join(w.to_bytes(2, "big") for w in P.ms5611_prom_words(m)))
    for t_c in temps:
        assert feed.raw(pressure=100000.0, temperature=t_c)["D2"] == P.ms5611_D2_for(m, t_c), t_c


def test_the_pressure_formula_without_its_wrapping_is_the_datasheets():
    """parts.bmp280_P64_fn (what the feed evaluates at every plant step) is
    bmp280_P64_of at every adc_P tried, for the datasheet's calibration and
    random ones, at t_fines where it drops the 64-bit wrapping (its bounds
    allow) and where it keeps the full formula; for the datasheet's part it
    is the unwrapped one (the fast path is the one flights take)."""
    rng = random.Random(11)
    calibs = [P.BMP280_EXAMPLE[0]] + [
        P.Bmp280Calib(rng.randint(1, 65535), rng.randint(-32768, 32767), rng.randint(-32768, 32767),
                      rng.randint(1, 65535), *(rng.randint(-32768, 32767) for _ in range(8))) for _ in range(40)]
    paths = set()
    for c in calibs:
        for tf in (128422, 0, 90000, 150000, -400000, rng.randint(-2 ** 20, 2 ** 20)):
            terms = P.bmp280_P64_terms(c, tf)
            of = P.bmp280_P64_fn(c, terms)
            paths.add(of.__name__)
            for a in [0, 1, 0xFFFFE, 0xFFFFF] + [rng.randint(0, 0xFFFFF) for _ in range(150)]:
                assert of(a) == P.bmp280_P64_of(c, a, terms), (c, tf, a)
    assert paths == {"of", "<lambda>"}  # both ways taken
    assert P.bmp280_P64_fn(P.BMP280_EXAMPLE[0], P.bmp280_P64_terms(P.BMP280_EXAMPLE[0], 128422)).__name__ == "of"


def test_the_walk_with_values_kept_answers_as_the_full_search():
    """sensors._walk_nearest, given values of f already known (the feed
    keeps them between plant steps), answers as parts._nearest_search does,
    from any guess, rising and falling, with repeated values."""
    from fswkit.sim.sensors import _walk_nearest

    rng = random.Random(3)
    for _ in range(3000):
        k, off = rng.choice([-1, 1]) * rng.uniform(0.05, 3), rng.uniform(-50, 50)
        inc = k > 0
        hi = rng.choice([3, 50, 0xFFFFF])
        f = (lambda x, k=k, off=off: int(k * x + off))  # monotonic, plateaus where |k| < 1
        target = rng.uniform(min(f(0), f(hi)) - 5, max(f(0), f(hi)) + 5)
        seen = {x: f(x) for x in (rng.randint(0, hi) for _ in range(rng.randint(0, 6)))}
        assert _walk_nearest(f, target, rng.randint(-5, hi + 5), 0, hi, inc, seen) == \
            P._nearest_search(f, target, 0, hi, inc)


def test_a_parts_hash_is_the_dataclasss_and_is_not_pickled():
    """Sensor keeps its hash (the number the dataclass's own hash gives, so
    sets of parts keep their order) after the first time; a pickled part
    carries no hash (another process hashes strings otherwise) and equals
    and hashes as the original."""
    import dataclasses
    import pickle

    fields = [getattr(BMP, f.name) for f in dataclasses.fields(BMP)]
    assert hash(BMP) == hash(tuple(fields)) == hash(BMP)
    copy = pickle.loads(pickle.dumps(BMP))
    assert "_hash" not in copy.__dict__ and copy == BMP and hash(copy) == hash(BMP)
    assert dataclasses.replace(BMP, line=2) != BMP and hash(dataclasses.replace(BMP, line=2)) != hash(BMP)


def test_accelerometer_counts_at_the_parts_range():
    """ADXL345 in full resolution: 256 counts a g at every range, stopping at
    the range's 13 bits (+-16 g); MPU-6050 at +-8 g: 4096 a g; an axis not
    given reads 0 g."""
    adxl = PartFeed(ADXL_I2C, 0x53, b"\0\0\0")
    assert adxl.raw(z=1.0) == {"x": 0, "y": 0, "z": 256}
    assert adxl.raw(x=-2.5, z=15.99) == {"x": -640, "y": 0, "z": 4093}
    assert adxl.raw(z=40.0)["z"] == 4095 and adxl.raw(z=-40.0)["z"] == -4096
    small = PartFeed(sensor("adxl345", address=0x1D, range=2), 0x1D, b"\0\0\0")
    assert small.raw(z=3.0)["z"] == 511  # +-2 g: 10 bits
    mpu = PartFeed(MPU, 0x68, b"\0" * 4)
    raw = mpu.raw(x=1.5, temperature=25.0)
    assert (raw["ax"], raw["ay"], raw["az"]) == (6144, 0, 0)
    assert abs(P.mpu6050_temp_c(raw["temp"]) - 25.0) < 1 / 340


def test_find_part_by_kind_address_and_chip_select():
    parts = (BMP, ADXL_I2C, ADXL_SPI)
    assert find_part(parts, "bmp280", ("bmp280", "ms5611")) == (BMP, None)
    assert find_part(parts, "bmp280@0x76", ("bmp280", "ms5611")) == (BMP, None)
    assert find_part(parts, "adxl345@spi:9", ("adxl345",)) == (ADXL_SPI, None)
    assert find_part(parts, "adxl345@i2c:0x53", ("adxl345",)) == (ADXL_I2C, None)
    part, why = find_part(parts, "adxl345", ("adxl345",))
    assert part is None and "2 adxl345 parts (adxl345@0x53, adxl345@spi:9): name one" in why
    part, why = find_part(parts, "bmp280@0x77", ("bmp280", "ms5611"))
    assert part is None and "not in the project's sensor tables (its parts: bmp280@0x76, adxl345@0x53" in why
    part, why = find_part(parts, "ms5611", ("bmp280", "ms5611"))
    assert part is None and "have no ms5611" in why
    part, why = find_part(parts, "adxl345@0x53", ("bmp280", "ms5611"))
    assert part is None and "a part of kind bmp280 or ms5611" in why
    part, why = find_part(parts, "bmp280@zz", ("bmp280",))
    assert part is None and "KIND@ADDRESS" in why
    assert [part_name(p) for p in parts] == ["bmp280@0x76", "adxl345@0x53", "adxl345@spi:9"]


# ---- on the simulated board --------------------------------------------------------------

@needs_sim
def test_batch_sets_the_raw_counts_of_i2c_and_spi_parts(probe):
    """One `batch` carries the analog millivolts and two parts' raw counts;
    part_info then holds exactly PartFeed's counts (the inverse of the
    values fed, with the calibration read from the board)."""
    sensors = (BMP, ADXL_SPI)
    parts = board_parts(sensors, "uno")
    assert parts == [("bmp280", 0x76), ("adxl345", "B1")]  # pin 9 is PB1 on the Uno
    with SimBoard(probe, "uno", sim_limit=5, wall_limit=60, parts=parts) as b:
        cal = b.part_calibration(0x76)
        baro = PartFeed(BMP, 0x76, cal)
        acc = PartFeed(ADXL_SPI, "B1", b.part_calibration("B1"))
        want_b = baro.raw(pressure=89874.6, temperature=4.25)
        want_a = acc.raw(z=-3.5)
        step = b.batch(b.cycles_for(0.01), {"A0": 1.0}, None, {0x76: want_b, "B1": want_a})
        assert step.run.stop == "target"
        info = b.part_info(0x76)
        assert (info["adc_P"], info["adc_T"]) == (want_b["adc_P"], want_b["adc_T"])
        c = P.bmp280_parse_calib(cal)
        t_fine = P.bmp280_compensate_T(c, info["adc_T"])[1]
        assert info["adc_P"] == P.bmp280_adc_P_for(c, 89874.6, t_fine)
        assert info["adc_T"] == P.bmp280_adc_T_for(c, 4.25)
        assert (b.part_info("B1")["x"], b.part_info("B1")["z"]) == (0, -896)
        # names not given keep their values
        b.batch(b.cycles_for(0.02), parts={"B1": {"x": 7}})
        assert [b.part_info("B1")[k] for k in "xyz"] == [7, 0, -896]


@needs_sim
def test_a_bad_part_word_is_refused_before_anything_is_applied(probe):
    with SimBoard(probe, "uno", sim_limit=5, wall_limit=60, parts=[("bmp280", 0x76)]) as b:
        b.part_raw(0x76, adc_P=1000, adc_T=2000)
        cycle = b.cycle
        for word, msg in (("@0x76:adc_P=5,adc_X=1", "bad raw counts `@0x76:adc_P=5,adc_X=1`: the bmp280 takes"),
                          ("@0x76:adc_P=1048576", "(0..1048575)"),
                          ("@0x76:adc_P=", "bad raw counts"),
                          ("@0x77:adc_P=5", "no part at `@0x77:adc_P=5`"),
                          ("@B1:z=5", "no part at"),
                          ("@0x76", "no part at")):
            with pytest.raises(SimError) as e:
                b.command(f"batch {cycle + 16000} 0=2500 {word}")
            assert msg in str(e.value), str(e.value)
        assert b.part_info(0x76)["adc_P"] == 1000  # nothing applied, no time run
        assert b.command("step 0").split()[1] == f"cycle={cycle}"


@needs_sim
def test_firmware_reads_the_counts_fed_through_batch(probe):
    """The probe starts a forced BMP280 measurement and reads 0xF7..0xFC: the
    adc_P and adc_T that the batch before set (latched by the measurement's
    end); and the SPI ADXL345's data registers hold the z counts fed."""
    from test_twi_parts import Probe, bmp_adc, poll, wait_until, write, xread, xresult

    with SimBoard(probe, "uno", sim_limit=10, wall_limit=60, parts=[("bmp280", 0x76), ("adxl345", "B1")],
                  spi_flash="B2") as b:
        baro = PartFeed(BMP, 0x76, b.part_calibration(0x76))
        acc = PartFeed(ADXL_SPI, "B1", b.part_calibration("B1"))
        p = Probe(b)
        want = baro.raw(pressure=95000.0, temperature=10.0)
        wz = acc.raw(z=2.0)
        b.batch(b.cycle + b.cycles_for(0.001), parts={0x76: want, "B1": wz})
        r = p.run(write(0x76, bytes([0xF4, 0x25])), poll(0x76, 0xF3, 0x08, 0x00), xread(0x76, 0xF7, 6),
                  "S2d08", "M", wait_until(10.1e-3), "Sf2" + "00" * 6)
        data = xresult(r[2])[1]
        assert (bmp_adc(data[:3]), bmp_adc(data[3:])) == (want["adc_P"], want["adc_T"])
        c = P.bmp280_parse_calib(b.part_calibration(0x76))
        t_fine = P.bmp280_compensate_T(c, bmp_adc(data[3:]))[1]
        assert abs(P.bmp280_compensate_P64(c, bmp_adc(data[:3]), t_fine) / 256.0 - 95000.0) < 0.2
        z = int.from_bytes(bytes.fromhex(r[6][1:])[5:7], "little", signed=True)
        assert z == wz["z"] == 512
