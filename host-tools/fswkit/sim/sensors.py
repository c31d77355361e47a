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
the count the real one would. Used by tape replays (fswkit.sim.tape_replay).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fswkit.autocode.iotables import analog_gain, analog_value
from fswkit.autocode.numeric import REALS


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
