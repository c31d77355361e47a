"""The International Standard Atmosphere's troposphere (ISO 2533, 0 to
11 km): pressure, temperature and density at a geopotential altitude."""

from __future__ import annotations

G0 = 9.80665  # m/s², standard gravity
R_AIR = 287.05287  # J/(kg·K), specific gas constant of dry air
T0 = 288.15  # K at sea level
P0 = 101325.0  # Pa at sea level
LAPSE = 0.0065  # K/m
EXPONENT = G0 / (R_AIR * LAPSE)  # 5.25588
TOP = 11000.0  # m: the troposphere's top; the model stops there


def temperature(h: float) -> float:
    """K at `h` m above sea level."""
    return T0 - LAPSE * min(h, TOP)


def pressure(h: float) -> float:
    """Pa at `h` m above sea level: P0 (T/T0)^(g0/(R L))."""
    return P0 * (temperature(h) / T0) ** EXPONENT


def density(h: float) -> float:
    """kg/m³ at `h` m above sea level: p / (R T)."""
    return pressure(h) / (R_AIR * temperature(h))


def altitude(p: float) -> float:
    """The altitude (m above sea level) whose standard pressure is `p` Pa."""
    return T0 / LAPSE * (1.0 - (p / P0) ** (1.0 / EXPONENT))


def density_fn(pad_altitude: float):
    """A fast density(h above the pad) for the integrator: the exact ISA
    formula, with its constants folded."""
    t_pad = T0 - LAPSE * pad_altitude
    k = P0 / (R_AIR * T0 ** EXPONENT)
    e = EXPONENT - 1.0

    def rho(h: float) -> float:
        t = t_pad - LAPSE * h
        return k * t ** e if t > 0 else 0.0
    return rho

