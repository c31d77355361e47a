"""Sensors on the simulated board's I2C (TWI) and SPI (harness -I, `part`;
SimBoard(parts=...), part_calibration / part_raw / part_fail): register
models of the BMP280, MS5611, MPU-6050 and ADXL345 as firmware sees them
through the AVR's TWI and SPI registers, with calibration and raw counts set
from Python, conversions lasting the datasheets' maximum times in simulated
time, and failures (`nack`, `stuck`).

The firmware is tests/sim/twi_probe/probe.c, built here with avr-gcc: it
runs a script of TWI (and SPI) transactions sent over UART0 and answers with
the TWI status codes and the bytes read (see its header). Times are the
probe's Timer1 ticks (0.5 us) from the STOP of the last write step; simavr
1.6 takes 9 us per TWI byte, so a register poll takes about 30 us."""

from __future__ import annotations

import os
import re
import shutil
from pathlib import Path

import pytest

from support.uartprobe import UartProbe, build_probe
from fswkit.sim.board import SimBoard, SimError

pytestmark = pytest.mark.skipif(
    shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
    reason="gcc-avr (to build the probe firmware) and libsimavr-dev are needed (make setup)")

PROBE_C = Path(__file__).resolve().parent / "twi_probe" / "probe.c"
TICK = 0.5e-6  # the probe's Timer1 tick
POLL = 80e-6   # a conversion's end is seen within this of its time (a poll's transactions)
STEP = 150e-6  # more than a probe step takes to reach its first TWI byte (about 50 us at -Os)

BMP, MS, MPU, ADXL = 0x76, 0x77, 0x68, 0x53
# TWI status codes (ATmega328P datasheet, table 22-2 and 22-3)
MT_SLA_NACK, MR_SLA_NACK, DONE = 0x20, 0x48, 0x58


@pytest.fixture(scope="module")
def probe(tmp_path_factory) -> str:
    return build_probe(PROBE_C, tmp_path_factory.mktemp("twi"))


class Probe(UartProbe):
    """Talks to probe.c on a SimBoard's UART0, advancing simulated time."""

    def __init__(self, board: SimBoard):
        super().__init__(board)
        assert self.line() == "ready"

    def run(self, *steps: str, limit_s: float = 2.0) -> list[str]:
        self.b.uart_write((",".join(steps) + "\n").encode())
        out = self.line(limit_s).split(",")
        assert len(out) == len(steps), out
        return out

    # one step, decoded
    def write(self, addr: int, data: bytes) -> int:
        """Bytes written in one transaction: the last TWI status."""
        return int(self.run(write(addr, data))[0][1:], 16)

    def read(self, addr: int, reg: int, n: int) -> bytes:
        """A register read (register pointer, repeated START, n bytes), which must succeed."""
        st, data = xresult(self.run(xread(addr, reg, n))[0])
        assert st == DONE, hex(st)
        return data


def write(addr: int, data: bytes) -> str:
    return f"W{addr:02x}{data.hex()}"


def xread(addr: int, reg: int, n: int) -> str:
    return f"X{addr:02x}{reg:02x}{n:02x}"


def poll(addr: int, reg: int, mask: int, want: int) -> str:
    return f"P{addr:02x}{reg:02x}{mask:02x}{want:02x}"


def wait_until(seconds: float) -> str:
    return f"Z{round(seconds / TICK):08x}"


def xresult(step: str) -> tuple[int, bytes]:
    """An X or R step's result: (status, bytes read)."""
    assert step[0] in "XR", step
    return int(step[1:3], 16), bytes.fromhex(step[3:])


def poll_time(step: str) -> float:
    assert step[0] == "P" and step[1] != "!", step
    return int(step[1:], 16) * TICK


def be24(data: bytes) -> int:
    return int.from_bytes(data[:3], "big")


def bmp_adc(data: bytes) -> int:
    """A BMP280 20-bit result from its msb, lsb, xlsb registers."""
    return data[0] << 12 | data[1] << 4 | data[2] >> 4


def crc4(prom: bytes) -> int:
    """The MS5611's PROM CRC-4 (TE application note AN520)."""
    words = [int.from_bytes(prom[i:i + 2], "big") for i in range(0, 16, 2)]
    words[7] &= 0xFF00
    rem = 0
    for i in range(16):
        rem ^= (words[i >> 1] & 0xFF) if i & 1 else (words[i >> 1] >> 8)
        for _ in range(8):
            rem = ((rem << 1) ^ 0x3000) if rem & 0x8000 else rem << 1
            rem &= 0xFFFF
    return (rem >> 12) & 0xF


ALL = [("bmp280", BMP), ("ms5611", MS), ("mpu6050", MPU), ("adxl345", ADXL)]


def board(elf: str, parts=ALL, **kw) -> SimBoard:
    return SimBoard(elf, "uno", sim_limit=60, wall_limit=120, parts=parts, **kw)


# ---- IDs, calibration, several parts on one bus ------------------------------------------

def test_ids_and_calibration_of_four_parts_on_one_bus(probe):
    """Each part answers at its own address with its ID and the calibration
    the host stored; an address nobody has gets no ACK."""
    bmp_cal = bytes(range(0x10, 0x10 + 24))
    prom = bytes.fromhex("0000 9cbf 903c 5b15 5af2 82b8 6e98 1234")
    with board(probe) as b:
        assert b.parts() == {BMP: "bmp280", MS: "ms5611", MPU: "mpu6050", ADXL: "adxl345"}
        default_prom = b.part_calibration(MS)
        assert crc4(default_prom) == default_prom[15] & 0xF  # the datasheet example with a valid CRC
        assert b.part_calibration(BMP, bmp_cal) == bmp_cal
        assert b.part_calibration(MS, prom) == prom
        p = Probe(b)
        r = p.run(xread(BMP, 0xD0, 1), xread(BMP, 0x88, 24), xread(MPU, 0x75, 1), xread(MPU, 0x6B, 1),
                  xread(ADXL, 0x00, 1), write(MS, b"\x1e"),
                  *[s for w in range(8) for s in (write(MS, bytes([0xA0 + 2 * w])), f"R{MS:02x}02")],
                  xread(0x13, 0x00, 1), "R1301")
        assert xresult(r[0]) == (DONE, b"\x58")
        assert xresult(r[1]) == (DONE, bmp_cal)
        assert xresult(r[2]) == (DONE, b"\x68")
        assert xresult(r[3]) == (DONE, b"\x40")  # PWR_MGMT_1: asleep at power-on
        assert xresult(r[4]) == (DONE, b"\xe5")
        assert r[5] == "W28"
        words = b"".join(xresult(s)[1] for s in r[7:22:2])
        assert words == prom  # verbatim, its (wrong) CRC included: the host's to choose
        assert xresult(r[22])[0] == MT_SLA_NACK
        assert xresult(r[23]) == (MR_SLA_NACK, b"")


def test_two_parts_of_a_kind_at_their_two_addresses(probe):
    with board(probe, parts=[("bmp280", 0x76), ("bmp280", 0x77)]) as b:
        b.part_raw(0x76, adc_P=0x11111, adc_T=0x22222)
        b.part_raw(0x77, adc_P=0x33333, adc_T=0x44444)
        p = Probe(b)
        r = p.run(write(0x76, b"\xf4\x25"), write(0x77, b"\xf4\x25"), wait_until(0.010),
                  xread(0x76, 0xF7, 6), xread(0x77, 0xF7, 6))
        a, c = xresult(r[3])[1], xresult(r[4])[1]
        assert (bmp_adc(a[:3]), bmp_adc(a[3:])) == (0x11111, 0x22222)
        assert (bmp_adc(c[:3]), bmp_adc(c[3:])) == (0x33333, 0x44444)


# ---- BMP280 -------------------------------------------------------------------------------

@pytest.mark.parametrize("ctrl,t_meas", [
    (0x25, 1.25e-3 + 2.3e-3 + 2.3e-3 + 0.575e-3),           # T x1, P x1: 6.4 ms (max)
    (0x55, 1.25e-3 + 2 * 2.3e-3 + 16 * 2.3e-3 + 0.575e-3),  # T x2, P x16: 43.2 ms
    (0x21, 1.25e-3 + 2.3e-3),                                # T x1, P skipped: 3.55 ms
])
def test_bmp280_forced_measurement_takes_the_datasheet_time(probe, ctrl, t_meas):
    """A forced measurement: `measuring` (status bit 3) until the
    datasheet's maximum measurement time for the oversampling, then the data
    registers hold the host's counts (a skipped pressure reads 0x80000) and
    the mode is back to sleep; before it ends they hold the old ones."""
    with board(probe, parts=[("bmp280", BMP)]) as b:
        b.part_raw(BMP, adc_P=415148, adc_T=519888)
        p = Probe(b)
        r = p.run(xread(BMP, 0xF7, 6), write(BMP, bytes([0xF4, ctrl])), xread(BMP, 0xF3, 1), xread(BMP, 0xF7, 6),
                  poll(BMP, 0xF3, 0x08, 0x00), xread(BMP, 0xF7, 6), xread(BMP, 0xF4, 1))
        before = xresult(r[0])[1]
        assert (bmp_adc(before[:3]), bmp_adc(before[3:])) == (0x80000, 0x80000)  # reset values
        assert xresult(r[2])[1] == b"\x08"
        assert xresult(r[3])[1] == before  # a read during the measurement: the old data
        assert t_meas - 20e-6 <= poll_time(r[4]) <= t_meas + POLL
        data = xresult(r[5])[1]
        assert bmp_adc(data[3:]) == 519888
        assert bmp_adc(data[:3]) == (415148 if ctrl & 0x1C else 0x80000)
        assert xresult(r[6])[1] == bytes([ctrl & 0xFC])  # forced -> sleep
        assert b.part_info(BMP)["conversions"] == 1


def test_bmp280_normal_mode_repeats_and_soft_reset(probe):
    """Normal mode measures every t_measure + t_standby (6.4 + 0.5 ms here);
    raw values set meanwhile show at the next measurement's end; 0xB6 to
    0xE0 resets the registers (calibration kept)."""
    with board(probe, parts=[("bmp280", BMP)]) as b:
        cal = b.part_calibration(BMP)
        p = Probe(b)
        p.run(write(BMP, b"\xf5\x00\xf4\x27"))  # config: t_sb 0.5 ms; ctrl_meas: x1, x1, normal
        b.run_for(0.020)
        n = b.part_info(BMP)["conversions"]
        assert n >= 2  # 6.925 ms a period
        b.part_raw(BMP, adc_T=0x12345)
        r = p.run("M", poll(BMP, 0xF3, 0x08, 0x08), poll(BMP, 0xF3, 0x08, 0x00), xread(BMP, 0xFA, 3),
                  xread(BMP, 0xF4, 1))
        assert bmp_adc(xresult(r[3])[1]) == 0x12345
        assert xresult(r[4])[1] == b"\x27"  # still normal
        r = p.run(write(BMP, b"\xe0\xb6"), xread(BMP, 0xF4, 2), xread(BMP, 0xF7, 6), xread(BMP, 0x88, 24))
        assert xresult(r[1])[1] == b"\x00\x00"
        assert xresult(r[2])[1] == bytes.fromhex("800000800000")
        assert xresult(r[3])[1] == cal


# ---- MS5611 -------------------------------------------------------------------------------

@pytest.mark.parametrize("osr,t_conv", [(0, 0.60e-3), (2, 2.28e-3), (4, 9.04e-3)])
def test_ms5611_conversion_time_and_adc_read(probe, osr, t_conv):
    """CONVERT D1/D2 at an OSR; an ADC read before the datasheet's maximum
    conversion time gives 0 (and the conversion goes on), after it the
    host's count, a second read 0."""
    with board(probe, parts=[("ms5611", MS)]) as b:
        b.part_raw(MS, D1=9085466, D2=8569150)
        p = Probe(b)
        adc = [write(MS, b"\x00"), f"R{MS:02x}03"]
        # each ADC read's STOP restarts the probe's clock
        r = p.run(write(MS, bytes([0x40 + 2 * osr])), wait_until(t_conv - STEP), *adc, wait_until(STEP), *adc,
                  *adc)
        assert xresult(r[3]) == (DONE, b"\x00\x00\x00")  # too early: 0, the conversion goes on
        assert be24(xresult(r[6])[1]) == 9085466
        assert xresult(r[8]) == (DONE, b"\x00\x00\x00")  # read twice: 0
        r = p.run(write(MS, bytes([0x50 + 2 * osr])), wait_until(t_conv + 30e-6), *adc)
        assert be24(xresult(r[3])[1]) == 8569150
        assert b.part_info(MS)["conversions"] == 2


def busy_cycles(b: SimBoard, part: int, limit_s: float = 0.1, step: int = 16) -> int:
    """Steps the board `step` cycles at a time until the part's conversion
    starts and ends (the harness's `part ADDR info` busy flag): its length in cycles."""
    deadline = b.cycle + b.cycles_for(limit_s)
    while not b.part_info(part)["busy"]:
        assert b.cycle < deadline, "no conversion started"
        b.step(step)
    start = b.cycle
    while b.part_info(part)["busy"]:
        assert b.cycle < deadline, "the conversion did not end"
        b.step(step)
    return b.cycle - start


@pytest.mark.parametrize("cmd,seconds", [(0x40, 0.60e-3), (0x42, 1.17e-3), (0x44, 2.28e-3), (0x56, 4.54e-3),
                                         (0x58, 9.04e-3)])
def test_ms5611_conversion_times_on_the_simulated_clock(probe, cmd, seconds):
    """Each OSR's conversion lasts the datasheet's maximum, to the cycle."""
    with board(probe, parts=[("ms5611", MS)]) as b:
        Probe(b).b.uart_write((write(MS, bytes([cmd])) + "\n").encode())
        assert abs(busy_cycles(b, MS) - b.cycles_for(seconds)) <= 16


@pytest.mark.parametrize("ctrl,seconds", [(0x25, 6.425e-3), (0x71, 1.25e-3 + 4 * 2.3e-3 + 8 * 2.3e-3 + 0.575e-3)])
def test_bmp280_measurement_times_on_the_simulated_clock(probe, ctrl, seconds):
    with board(probe, parts=[("bmp280", BMP)]) as b:
        Probe(b).b.uart_write((write(BMP, bytes([0xF4, ctrl])) + "\n").encode())
        assert abs(busy_cycles(b, BMP, step=64) - b.cycles_for(seconds)) <= 64


def test_ms5611_adc_read_before_the_end_gives_zero_then_the_result(probe):
    with board(probe, parts=[("ms5611", MS)]) as b:
        b.part_raw(MS, D1=0x123456)
        p = Probe(b)
        r = p.run(write(MS, b"\x48"), write(MS, b"\x00"), f"R{MS:02x}03", "M", wait_until(9.2e-3),
                  write(MS, b"\x00"), f"R{MS:02x}03")
        assert xresult(r[2])[1] == b"\x00\x00\x00"
        assert be24(xresult(r[6])[1]) == 0x123456


# ---- MPU-6050 and ADXL345 -------------------------------------------------------------------

def test_mpu6050_sleeps_at_power_on_then_samples(probe):
    raw = dict(ax=-1234, ay=2345, az=16384, temp=-3920, gx=-1, gy=100, gz=-32768)
    with board(probe, parts=[("mpu6050", MPU)]) as b:
        b.part_raw(MPU, **raw)
        p = Probe(b)
        # SMPLRT_DIV 99: 8 kHz / 100, a sample every 12.5 ms
        r = p.run(xread(MPU, 0x3B, 14), write(MPU, b"\x1c\x08"), xread(MPU, 0x1C, 1), write(MPU, b"\x19\x63"))
        assert xresult(r[0])[1] == bytes(14)  # asleep: no sample yet
        assert xresult(r[2])[1] == b"\x08"    # ACCEL_CONFIG: +-4 g
        r = p.run(write(MPU, b"\x6b\x00"), wait_until(12.4e-3), xread(MPU, 0x3A, 1), wait_until(12.6e-3),
                  xread(MPU, 0x3A, 1), xread(MPU, 0x3B, 14), xread(MPU, 0x3A, 1))
        assert xresult(r[2])[1] == b"\x00"  # no sample before 12.5 ms
        assert xresult(r[4])[1] == b"\x01"  # DATA_RDY_INT, cleared by the read
        got = xresult(r[5])[1]
        assert [int.from_bytes(got[i:i + 2], "big", signed=True) for i in range(0, 14, 2)] == list(raw.values())
        assert xresult(r[6])[1] == b"\x00"


@pytest.mark.parametrize("where", [ADXL, "B1"])
def test_adxl345_on_i2c_and_spi(probe, where):
    """DEVID, measure mode, little-endian data at 100 Hz; on SPI (4-wire, CS
    on PB1) a read sets bit 7, a multi-byte transfer bit 6."""
    # on SPI it shares the bus with the flash (deselected: CS PB2 high)
    with board(probe, parts=[("adxl345", where)], spi_flash="B2" if where == "B1" else None) as b:
        b.part_raw(where, x=-2, y=300, z=-256)
        p = Probe(b)
        want = bytes.fromhex("feff2c0100ff")
        if where == ADXL:
            r = p.run(xread(ADXL, 0x00, 1), write(ADXL, b"\x31\x0b"), write(ADXL, b"\x2d\x08"), wait_until(10.1e-3),
                      xread(ADXL, 0x32, 6), xread(ADXL, 0x2D, 5))
            assert xresult(r[0])[1] == b"\xe5"
            assert xresult(r[4])[1] == want
            assert xresult(r[5])[1][0] == 0x08 and xresult(r[5])[1][4] == 0x0B  # POWER_CTL, DATA_FORMAT
        else:
            r = p.run("S8000", "S310b", "S2d08", "M", wait_until(10.1e-3), "Sf2" + "00" * 6, "Sb2" + "00" * 3,
                      "Sb100")
            assert r[0] == "Sffe5"
            assert bytes.fromhex(r[5][1:])[1:] == want
            assert bytes.fromhex(r[6][1:])[1:] == b"\xfe" * 3  # no MB bit: the same register again
            assert r[7] == "Sff0b"


# ---- failures -------------------------------------------------------------------------------

def test_fail_nack_stops_answering_and_ok_brings_it_back(probe):
    with board(probe, parts=[("bmp280", BMP), ("mpu6050", MPU)]) as b:
        p = Probe(b)
        b.part_fail(BMP, "nack")
        r = p.run(xread(BMP, 0xD0, 1), f"R{BMP:02x}01", write(BMP, b"\xf4\x25"), xread(MPU, 0x75, 1))
        assert xresult(r[0])[0] == MT_SLA_NACK
        assert xresult(r[1])[0] == MR_SLA_NACK
        assert r[2] == f"W{MT_SLA_NACK:02x}"
        assert xresult(r[3]) == (DONE, b"\x68")  # the other part is still there
        assert b.part_info(BMP)["fail"] == "nack"
        b.part_fail(BMP, "ok")
        assert p.read(BMP, 0xD0, 1) == b"\x58"


def test_address_probe_is_acked_and_disturbs_nothing(probe):
    """The drivers' heartbeat, a zero-length write (START, SLA+W, STOP), is
    ACKed by every part (status 18) and NACKed (20) by one told to `fail
    nack` or by an empty address; probing an MS5611 and a BMP280 while they
    convert neither ends nor spoils their conversions."""
    with board(probe) as b:
        p = Probe(b)
        r = p.run(write(BMP, b""), write(MS, b""), write(MPU, b""), write(ADXL, b""), write(0x50, b""))
        assert r == ["W18", "W18", "W18", "W18", f"W{MT_SLA_NACK:02x}"]
        b.part_raw(MS, D1=9085466)
        b.part_raw(BMP, adc_P=415148, adc_T=519888)
        r = p.run(write(MS, bytes([0x44])), write(BMP, bytes([0xF4, 0x25])),  # D1 at OSR 1024; forced x1/x1
                  write(MS, b""), write(BMP, b""), xread(BMP, 0xF3, 1), wait_until(7e-3),
                  write(MS, b""), write(BMP, b""), xread(BMP, 0xF3, 1),
                  write(MS, b"\x00"), f"R{MS:02x}03", xread(BMP, 0xF7, 6))
        assert r[2] == r[3] == "W18"
        assert xresult(r[4]) == (DONE, b"\x08")  # measuring
        assert r[6] == r[7] == "W18"
        assert xresult(r[8]) == (DONE, b"\x00")  # done
        assert be24(xresult(r[10])[1]) == 9085466
        assert bmp_adc(xresult(r[11])[1]) == 415148
        b.part_fail(MS, "nack")
        assert p.run(write(MS, b""))[0] == f"W{MT_SLA_NACK:02x}"
        b.part_fail(MS, "ok")
        assert p.run(write(MS, b""))[0] == "W18"


def test_stuck_freezes_the_data_and_ok_releases_it(probe):
    with board(probe, parts=[("bmp280", BMP), ("ms5611", MS)]) as b:
        p = Probe(b)
        b.part_raw(BMP, adc_P=100000, adc_T=200000)
        b.part_raw(MS, D1=111111)
        p.run(write(BMP, b"\xf4\x25"), write(MS, b"\x48"), wait_until(10e-3))
        first = p.read(BMP, 0xF7, 6)
        b.part_fail(BMP, "stuck")
        b.part_fail(MS, "stuck")
        b.part_raw(BMP, adc_P=300000, adc_T=400000)
        b.part_raw(MS, D1=222222)
        r = p.run(write(BMP, b"\xf4\x25"), write(MS, b"\x00"), f"R{MS:02x}03", write(MS, b"\x48"),
                  poll(BMP, 0xF3, 0x08, 0x00), wait_until(10e-3), xread(BMP, 0xF7, 6), write(MS, b"\x00"),
                  f"R{MS:02x}03")
        assert be24(xresult(r[2])[1]) == 111111
        assert xresult(r[6])[1] == first  # a measurement ended, the data did not change
        assert be24(xresult(r[8])[1]) == 111111
        b.part_fail(BMP, "ok")
        p.run(write(BMP, b"\xf4\x25"), wait_until(7e-3))
        got = p.read(BMP, 0xF7, 6)
        assert (bmp_adc(got[:3]), bmp_adc(got[3:])) == (300000, 400000)


def test_power_reset_restarts_the_parts(probe):
    with board(probe, parts=[("mpu6050", MPU)]) as b:
        p = Probe(b)
        p.run(write(MPU, b"\x6b\x00"))
        b.reset("power")
        p = Probe(b)
        assert p.read(MPU, 0x6B, 1) == b"\x40"


# ---- the host side --------------------------------------------------------------------------

def test_part_options_and_commands_check_their_input(probe):
    with pytest.raises(ValueError, match="bmp280"):
        board(probe, parts=[("bmp999", 0x76)])
    with pytest.raises(SimError, match="0x76 or 0x77"):
        board(probe, parts=[("bmp280", 0x40)])
    with pytest.raises(SimError, match="I2C only"):
        board(probe, parts=[("bmp280", "B1")])
    with pytest.raises(SimError, match="already"):
        board(probe, parts=[("bmp280", 0x76), ("ms5611", 0x76)])
    with pytest.raises(SimError, match="chip select is B2"):
        board(probe, parts=[("adxl345", "B2")], spi_flash="B2")
    with board(probe, parts=[("bmp280", BMP)]) as b:
        with pytest.raises(SimError, match="no part at 0x68"):
            b.part_info(0x68)
        with pytest.raises(SimError, match="adc_P"):
            b.part_raw(BMP, adc_P=1 << 20)
        with pytest.raises(SimError, match="adc_P"):
            b.part_raw(BMP, D1=5)
        with pytest.raises(SimError, match="at most 24 bytes"):
            b.part_calibration(BMP, bytes(25))
        with pytest.raises(ValueError, match="nack"):
            b.part_fail(BMP, "broken")
        assert b.part_registers(BMP, 0xD0, 1) == b"\x58"
        assert b.part_info(BMP)["adc_T"] == 519888


def test_the_docs_describe_the_option_and_the_command():
    doc = (Path(__file__).resolve().parents[2] / "docs" / "sim.md").read_text()
    assert "## Parts on I2C and SPI" in doc
    assert re.search(r"^\| `-I KIND@ADDR` \|", doc, re.M)
    assert re.search(r"^\| `part` / `part ID info`", doc, re.M)
