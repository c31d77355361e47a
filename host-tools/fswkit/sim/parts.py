"""Digital sensor parts as the firmware converts them, in Python integers:
the forward formulas mirror firmware/src/fsw_parts.cpp step for step (the
datasheets' integer arithmetic, shifts and widths, with the same
two's-complement wrap where a corrupt calibration would overflow the width
the datasheet names), and the inverse helpers a simulated part uses: for a
physical pressure or temperature, the raw counts the part would report.

Sources (docs/sensors.md): Bosch BST-BMP280-DS001 3.11.3 and 8.2; TE
Connectivity MS5611-01BA03 "Pressure and temperature calculation", "Second
order temperature compensation" and AN520 (PROM CRC-4); Analog Devices
ADXL345 Table 1 and register 0x31; InvenSense RM-MPU-6000A 4.17 and 4.18.

Python's `>>` on a negative int is the floor shift the firmware's arithmetic
shifts are; C's `/` truncates toward zero (`_cdiv`).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

__all__ = [
    "Bmp280Calib", "bmp280_parse_calib", "bmp280_parse_raw", "bmp280_raw_bytes", "bmp280_calib_bytes",
    "bmp280_compensate_T", "bmp280_compensate_P64", "bmp280_P64_terms", "bmp280_P64_of", "bmp280_P64_fn",
    "bmp280_compensate_P32", "bmp280_adc_T_for", "bmp280_adc_P_for",
    "Ms5611Calib", "Ms5611Result", "ms5611_crc4", "ms5611_prom_words", "ms5611_parse_prom", "ms5611_compensate",
    "ms5611_D2_for", "ms5611_D1_for",
    "adxl345_bits", "adxl345_counts", "adxl345_g_per_count", "adxl345_raw_bytes",
    "mpu6050_accel_counts", "mpu6050_g_per_count", "mpu6050_temp_c", "mpu6050_raw_bytes",
    "BMP280_EXAMPLE", "MS5611_EXAMPLE",
]


# ---- fixed-width two's complement ------------------------------------------------

def _s32(x: int) -> int:
    x &= 0xFFFFFFFF
    return x - (1 << 32) if x & 0x80000000 else x


def _u32(x: int) -> int:
    return x & 0xFFFFFFFF


def _s64(x: int) -> int:
    x &= 0xFFFFFFFFFFFFFFFF
    return x - (1 << 64) if x & 0x8000000000000000 else x


def _cdiv(n: int, d: int) -> int:
    """C's integer division: truncation toward zero."""
    q = abs(n) // abs(d)
    return q if (n >= 0) == (d >= 0) else -q


def _s16(x: int) -> int:
    x &= 0xFFFF
    return x - 0x10000 if x & 0x8000 else x


# ---- Bosch BMP280 ------------------------------------------------------------------

@dataclass(frozen=True)
class Bmp280Calib:
    """Trimming parameters (datasheet 3.11.2, Table 17)."""

    dig_T1: int
    dig_T2: int
    dig_T3: int
    dig_P1: int
    dig_P2: int
    dig_P3: int
    dig_P4: int
    dig_P5: int
    dig_P6: int
    dig_P7: int
    dig_P8: int
    dig_P9: int


_CALIB_FMT = "<HhhHhhhhhhhh"  # 0x88..0x9F, LSB first; T1 and P1 unsigned


def bmp280_parse_calib(data: bytes) -> Bmp280Calib:
    return Bmp280Calib(*struct.unpack(_CALIB_FMT, bytes(data[:24])))


def bmp280_calib_bytes(c: Bmp280Calib) -> bytes:
    return struct.pack(_CALIB_FMT, c.dig_T1, c.dig_T2, c.dig_T3, c.dig_P1, c.dig_P2, c.dig_P3, c.dig_P4, c.dig_P5,
                       c.dig_P6, c.dig_P7, c.dig_P8, c.dig_P9)


def bmp280_parse_raw(data: bytes) -> tuple[int, int]:
    """(adc_P, adc_T) from the 6 bytes of 0xF7..0xFC (20 bits each)."""
    b = bytes(data[:6])
    return (b[0] << 12 | b[1] << 4 | b[2] >> 4, b[3] << 12 | b[4] << 4 | b[5] >> 4)


def bmp280_raw_bytes(adc_P: int, adc_T: int) -> bytes:
    """The 6 bytes of 0xF7..0xFC holding adc_P and adc_T (xlsb's low nibble 0)."""
    return bytes([adc_P >> 12 & 0xFF, adc_P >> 4 & 0xFF, (adc_P & 0xF) << 4,
                  adc_T >> 12 & 0xFF, adc_T >> 4 & 0xFF, (adc_T & 0xF) << 4])


def bmp280_compensate_T(c: Bmp280Calib, adc_T: int) -> tuple[int, int]:
    """(T in 0.01 degC, t_fine): datasheet 3.11.3 bmp280_compensate_T_int32."""
    T1, T2, T3 = c.dig_T1, c.dig_T2, c.dig_T3
    var1 = _s32(_s32((adc_T >> 3) - (T1 << 1)) * T2) >> 11
    d = _s32((adc_T >> 4) - T1)
    var2 = _s32((_s32(d * d) >> 12) * T3) >> 14
    t_fine = _s32(var1 + var2)
    return _s32(_s32(t_fine * 5) + 128) >> 8, t_fine


def bmp280_compensate_P64(c: Bmp280Calib, adc_P: int, t_fine: int) -> int:
    """Pa in unsigned Q24.8: datasheet 3.11.3 bmp280_compensate_P_int64."""
    return bmp280_P64_of(c, adc_P, bmp280_P64_terms(c, t_fine))


def bmp280_P64_terms(c: Bmp280Calib, t_fine: int) -> tuple[int, int]:
    """(var1, var2) of bmp280_compensate_P_int64 before adc_P enters: they
    depend on t_fine alone, so a search over adc_P works them out once."""
    var1 = t_fine - 128000
    var2 = _s64(_s64(var1 * var1) * c.dig_P6)
    var2 = _s64(var2 + _s64(_s64(var1 * c.dig_P5) << 17))
    var2 = _s64(var2 + _s64(c.dig_P4 << 35))
    var1 = _s64((_s64(_s64(var1 * var1) * c.dig_P3) >> 8) + _s64(_s64(var1 * c.dig_P2) << 12))
    var1 = _s64(_s64((1 << 47) + var1) * c.dig_P1) >> 33
    return var1, var2


def bmp280_P64_of(c: Bmp280Calib, adc_P: int, terms: tuple[int, int]) -> int:
    """bmp280_compensate_P_int64 from adc_P on, with `terms` =
    bmp280_P64_terms(c, t_fine)."""
    var1, var2 = terms
    if var1 == 0:
        return 0
    p = 1048576 - adc_P
    p = _s64(_cdiv(_s64(_s64(_s64(p << 31) - var2) * 3125), var1))
    var1 = _s64(_s64(c.dig_P9 * (p >> 13)) * (p >> 13)) >> 25
    var2 = _s64(c.dig_P8 * p) >> 19
    p = _s64((_s64(_s64(p + var1) + var2) >> 8) + _s64(c.dig_P7 << 4))
    return p & 0xFFFFFFFF


def bmp280_P64_fn(c: Bmp280Calib, terms: tuple[int, int]):
    """adc_P -> bmp280_P64_of(c, adc_P, terms), the same value for every
    adc_P in 0..0xFFFFF, cheaper: when no intermediate of the formula can
    leave the signed 64-bit range for any of those adc_P at these `terms`
    (bounds worked out here once), the formula without its wrapping, its
    constants folded; else bmp280_P64_of itself."""
    var1, var2 = terms
    if var1 <= 0:
        return lambda a: bmp280_P64_of(c, a, terms)
    P7, P8, P9 = c.dig_P7 << 4, c.dig_P8, c.dig_P9
    lim = 1 << 63
    # (p << 31) - var2 for p = 1048576 - adc_P in 1..2^20 rises with p: its most negative and most positive
    n = max(abs((1 << 31) - var2), abs((1048576 << 31) - var2))
    q = n * 3125 // var1  # |p| after the division at most
    s = (q >> 13) + 1  # |p >> 13| at most
    if n * 3125 >= lim or abs(P9) * s * s >= lim or abs(P8) * q >= lim or \
            q + (abs(P9) * s * s >> 25) + (abs(P8) * q >> 19) + abs(P7) + 2 >= lim:
        return lambda a: bmp280_P64_of(c, a, terms)
    # every intermediate is within range: _s64 is the identity on each (the division truncates toward
    # zero, as C's)

    def of(adc_P: int) -> int:
        n = (((1048576 - adc_P) << 31) - var2) * 3125
        p = n // var1 if n >= 0 else -(-n // var1)
        s = p >> 13
        return (((p + (P9 * s * s >> 25) + (P8 * p >> 19)) >> 8) + P7) & 0xFFFFFFFF
    return of


def bmp280_compensate_P32(c: Bmp280Calib, adc_P: int, t_fine: int) -> int:
    """Whole Pa: datasheet 8.2 bmp280_compensate_P_int32."""
    var1 = _s32((t_fine >> 1) - 64000)
    q = var1 >> 2
    qq = _s32(q * q)
    var2 = _s32((qq >> 11) * c.dig_P6)
    var2 = _s32(var2 + _s32(_s32(var1 * c.dig_P5) << 1))
    var2 = _s32((var2 >> 2) + _s32(c.dig_P4 << 16))
    var1 = _s32((_s32(c.dig_P3 * (qq >> 13)) >> 3) + (_s32(c.dig_P2 * var1) >> 1)) >> 18
    var1 = _s32(_s32(32768 + var1) * c.dig_P1) >> 15
    if var1 == 0:
        return 0
    p = _u32(_u32(_s32(1048576 - adc_P)) - _u32(var2 >> 12)) * 3125 & 0xFFFFFFFF
    if p < 0x80000000:
        p = _u32(p << 1) // _u32(var1)
    else:
        p = _u32((p // _u32(var1)) * 2)
    var1 = _s32(c.dig_P9 * _s32(_u32((p >> 3) * (p >> 3)) >> 13)) >> 12
    var2 = _s32(_s32(p >> 2) * c.dig_P8) >> 13
    return _u32(_s32(p) + (_s32(_s32(var1 + var2) + c.dig_P7) >> 4))


def _nearest_search(f, target: float, lo: int, hi: int, increasing: bool) -> int:
    """The x in [lo, hi] whose f(x) is nearest `target`, f monotonic (not
    strictly: integer outputs repeat) in the given direction; ties to the
    smaller x. Binary search for the first x with f(x) >= target (<= when
    decreasing), then the better of it and its predecessor."""
    a, b = lo, hi
    while a < b:
        m = (a + b) // 2
        v = f(m)
        if (v >= target) if increasing else (v <= target):
            b = m
        else:
            a = m + 1
    best = a
    if a > lo and abs(f(a - 1) - target) <= abs(f(a) - target):
        best = a - 1
    return best


def bmp280_adc_T_for(c: Bmp280Calib, celsius: float) -> int:
    """The 20-bit adc_T whose compensated temperature (0.01 degC) is nearest
    `celsius` (T rises with adc_T for a real part's dig_T2 > 0)."""
    return _nearest_search(lambda a: bmp280_compensate_T(c, a)[0], celsius * 100.0, 0, 0xFFFFF, True)


def bmp280_adc_P_for(c: Bmp280Calib, pascal: float, t_fine: int, formula: int = 64) -> int:
    """The 20-bit adc_P whose compensated pressure, at `t_fine`, is nearest
    `pascal`, by the 64-bit (Q24.8) or the 32-bit (whole Pa) formula; the
    pressure falls as adc_P rises."""
    if formula == 64:
        terms = bmp280_P64_terms(c, t_fine)
        return _nearest_search(lambda a: bmp280_P64_of(c, a, terms), pascal * 256.0, 0, 0xFFFFF, False)
    return _nearest_search(lambda a: bmp280_compensate_P32(c, a, t_fine), pascal, 0, 0xFFFFF, False)


# ---- TE Connectivity MS5611-01BA03 -------------------------------------------------

@dataclass(frozen=True)
class Ms5611Calib:
    C1: int
    C2: int
    C3: int
    C4: int
    C5: int
    C6: int


@dataclass(frozen=True)
class Ms5611Result:
    dT: int
    TEMP: int  # 0.01 degC
    OFF: int
    SENS: int
    P: int  # 0.01 mbar
    T2: int = 0
    OFF2: int = 0
    SENS2: int = 0


def ms5611_crc4(words: list[int]) -> int:
    """AN520's crc4 over the 8 PROM words (word 7's low byte taken as 0)."""
    w = [x & 0xFFFF for x in words[:8]]
    w[7] &= 0xFF00
    rem = 0
    for i in range(16):
        rem ^= (w[i >> 1] & 0x00FF) if i & 1 else (w[i >> 1] >> 8)
        for _ in range(8):
            rem = ((rem << 1) ^ 0x3000) if rem & 0x8000 else (rem << 1)
            rem &= 0xFFFF
    return (rem >> 12) & 0xF


def ms5611_prom_words(c: Ms5611Calib, word0: int = 0, serial: int = 0) -> list[int]:
    """A PROM holding `c`, with word 0 and word 7's high 12 bits as given and
    word 7's low 4 bits the AN520 CRC."""
    w = [word0 & 0xFFFF, c.C1, c.C2, c.C3, c.C4, c.C5, c.C6, (serial << 4) & 0xFFF0]
    w[7] |= ms5611_crc4(w)
    return w


def ms5611_parse_prom(words: list[int]) -> Ms5611Calib | None:
    """C1..C6, or None as the firmware refuses the PROM (CRC, all 0, all 1s)."""
    w = [x & 0xFFFF for x in words[:8]]
    if all(x == 0 for x in w) or all(x == 0xFFFF for x in w) or ms5611_crc4(w) != w[7] & 0xF:
        return None
    return Ms5611Calib(*w[1:7])


def ms5611_compensate(c: Ms5611Calib, D1: int, D2: int, second_order: bool = True) -> Ms5611Result:
    """The datasheet's first-order compensation, and the second order (TEMP <
    20 degC, < -15 degC) when asked; divisions by 2^n are floor shifts."""
    D1 &= 0xFFFFFF
    D2 &= 0xFFFFFF
    dT = D2 - (c.C5 << 8)
    TEMP = 2000 + ((dT * c.C6) >> 23)
    OFF = (c.C2 << 16) + ((c.C4 * dT) >> 7)
    SENS = (c.C1 << 15) + ((c.C3 * dT) >> 8)
    T2 = OFF2 = SENS2 = 0
    if second_order and TEMP < 2000:
        T2 = (dT * dT) >> 31
        lo = (TEMP - 2000) ** 2
        OFF2 = (5 * lo) >> 1
        SENS2 = (5 * lo) >> 2
        if TEMP < -1500:
            vlo = (TEMP + 1500) ** 2
            OFF2 += 7 * vlo
            SENS2 += (11 * vlo) >> 1
        TEMP -= T2
        OFF -= OFF2
        SENS -= SENS2
    P = (((D1 * SENS) >> 21) - OFF) >> 15
    return Ms5611Result(dT, TEMP, OFF, SENS, P, T2, OFF2, SENS2)


def ms5611_D2_for(c: Ms5611Calib, celsius: float, second_order: bool = True) -> int:
    """The 24-bit D2 whose TEMP (0.01 degC) is nearest `celsius`."""
    return _nearest_search(lambda d: ms5611_compensate(c, 0, d, second_order).TEMP, celsius * 100.0, 0, 0xFFFFFF,
                           True)


def ms5611_D1_for(c: Ms5611Calib, mbar: float, D2: int, second_order: bool = True) -> int:
    """The 24-bit D1 whose P (0.01 mbar), at temperature reading D2, is
    nearest `mbar` (P rises with D1 when SENS > 0)."""
    return _nearest_search(lambda d: ms5611_compensate(c, d, D2, second_order).P, mbar * 100.0, 0, 0xFFFFFF, True)


# ---- Analog Devices ADXL345 ---------------------------------------------------------

def adxl345_bits(data_format: int) -> int:
    return 10 + (data_format & 3) if data_format & 0x08 else 10


def adxl345_counts(data: bytes, data_format: int) -> tuple[int, int, int]:
    shift = 16 - adxl345_bits(data_format) if data_format & 0x04 else 0
    b = bytes(data[:6])
    return tuple(_s16(b[2 * i] | b[2 * i + 1] << 8) >> shift for i in range(3))  # type: ignore[return-value]


def adxl345_g_per_count(data_format: int) -> float:
    """2^-8 g (3.9 mg/LSB typ., 256 LSB/g) in full resolution; 2^(range - 8) in 10-bit mode."""
    return 2.0 ** -8 if data_format & 0x08 else 2.0 ** ((data_format & 3) - 8)


def adxl345_raw_bytes(xyz: tuple[int, int, int], data_format: int) -> bytes:
    """DATAX0..DATAZ1 for these counts (each within the mode's bits)."""
    shift = 16 - adxl345_bits(data_format) if data_format & 0x04 else 0
    return b"".join(struct.pack("<H", (v << shift) & 0xFFFF) for v in xyz)


# ---- InvenSense MPU-6050 ---------------------------------------------------------

def mpu6050_accel_counts(data: bytes) -> tuple[int, int, int]:
    return struct.unpack(">hhh", bytes(data[:6]))  # type: ignore[return-value]


def mpu6050_g_per_count(afs_sel: int) -> float:
    return 2.0 ** ((afs_sel & 3) - 14)  # 16384, 8192, 4096, 2048 LSB/g


def mpu6050_temp_c(temp_out: int) -> float:
    """TEMP_OUT / 340 + 36.53 in binary32, quotient then sum rounded (the
    firmware's order), returned as the binary32 value."""
    def f32(x: float) -> float:
        return struct.unpack("<f", struct.pack("<f", x))[0]
    # binary32 quotient and sum are the exact results rounded once; binary64
    # holds both operands exactly and its own rounding of a quotient/sum of
    # two binary32 values never lands on a binary32 tie the other way
    # (2p + 2 <= 53), so rounding through binary64 gives the same bits.
    return f32(f32(float(temp_out) / f32(340.0)) + f32(36.53))


def mpu6050_raw_bytes(xyz: tuple[int, int, int]) -> bytes:
    return struct.pack(">hhh", *xyz)


# ---- the datasheets' worked examples ---------------------------------------------------

# BMP280 datasheet (calculation example): T = 25.08 degC (t_fine 128422);
# the double-precision formula gives 100653.27 Pa, the 64-bit integer one
# 25767233 / 256 = 100653.25 Pa, the 32-bit one 100653 Pa.
BMP280_EXAMPLE = (Bmp280Calib(27504, 26435, -1000, 36477, -10685, 3024, 2855, 140, -7, 15500, -14600, 6000),
                  415148, 519888)
# MS5611-01BA03 datasheet (example / typical column): dT 2366, TEMP 2007,
# OFF 2420281617, SENS 1315097036, P 100009.
MS5611_EXAMPLE = (Ms5611Calib(40127, 36924, 23317, 23282, 33464, 28312), 9085466, 8569150)
