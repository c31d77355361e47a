"""A physical value as the firmware reads it through an analog sensor and
the MCU's converter, exactly: the sensor's output volts through the inverse
of the project's `.aio` calibration (`element = volts * scale + offset`, so
`volts = (value - offset) / scale`), clipped at the rails (0..Vref: the
sensor's output saturates), converted as a real AVR ADC converts,
`counts = floor(V * 2^bits / Vref)` at most `2^bits - 1`, with the board's
`[adc] bits` and `vref`. The firmware then reads
`counts * gain + offset`, gain = scale * Vref / (2^bits - 1) folded on the
host (`reading`: with the board's arithmetic `real`, bit for bit the
firmware's, fswkit.autocode.iotables.analog_value).

The simulated board takes an input in whole millivolts and converts it as
`floor(mV * (2^bits - 1) / Vref_mV)` (simavr); `millivolts(counts)` is the
smallest input that gives exactly `counts` there, so the simulated MCU reads
the count the real one would. Used by tape replays (fswkit.plant.tape_replay).

A digital part of the `.sns` tables (`PartFeed`, below) is fed the other
way: a physical value becomes the raw counts the part's result registers
hold, by its datasheet's compensation run backwards with its calibration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fswkit.autocode.iotables import analog_gain, analog_value
from fswkit.autocode.numeric import REALS
from fswkit.autocode.numtext import integer


@dataclass(frozen=True)
class AnalogSensor:
    """One analog input channel: the `.aio` calibration of its element and
    the board's converter."""

    pin: str  # as the .aio names it ("A0")
    element: str
    scale: float  # element = volts * scale + offset
    offset: float
    vref: float  # volts
    bits: int
    real: str | None = None  # the board's arithmetic ("f32", "f64"); None: the ideal, in binary64

    def __post_init__(self):
        if not self.scale or not math.isfinite(self.scale):
            raise ValueError(f"{self.pin} (`{self.element}`): a calibration scale of {self.scale!r} has no inverse")

    @property
    def full(self) -> int:
        """The largest count, 2^bits - 1."""
        return (1 << self.bits) - 1

    def volts(self, value: float) -> float:
        """The sensor's output for a physical value, clipped at the rails."""
        v = (value - self.offset) / self.scale
        return min(max(v, 0.0), self.vref)

    def counts(self, volts: float) -> int:
        """The converter's result for volts at its input (clipped to 0..Vref)."""
        v = min(max(volts, 0.0), self.vref)
        return min(int(math.floor(v * (1 << self.bits) / self.vref)), self.full)

    def count_of(self, value: float) -> int:
        """value -> volts -> counts."""
        return self.counts(self.volts(value))

    def reading(self, counts: int) -> float:
        """What the firmware's element holds for a count: with `real`, its
        multiply-add in the board's arithmetic, bit for bit
        (iotables.analog_value); without, the calibration in binary64."""
        if self.real is None:
            return counts * self.vref / self.full * self.scale + self.offset
        r = REALS[self.real]
        gain = analog_gain(self.scale, self.vref, self.bits, r)
        return analog_value(counts, gain, r.literal(repr(self.offset)), r)

    def millivolts(self, counts: int) -> int:
        """The whole millivolts that the simulated converter turns into
        exactly `counts`: ceil(counts * Vref_mV / (2^bits - 1))."""
        vref_mv = int(round(self.vref * 1000))
        return -(-counts * vref_mv // self.full)

    @property
    def lsb(self) -> float:
        """One count in the element's units (its magnitude)."""
        return abs(self.vref / self.full * self.scale)

    def range(self) -> tuple[float, float]:
        """The physical values between the rails (low, high)."""
        a, b = self.offset, self.vref * self.scale + self.offset
        return (min(a, b), max(a, b))


def from_channel(channel, board) -> AnalogSensor:
    """The sensor of a project's analog input channel (autocode's Channel)."""
    return AnalogSensor(channel.pin, channel.element.name, float(channel.scale), float(channel.offset),
                        float(board.adc_vref), int(board.adc_bits), board.real)


# ---- digital parts (a `.sns` table's rows) ---------------------------------------------
# A digital sensor part fed physical values: the raw counts its result
# registers must hold for the firmware's driver to read those values, by the
# datasheet's own compensation run backwards (fswkit.sim.parts' inverse
# helpers) with the part's calibration as the simulated board holds it
# (`SimBoard.part_calibration`).

BAROMETERS = ("bmp280", "ms5611")
ACCELEROMETERS = ("adxl345", "mpu6050")
AXES = ("x", "y", "z")


def part_name(sensor) -> str:
    """A part as the `.sns` table and the health frame name it: `bmp280@0x76`, `adxl345@spi:7`."""
    if sensor.bus == "spi":
        return f"{sensor.part}@spi:{sensor.cs_pin}"
    return f"{sensor.part}@0x{sensor.address:02x}"


def harness_id(sensor, board) -> int | str:
    """The part's name on the simulated board: its I2C address, or its SPI
    chip select's port pin (`"B1"` for the Uno's pin 9), from the board's
    pin table (fswkit.sim.board.pin_map)."""
    if sensor.bus != "spi":
        return int(sensor.address)
    from fswkit.sim.board import pin_map, sim_board

    port, bit = pin_map(sim_board(board)).digital[sensor.cs_pin]
    return f"{port}{bit}"


def board_parts(sensors, board) -> list[tuple[str, int | str]]:
    """`SimBoard(parts=...)` for an application's sensor parts."""
    return [(s.part, harness_id(s, board)) for s in sensors]


def find_part(sensors, text: str, kinds: tuple[str, ...]):
    """The application's part that plant.toml / tape.toml names: `bmp280`
    (the only one of its kind), `bmp280@0x76`, `adxl345@spi:7` (also
    `@i2c:0x53`); (sensor, None) or (None, the reason)."""
    kind, at, where = text.strip().partition("@")
    kind = kind.strip().lower()
    if kind not in kinds:
        return None, f"\"{text}\": a part of kind {' or '.join(kinds)} (\"{kinds[0]}@0x76\"), not `{kind}`"
    same = [s for s in sensors if s.part == kind]
    listed = ", ".join(part_name(s) for s in sensors) or "none"
    if not at:
        if len(same) == 1:
            return same[0], None
        if not same:
            return None, f"the project's sensor tables have no {kind} (its parts: {listed})"
        return None, f"the project has {len(same)} {kind} parts ({', '.join(part_name(s) for s in same)}): name one"
    where = where.strip().lower()
    bus, colon, rest = where.partition(":")
    if colon and bus == "spi":
        pin = integer(rest)
        hit = [s for s in same if s.bus == "spi" and s.cs_pin == pin]
    else:
        pin = addr = integer(rest if colon and bus == "i2c" else where, hex_ok=True)
        hit = [s for s in same if s.bus == "i2c" and s.address == addr]
    if pin is None:  # plain ASCII digits, an address also 0x and hex digits (fswkit.autocode.numtext)
        return None, (f"\"{text}\": expected KIND@ADDRESS (\"{kind}@0x76\") or KIND@spi:PIN "
                      f"(\"{kind}@spi:7\")")
    if not hit:
        return None, f"\"{text}\" is not in the project's sensor tables (its parts: {listed})"
    return hit[0], None


def _walk_nearest(f, target: float, guess: int, lo: int, hi: int, increasing: bool,
                  seen: dict[int, float] | None = None) -> int:
    """parts._nearest_search's answer, found by galloping from `guess`
    (steps 1, 2, 4, ... until the answer is bracketed, then bisection): a
    few evaluations when the guess is close. `seen`: f's values already
    known (x -> f(x)), kept and added to (f is a pure function)."""
    if seen is None:
        seen = {}
    get = seen.get
    # each x evaluated once (the last comparison reuses the search's values); an x "reaches" when f(x) is at
    # or past the target (the full search's condition: its answer is the first x that reaches)
    x = min(max(guess, lo), hi)
    v = get(x)
    if v is None:
        v = seen[x] = f(x)
    if lo < x < hi:  # the answer next to the guess (as a rule): what the walk below finds then, in one look
        if (v >= target) if increasing else (v <= target):
            v0 = get(x - 1)
            if v0 is None:
                v0 = seen[x - 1] = f(x - 1)
            if not ((v0 >= target) if increasing else (v0 <= target)):  # x is the first that reaches
                return x - 1 if abs(v0 - target) <= abs(v - target) else x
        else:
            v1 = get(x + 1)
            if v1 is None:
                v1 = seen[x + 1] = f(x + 1)
            if (v1 >= target) if increasing else (v1 <= target):  # x + 1 is
                return x if abs(v - target) <= abs(v1 - target) else x + 1
    step = 1
    if (v >= target) if increasing else (v <= target):  # the first reaching x is at or below x
        b = x
        while True:
            a = max(lo, b - step)
            if a == lo:
                break
            v = get(a)
            if v is None:
                v = seen[a] = f(a)
            if not ((v >= target) if increasing else (v <= target)):
                break
            b, step = a, step * 2
        if a == lo:
            v = get(lo)
            if v is None:
                v = seen[lo] = f(lo)
            if (v >= target) if increasing else (v <= target):
                b = lo
    else:  # above x
        a = x
        while True:
            b = min(hi, a + step)
            if b == hi:
                break
            v = get(b)
            if v is None:
                v = seen[b] = f(b)
            if (v >= target) if increasing else (v <= target):
                break
            a, step = b, step * 2
    while a < b:  # the first reaching x in (a, b], `a` not reaching (or lo)
        m = (a + b) // 2
        v = get(m)
        if v is None:
            v = seen[m] = f(m)
        if (v >= target) if increasing else (v <= target):
            b = m
        else:
            a = m + 1
    x = b
    if x > lo:
        v0 = get(x - 1)
        if v0 is None:
            v0 = seen[x - 1] = f(x - 1)
        v = get(x)
        if v is None:
            v = seen[x] = f(x)
        if abs(v0 - target) <= abs(v - target):
            return x - 1
    return x


class _Inverse:
    """A monotonic integer function's nearest inverse, remembering its last
    answers: a plant step's value is near the last one, so the answer is a
    few steps from a secant guess (the same answer as a full search).

    `whole`: f is always the same function and its values are whole
    numbers. The answer then depends on the target only through
    ceil(2 x target) (floor when f falls): the first x whose f(x) reaches
    the target is the first that reaches its ceiling (floor), and the
    nearer of it and its predecessor is decided by 2 x target against the
    whole number f(x - 1) + f(x). Answers are kept by that number: a
    temperature, whose counts step in plateaus a whole 0.01 degC wide, moves
    across one in several plant steps, and the walk is done once for it."""

    def __init__(self, lo: int, hi: int, increasing: bool, whole: bool = False):
        self.lo, self.hi, self.increasing = lo, hi, increasing
        self.last: tuple[float, int] | None = None
        self.slope: float | None = None  # counts per unit of target
        self.known: dict[int, int] | None = {} if whole else None  # ceil(2 x target) (floor) -> the answer

    def __call__(self, f, target: float, full, seen: dict | None = None) -> int:
        """The answer for `target`; `full()` the full search's (the first time); `seen`: f's values known
        (x -> f(x)), kept and added to, as _walk_nearest's."""
        known = self.known
        if known is not None and math.isfinite(target):
            key = math.ceil(2.0 * target) if self.increasing else math.floor(2.0 * target)
            x = known.get(key)
            if x is None:
                x = known[key] = self._search(f, target, full, seen)
            return x
        return self._search(f, target, full, seen)

    def _search(self, f, target: float, full, seen: dict | None = None) -> int:
        x = None
        if self.last is not None and self.slope is not None:
            t0, x0 = self.last
            x = _walk_nearest(f, target, int(round(x0 + (target - t0) * self.slope)), self.lo, self.hi,
                              self.increasing, seen)
        else:
            x = full()
        if self.last is not None and target != self.last[0] and x != self.last[1]:
            s = (x - self.last[1]) / (target - self.last[0])
            if s and (s > 0) == self.increasing:
                self.slope = s
        self.last = (target, x)
        return x


class PartFeed:
    """One part of the application as the plant or a tape feeds it: `raw`
    turns physical values into the part's raw counts (`SimBoard.part_raw`
    names), with the calibration the board holds for it.

    Barometers: pressure (Pa) and temperature (°C) → bmp280 adc_P, adc_T
    (the temperature first, its t_fine then the pressure's, by the 64-bit
    formula the driver uses) or ms5611 D2, D1 (second-order compensation
    as the driver applies it). Accelerometers: x, y, z (g; an axis not
    given reads 0 g) → adxl345 counts at its `range` in full resolution,
    right-justified (3.9 mg a count), or mpu6050 counts at its `range`
    (16384 / 2^AFS_SEL a g) and its temperature register for `temperature`;
    counts round to the nearest and stop at the output's limits."""

    def __init__(self, sensor, where: int | str, calibration: bytes | None):
        from . import parts as P

        self._P = P  # (`raw` runs every plant step: the module looked up once)
        self.sensor, self.where, self.part = sensor, where, sensor.part
        self.name = part_name(sensor)
        self.settings = dict(sensor.settings)
        self.calib = None
        if self.part == "bmp280":
            self.calib = P.bmp280_parse_calib(calibration)
        elif self.part == "ms5611":
            words = [int.from_bytes(calibration[i:i + 2], "big") for i in range(0, 16, 2)]
            self.calib = P.Ms5611Calib(*words[1:7])
        self._t: tuple[float, int, int] | None = None  # (°C, raw temperature, t_fine / D2)
        # the raw temperature (BMP280 adc_T, MS5611 D2): the temperature changes at every plant step
        # (its compensation, BMP280 T or MS5611 TEMP, is in whole 0.01 degC: `whole`)
        self._temp = _Inverse(0, 0xFFFFF if self.part == "bmp280" else 0xFFFFFF, True, whole=True)
        self._p = _Inverse(0, 0xFFFFF if self.part == "bmp280" else 0xFFFFFF, self.part != "bmp280")
        # the BMP280's compensations are pure functions of the raw counts (and t_fine): each raw count's
        # value is worked out once (a flight's temperatures span a few hundred adc_T; its pressures, for
        # one t_fine at a time, the few counts around the last answer)
        self._t_of: dict[int, int] = {}  # adc_T -> bmp280_compensate_T's T
        self._t_fine: dict[int, int] = {}  # adc_T -> bmp280_compensate_T's t_fine
        self._p_of: dict[int, int] = {}  # adc_P -> bmp280_compensate_P64 at t_fine self._p_tf
        self._p_tf: int | None = None
        self._p_fn = None  # adc_P -> bmp280_compensate_P64 at self._p_tf (parts.bmp280_P64_fn)
        self._accel_forms: dict = {}  # the accelerometer's range setting -> _accel_form's answer

    def _bmp280_T(self, adc_T: int) -> int:
        """bmp280_compensate_T's T for adc_T (its t_fine kept in _t_fine)."""
        T, self._t_fine[adc_T] = self._P.bmp280_compensate_T(self.calib, adc_T)
        return T

    @property
    def data_format(self) -> int:
        """The ADXL345's DATA_FORMAT for its settings: full resolution and the range."""
        return 0x08 | {2: 0, 4: 1, 8: 2, 16: 3}[self.settings.get("range", 16)]

    def raw(self, pressure: float | None = None, temperature: float | None = None,
            x: float = 0.0, y: float = 0.0, z: float = 0.0) -> dict[str, int]:
        P = self._P

        if self.part in BAROMETERS:
            out = {}
            t_c = 15.0 if temperature is None else float(temperature)
            if self._t is None or self._t[0] != t_c:
                if self.part == "bmp280":
                    c = self.calib
                    adc_T = self._temp(self._bmp280_T, t_c * 100.0, lambda: P.bmp280_adc_T_for(c, t_c), self._t_of)
                    if adc_T not in self._t_fine:
                        self._bmp280_T(adc_T)
                    self._t = (t_c, adc_T, self._t_fine[adc_T])
                else:
                    c = self.calib
                    self._t = (t_c, self._temp(lambda d: P.ms5611_compensate(c, 0, d, True).TEMP, t_c * 100.0,
                                               lambda: P.ms5611_D2_for(c, t_c)), 0)
            if self.part == "bmp280":
                out["adc_T"] = self._t[1]
                if pressure is not None:
                    c, tf = self.calib, self._t[2]
                    if tf != self._p_tf:  # (and t_fine's part of the formula, worked out once for it)
                        self._p_tf, self._p_of = tf, {}
                        self._p_fn = P.bmp280_P64_fn(c, P.bmp280_P64_terms(c, tf))
                    pa = float(pressure)
                    out["adc_P"] = self._p(self._p_fn, pa * 256.0, lambda: P.bmp280_adc_P_for(c, pa, tf), self._p_of)
            else:
                out["D2"] = d2 = self._t[1]
                if pressure is not None:
                    c = self.calib
                    out["D1"] = self._p(lambda d: P.ms5611_compensate(c, d, d2, True).P, float(pressure),
                                        lambda: P._nearest_search(lambda d: P.ms5611_compensate(c, d, d2, True).P,
                                                                     float(pressure), 0, 0xFFFFFF, True))
            return out
        per, lo, hi, names = self._accel_form()
        out = {}
        for name, g in zip(names, (x, y, z)):
            # an axis at 0 g (those the plant does not feed) reads 0 counts, the formula's answer (lo < 0 < hi)
            out[name] = 0 if g == 0 else min(max(int(round(float(g) / per)), lo), hi)
        if self.part == "mpu6050" and temperature is not None:
            out["temp"] = min(max(int(round((float(temperature) - 36.53) * 340.0)), -32768), 32767)
        return out

    def _accel_form(self) -> tuple[float, int, int, tuple[str, str, str]]:
        """An accelerometer's (g a count, least count, greatest count, the axes' raw names) for its
        settings, worked out once for them (`raw` runs every plant step)."""
        key = self.settings.get("range", 16)
        form = self._accel_forms.get(key)
        if form is None:
            P = self._P
            if self.part == "adxl345":
                fmt = self.data_format
                per, bits = P.adxl345_g_per_count(fmt), P.adxl345_bits(fmt)
                form = (per, -(1 << (bits - 1)), (1 << (bits - 1)) - 1, ("x", "y", "z"))
            else:
                afs = {2: 0, 4: 1, 8: 2, 16: 3}[key]
                form = (P.mpu6050_g_per_count(afs), -32768, 32767, ("ax", "ay", "az"))
            form = self._accel_forms[key] = form
        return form
