"""The sensor drivers against the simulated board's parts (harness -I) with
failures set by the host mid-run. First the barometers
(firmware/src/fsw_baro.h over fsw_twi.h), a BMP280 and an MS5611: `nack`
is reported at the step after the driver's next transaction (a heartbeat
while it waits for a conversion: within 3 ms), `stuck` after the driver's 5 unchanged conversions, `ok`
brings the readings back, and through it all no step of either driver
blocks the 1 kHz executor cycle (the worst step is measured in the
firmware with micros32 and read from RAM).

The firmware is tests/sim/baro_probe/probe.cpp linked against the firmware
suites' libfswkit.a and Arduino core (mk/firmware.mk builds them). The
Unity suite tests/firmware/test_baro.cpp covers the datasheet values, the
absent and the wrong part, stuck on constant counts and the bus abort: it
cannot change a part's failure mode while it runs.

Then the accelerometers (fsw_accel.h): an ADXL345 on the TWI, one on the
SPI and an MPU-6050 (tests/sim/accel_probe/probe.cpp, 500 Hz cycles):
`nack` is reported within one step (the drivers read the part every step),
`ok` brings the readings back, `stuck` is seen after 5 unchanged samples."""

from __future__ import annotations

import os
import shutil
import struct
import subprocess
from pathlib import Path

import pytest

from fswkit.sim.board import SimBoard

ROOT = Path(__file__).resolve().parents[2]
PROBE = Path(__file__).resolve().parent / "baro_probe" / "probe.cpp"
ACCEL_PROBE = Path(__file__).resolve().parent / "accel_probe" / "probe.cpp"
ARDUINO = Path("/usr/share/arduino/hardware/arduino/avr")
AVR = ROOT / "build" / "firmware" / "avr"

pytestmark = pytest.mark.skipif(
    shutil.which("avr-g++") is None or not os.path.exists("/usr/include/simavr/sim_avr.h")
    or not ARDUINO.exists(),
    reason="gcc-avr, arduino-core-avr and libsimavr-dev are needed (make setup)")

BMP, MS = 0x76, 0x77
OK, NO_ANSWER, STUCK = 1, 2, 5  # SensorHealth: kSensorOk, kSensorNoAnswer, kSensorStuck (fsw_sensor.h)
FMT = "<BBHHHHiiIiIHHHHHHHH"
FIELDS = ("bmp_health ms_health bmp_faults ms_faults bmp_readings ms_readings bmp_temp_centi "
          "ms_temp_centi bmp_p_q8 ms_p cycles worst_bmp_us worst_ms_us worst_cycle_us "
          "twi_transactions twi_nack_addr twi_nack_data twi_bus_error twi_timeout").split()
BMP_MEASURE_S = 6.425e-3   # x1 / x1 forced measurement, datasheet max
MS_CONVERT_S = 2.28e-3     # OSR 1024


def build(tmp_path_factory, probe: Path) -> str:
    # the targets as mk/firmware.mk names them (relative to the tree: it defines its build rules only for
    # goals under its own build/firmware/, and an absolute path is not one of those)
    r = subprocess.run(["make", "--no-print-directory", "-f", "mk/firmware.mk",
                        str((AVR / "libfswkit.a").relative_to(ROOT)), str((AVR / "core.a").relative_to(ROOT))],
                       cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    out = tmp_path_factory.mktemp(probe.parent.name) / "probe.elf"
    defs = ["-mmcu=atmega328p", "-DF_CPU=16000000L", "-DARDUINO=10819", "-DARDUINO_AVR_UNO",
            "-DARDUINO_ARCH_AVR", f"-I{ARDUINO}/cores/arduino", f"-I{ARDUINO}/variants/standard"]
    r = subprocess.run(["avr-g++", "-std=gnu++11", "-Os", "-ffunction-sections", "-fdata-sections",
                        "-fno-exceptions", "-fno-rtti", "-fno-threadsafe-statics", *defs,
                        f"-I{ROOT / 'firmware' / 'src'}", "-Wall", "-Wextra", "-Werror",
                        "-o", str(out), str(probe), str(AVR / "libfswkit.a"), str(AVR / "core.a"),
                        "-Wl,--gc-sections"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return str(out)


@pytest.fixture(scope="module")
def elf(tmp_path_factory) -> str:
    return build(tmp_path_factory, PROBE)


class Run:
    """The board, the probe's RAM record, and raw counts that change every
    millisecond (as a real part's noise does), so only `stuck` is stuck."""

    def __init__(self, b: SimBoard):
        self.b = b
        self.addr, size = b.symbol("g_probe")
        assert size == struct.calcsize(FMT)
        self.k = 0

    def state(self) -> dict:
        return dict(zip(FIELDS, struct.unpack(FMT, self.b.peek(self.addr, struct.calcsize(FMT)))))

    def ms(self, n: int = 1) -> dict:
        for _ in range(n):
            self.k += 1
            self.b.part_raw(BMP, adc_P=415148 + (self.k % 64), adc_T=519888 + (self.k % 16))
            self.b.part_raw(MS, D1=9085466 + (self.k % 64), D2=8569150 + (self.k % 16))
            self.b.step(self.b.cycles_for(0.001))
        return self.state()

    def until(self, cond, limit_ms: int) -> tuple[int, dict]:
        """Milliseconds until cond(state) holds (at 1 ms resolution)."""
        for t in range(1, limit_ms + 1):
            s = self.ms()
            if cond(s):
                return t, s
        raise AssertionError(f"not within {limit_ms} ms: {self.state()}")


@pytest.fixture
def run(elf):
    with SimBoard(elf, "uno", uart="none", parts=[("bmp280", BMP), ("ms5611", MS)], sim_limit=30) as b:
        r = Run(b)
        r.ms(100)
        s = r.state()
        assert s["bmp_health"] == OK and s["ms_health"] == OK, s
        assert s["bmp_faults"] == 0 and s["ms_faults"] == 0, s
        yield r


def test_readings_flow_and_steps_are_short(run):
    s0 = run.state()
    s = run.ms(200)
    assert s["bmp_readings"] - s0["bmp_readings"] >= 20     # about 7.4 ms each
    assert s["ms_readings"] - s0["ms_readings"] >= 12       # about 12 ms each (D2 then D1)
    assert s["cycles"] - s0["cycles"] >= 195                # the executor kept its 1 kHz
    # Near the datasheet example (the raw counts differ by a few counts).
    assert abs(s["bmp_temp_centi"] - 2508) <= 2 and abs(s["bmp_p_q8"] / 256 - 100653.25) < 20
    assert abs(s["ms_temp_centi"] - 2007) <= 2 and abs(s["ms_p"] - 100009) < 20
    assert s["worst_cycle_us"] < 1000, s
    print(f"worst step: BMP280 {s['worst_bmp_us']} us, MS5611 {s['worst_ms_us']} us, "
          f"cycle {s['worst_cycle_us']} us")


@pytest.mark.parametrize("part,health,faults,next_txn_s", [
    (BMP, "bmp_health", "bmp_faults", BMP_MEASURE_S),
    (MS, "ms_health", "ms_faults", MS_CONVERT_S)])
def test_nack_reported_then_recovers(run, part, health, faults, next_txn_s):
    c0 = run.state()["cycles"]
    run.b.part_fail(part, "nack")
    # While a conversion runs the driver still talks to the part every
    # step (BMP280: a status read; MS5611: an address probe), so the
    # failure is seen at the step after the first failed transaction: at
    # most 3 ms, not the conversion time (next_txn_s) it would otherwise be.
    t, s = run.until(lambda s: s[health] == NO_ANSWER, 30)
    assert t <= 3, (t, next_txn_s)
    assert s[faults] >= 1
    # Retrying (every 20 ms) while the part is gone: the other driver and the
    # executor go on.
    s = run.ms(100)
    assert s[health] == NO_ANSWER and s[faults] >= 3
    assert s["cycles"] - c0 >= 0.95 * (t + 100)
    other = "ms_health" if part == BMP else "bmp_health"
    assert s[other] == OK
    run.b.part_fail(part, "ok")
    t, s = run.until(lambda s: s[health] == OK, 80)
    assert s["worst_cycle_us"] < 1000, s


@pytest.mark.parametrize("part,health,faults,readings", [
    (BMP, "bmp_health", "bmp_faults", "bmp_readings"),
    (MS, "ms_health", "ms_faults", "ms_readings")])
def test_stuck_detected_then_recovers(run, part, health, faults, readings):
    n0 = run.state()[readings]
    run.b.part_fail(part, "stuck")
    t, s = run.until(lambda s: s[health] == STUCK, 200)
    # 5 unchanged conversions after the first stuck one (+1: a conversion
    # may have been running when the part stuck).
    assert s[readings] - n0 <= 7, (s, n0)
    assert s[faults] == 1
    run.b.part_fail(part, "ok")
    t, s = run.until(lambda s: s[health] == OK, 60)
    assert s[faults] == 1
    assert s["worst_cycle_us"] < 1000, s


# ---- accelerometers ----------------------------------------------------------------

ADXL, ADXL_SPI, MPU = 0x53, "B1", 0x68
AFMT = "<3B3H3H3hI"
AFIELDS = ("health", "faults", "readings", "z")
STEP_S = 0.002  # the probe's cycle


class AccelRun:
    def __init__(self, b: SimBoard):
        self.b = b
        self.addr, size = b.symbol("g_probe")
        assert size == struct.calcsize(AFMT)
        self.k = 0

    def state(self) -> dict:
        v = struct.unpack(AFMT, self.b.peek(self.addr, struct.calcsize(AFMT)))
        s = {f: v[3 * i:3 * i + 3] for i, f in enumerate(AFIELDS)}
        s["cycles"] = v[12]
        return s

    def steps(self, n: int = 1) -> dict:
        """n probe cycles, the parts' counts changing by one every cycle."""
        for _ in range(n):
            self.k += 1
            self.b.part_raw(ADXL, x=self.k % 50, y=0, z=256)
            self.b.part_raw(ADXL_SPI, x=self.k % 50, y=0, z=256)
            self.b.part_raw(MPU, ax=self.k % 50, ay=0, az=2048)
            self.b.step(self.b.cycles_for(STEP_S))
        return self.state()


@pytest.fixture(scope="module")
def accel_elf(tmp_path_factory) -> str:
    return build(tmp_path_factory, ACCEL_PROBE)


@pytest.fixture
def accel(accel_elf):
    with SimBoard(accel_elf, "uno", uart="none", parts=[("adxl345", ADXL), ("adxl345", ADXL_SPI), ("mpu6050", MPU)],
                  sim_limit=30) as b:
        r = AccelRun(b)
        s = r.steps(100)  # the MPU-6050's reset takes 100 ms
        assert s["health"] == (OK, OK, OK), s
        assert s["faults"] == (0, 0, 0), s
        assert s["z"] == (256, 256, 2048), s
        yield r


@pytest.mark.parametrize("i,part", [(0, ADXL), (1, ADXL_SPI), (2, MPU)])
def test_accel_nack_seen_within_a_step_then_recovers(accel, i, part):
    s0 = accel.state()
    accel.b.part_fail(part, "nack")
    # The part is read at every step: the TWI's NACK is seen at the step
    # after the one whose read it failed (SPI: in that step itself). The
    # host stops the board anywhere in a cycle, and the record is written
    # after the cycle's steps: the cycle in progress may already have read
    # the part, so the first failed read is the next cycle's, and the record
    # counts one cycle more.
    s = s0
    for _ in range(12):  # 0.5 ms at a time
        accel.b.step(accel.b.cycles_for(STEP_S / 4))
        s = accel.state()
        if s["health"][i] == NO_ANSWER:
            break
    assert s["health"][i] == NO_ANSWER, s
    assert s["cycles"] - s0["cycles"] <= (2 if part == ADXL_SPI else 3), (s, s0)
    assert s["faults"][i] == s0["faults"][i] + 1
    others = [j for j in range(3) if j != i]
    s = accel.steps(30)
    assert s["health"][i] == NO_ANSWER and s["faults"][i] >= 3  # retried every 20 ms
    assert all(s["health"][j] == OK for j in others), s
    n = s["readings"][i]
    accel.b.part_fail(part, "ok")
    s = accel.steps(80)  # the MPU-6050 resets again: 100 ms
    assert s["health"][i] == OK, s
    assert s["readings"][i] > n
    assert all(s["faults"][j] == s0["faults"][j] for j in others), s


def test_accel_stuck_seen_after_five_unchanged_samples(accel):
    s0 = accel.state()
    for part in (ADXL, ADXL_SPI, MPU):
        accel.b.part_fail(part, "stuck")
    s = accel.state()
    for _ in range(20):
        accel.b.step(accel.b.cycles_for(STEP_S))
        s = accel.state()
        if s["health"] == (STUCK, STUCK, STUCK):
            break
    assert s["health"] == (STUCK, STUCK, STUCK), s
    # 400 Hz and 1 kHz samples: 5 unchanged ones within 15 ms and 5 ms (+ a cycle)
    assert s["cycles"] - s0["cycles"] <= 9, (s, s0)
    assert s["faults"] == tuple(f + 1 for f in s0["faults"])
    for part in (ADXL, ADXL_SPI, MPU):
        accel.b.part_fail(part, "ok")
    s = accel.steps(5)
    assert s["health"] == (OK, OK, OK), s
