"""Dispersion files (`fsw sim PROJECT --plant rocket --runs N --dispersion
FILE.toml`): how much each flight of a study differs from plant.toml's
nominal one. TOML checked against a schema as plant.toml is
(fswkit.plant.params: unknown keys, wrong types and out-of-range values
located at their line); every key may be left out (no dispersion of that
kind). docs/sim.md, "Dispersion studies", describes each key.

`draw(disp, seed, index)` is run `index` of a study with seed `seed`: a
Draw, computed from those two numbers alone (numpy's SeedSequence of
(seed, index)), so any run can be flown again exactly, alone. `apply(sc,
draw)` turns a freshly loaded rocket scenario (fswkit.plant.scenario) into
that run's: motor impulse, dry mass and drag scaled, vertical gusts blown,
sensor bias, noise, spikes and dropouts added, and a brown-out reset asked
of the co-simulation (`reset_at`, fswkit.plant.cosim).
"""

from __future__ import annotations

import bisect
import math
import os
from dataclasses import dataclass, field

import numpy as np

from .params import Field as F
from .params import ParamsError, Table
from .params import load_all as load_params
from .rocket import Chute, Motor


def _sensor(unit: str, what: str, bias_hi: float, spike_hi: float) -> Table:
    return Table(f"the {what}'s errors", {
        "bias_sd": F("float", f"a constant offset for the whole flight, standard deviation in {unit}", default=0.0,
                     lo=0, hi=bias_hi),
        "noise_scale": F("range", "its noise (plant.toml's standard deviation) multiplied by a factor drawn "
                         "uniformly in [low, high]", default=(1.0, 1.0), lo=0, hi=100),
        "spike_rate_hz": F("float", "spikes per simulated second (a Poisson process)", default=0.0, lo=0, hi=1000),
        "spike": F("range", f"a spike's size in {unit}, uniform in [low, high], either sign", default=(0.0, 0.0),
                   lo=0, hi=spike_hi),
        "spike_s": F("float", "how long a spike lasts, s", default=0.01, above=0, hi=10),
        "dropout_rate_hz": F("float", "dropouts per simulated second (a Poisson process)", default=0.0, lo=0,
                             hi=100),
        "dropout_s": F("range", "a dropout's length in seconds, uniform in [low, high]", default=(0.05, 0.5),
                       lo=0, hi=60),
        "dropout_volts": F("float", "what the converter reads during a dropout (an open line), V", default=0.0,
                           lo=0, hi=5),
    })


SCHEMA = {
    "": Table("the study", {}),
    "motor": Table("motor-to-motor spread", {
        "impulse_sd": F("float", "the thrust scaled by 1 + impulse_sd × a standard normal draw (replaces "
                        "plant.toml's impulse_sd, 0 included; absent: plant.toml's spread)", lo=0, hi=0.2,
                        required=False),
    }),
    "vehicle": Table("the vehicle as built", {
        "mass_sd": F("float", "dry mass scaled by 1 + mass_sd × a standard normal draw", default=0.0, lo=0, hi=0.3),
        "drag_sd": F("float", "the body's CdA scaled by 1 + drag_sd × a standard normal draw", default=0.0, lo=0,
                     hi=0.5),
        "chute_drag_sd": F("float", "each parachute's CdA scaled by 1 + chute_drag_sd × its own standard normal "
                           "draw", default=0.0, lo=0, hi=0.5),
    }),
    "wind": Table("vertical gusts (the plant has only its vertical axis)", {
        "gust_rate_hz": F("float", "gusts per simulated second from ignition on (a Poisson process)", default=0.0,
                          lo=0, hi=100),
        "gust_sd_m_s": F("float", "a gust's peak vertical air speed, standard deviation in m/s", default=0.0, lo=0,
                         hi=50),
        "gust_s": F("range", "a gust's length in seconds, uniform in [low, high] (a half-sine)",
                    default=(0.5, 2.0), lo=0.01, hi=60),
    }),
    "barometer": _sensor("Pa", "barometer", 1e4, 1e5),
    "accelerometer": _sensor("g", "accelerometer", 10, 100),
    "brownout": Table("a brown-out: the MCU resets in flight and its firmware starts again", {
        "probability": F("float", "the share of flights whose MCU resets once", default=0.0, lo=0, hi=1),
        "window_s": F("range", "when, in seconds after ignition, uniform in [low, high] (cut at the end of the "
                      "flight, plant.toml's max_s less ignition_s)", default=(0.0, 30.0), lo=0, hi=3600),
    }),
}

KEYS = ("motor", "vehicle", "wind", "barometer", "accelerometer", "brownout")


class Dispersion:
    """A checked dispersion file: `values[table][key]`."""

    def __init__(self, values: dict, path: str | None, where: dict | None = None):
        self.values, self.path, self.where = values, path, where or {}

    def past_flight(self, span_s: float) -> list[str]:
        """Located errors for what the file draws over a flight that lasts at
        most `span_s` after ignition: a brown-out window that starts past
        its end (draw cuts a window that only ends past it), a rate of
        events whose events over it would pass MAX_EVENTS a run."""
        from .params import error_at

        out = []
        over = max(SPAN_S, span_s)  # what draw draws events over
        for table, key in (("wind", "gust_rate_hz"), ("barometer", "spike_rate_hz"),
                           ("barometer", "dropout_rate_hz"), ("accelerometer", "spike_rate_hz"),
                           ("accelerometer", "dropout_rate_hz")):
            rate = self.values[table][key]
            if rate is not None and rate * over > MAX_EVENTS:  # (None: refused by the schema, said)
                out.append(error_at(self.path or "", self.where, table, key,
                                    f"{rate:g} a second over a flight of {over:,.0f} s is {rate * over:,.0f} events "
                                    f"a run: at most {MAX_EVENTS:,} (a lower rate, or a shorter max_s)"))
        window, probability = self.values["brownout"]["window_s"], self.values["brownout"]["probability"]
        if window is not None and probability and window[0] >= span_s:
            lo, hi = window
            out.append(error_at(self.path or "", self.where, "brownout", "window_s",
                                f"[{lo:g}, {hi:g}] starts after the end of the flight, {span_s:g} s after ignition "
                                "(the plant's max_s less its ignition_s): no brown-out could happen in flight"))
        return out

    @classmethod
    def none(cls) -> "Dispersion":
        """No dispersion at all: every run is plant.toml's flight (its noise seeds apart)."""
        from .params import check

        values, _ = check({}, SCHEMA, {}, "")
        return cls(values, None)


def load(path: str) -> Dispersion:
    """A dispersion file, checked; ParamsError with every located error."""
    disp, errors = load_all(path)
    if errors:
        raise ParamsError(errors)
    return disp


def load_all(path: str) -> tuple[Dispersion, list[str]]:
    """A dispersion file, checked, and its located errors, returned rather
    than raised so that a study reports them with the plant file's and
    `past_flight`'s (which skips a value refused: None); ParamsError only
    for a file that cannot be read."""
    if not os.path.exists(path):
        raise ParamsError([f"{path}: no such file (a dispersion file: see docs/sim.md, Dispersion studies)"])
    values, where, errors, _bad = load_params(path, SCHEMA)
    return Dispersion(values, path, where), errors


@dataclass
class SensorDraw:
    bias: float = 0.0
    noise_scale: float = 1.0
    spikes: list = field(default_factory=list)  # (start s, end s, size)
    dropouts: list = field(default_factory=list)  # (start s, end s)
    dropout_volts: float = 0.0


@dataclass
class Draw:
    """One run's parameters (everything `apply` needs)."""

    seed: int
    index: int
    noise_seed: int  # the scenario's own sensor-noise streams
    impulse: float | None = None  # factors; impulse None: plant.toml's own motor-to-motor spread
    mass: float = 1.0
    drag: float = 1.0
    drogue_drag: float = 1.0
    main_drag: float = 1.0
    gusts: list = field(default_factory=list)  # (start s, length s, peak m/s)
    baro: SensorDraw = field(default_factory=SensorDraw)
    accel: SensorDraw = field(default_factory=SensorDraw)
    brownout_s: float | None = None  # after ignition

    def row(self) -> dict:
        """The numbers a study's CSV shows for this run."""
        return {"impulse_factor": self.impulse, "mass_factor": self.mass, "drag_factor": self.drag,
                "gusts": len(self.gusts), "baro_bias_pa": self.baro.bias, "baro_noise_x": self.baro.noise_scale,
                "baro_spikes": len(self.baro.spikes), "baro_dropouts": len(self.baro.dropouts),
                "accel_bias_g": self.accel.bias, "accel_noise_x": self.accel.noise_scale,
                "accel_spikes": len(self.accel.spikes), "accel_dropouts": len(self.accel.dropouts),
                "brownout_s": self.brownout_s}


def _factor(rng: np.random.Generator, sd: float) -> float:
    """1 + sd × N(0, 1), kept above 0.2 (a draw beyond 4 sd of the widest spread allowed)."""
    return max(0.2, 1.0 + sd * float(rng.standard_normal())) if sd else 1.0


def _events(rng: np.random.Generator, rate: float, start: float, end: float) -> list[float]:
    """Poisson event times in [start, end)."""
    if rate <= 0 or end <= start:
        return []
    n = int(rng.poisson(rate * (end - start)))
    return sorted(float(x) for x in rng.uniform(start, end, n))


# Events are drawn over this many seconds after ignition from each kind's generator, and past them, up to
# the end of a longer flight (draw's span_s: plant.toml's max_s less ignition_s), from a generator of their
# own: a study of a flight within SPAN_S draws what it drew before longer flights were drawn to their end.
SPAN_S = 120.0
# The events of one kind a run may draw (rate × the flight's seconds): each is held in memory for the run,
# in every worker. 1,000 spikes a second over SPAN_S are 120,000.
MAX_EVENTS = 200_000


def _windows(rng: np.random.Generator, late: np.random.Generator, span_s: float) -> tuple:
    """(generator, start, end) of the two stretches events are drawn over."""
    return (rng, 0.0, SPAN_S), (late, SPAN_S, span_s)


def _sensor_draw(rng: np.random.Generator, late: np.random.Generator, p: dict, span_s: float) -> SensorDraw:
    d = SensorDraw(dropout_volts=p["dropout_volts"])
    d.bias = float(rng.normal(0.0, p["bias_sd"])) if p["bias_sd"] else 0.0
    lo, hi = p["noise_scale"]
    d.noise_scale = float(rng.uniform(lo, hi)) if hi > lo else lo
    for r, start, end in _windows(rng, late, span_s):
        for t in _events(r, p["spike_rate_hz"], start, end):
            size = float(r.uniform(*p["spike"])) * (1.0 if r.random() < 0.5 else -1.0)
            d.spikes.append((t, t + p["spike_s"], size))
        for t in _events(r, p["dropout_rate_hz"], start, end):
            d.dropouts.append((t, t + float(r.uniform(*p["dropout_s"]))))
    return d


def draw(disp: Dispersion, seed: int, index: int, span_s: float | None = None) -> Draw:
    """Run `index` of the study with seed `seed`: one generator per kind of
    dispersion, each from SeedSequence((seed, index, kind)), so that a key
    added to the file leaves the other kinds' draws as they were. With
    `span_s`, the seconds from ignition to the flight's end: spikes,
    dropouts and gusts cover them (those past SPAN_S from
    SeedSequence((seed, index, kind, 2))), and a brown-out window that ends
    past them is cut there (`probability` stays the share of flights that
    reset in flight)."""
    cut = span_s
    span_s = SPAN_S if span_s is None else span_s
    v = disp.values
    noise_seed = int(np.random.SeedSequence((seed, index)).generate_state(1)[0])
    rngs = {k: np.random.Generator(np.random.PCG64(np.random.SeedSequence((seed, index, i + 1))))
            for i, k in enumerate(KEYS)}
    late = {k: np.random.Generator(np.random.PCG64(np.random.SeedSequence((seed, index, i + 1, 2))))
            for i, k in enumerate(KEYS)}
    d = Draw(seed, index, noise_seed)
    if v["motor"]["impulse_sd"] is not None:  # written, 0 included: the study's spread replaces plant.toml's
        d.impulse = _factor(rngs["motor"], v["motor"]["impulse_sd"])
    veh = v["vehicle"]
    r = rngs["vehicle"]
    d.mass, d.drag = _factor(r, veh["mass_sd"]), _factor(r, veh["drag_sd"])
    d.drogue_drag, d.main_drag = _factor(r, veh["chute_drag_sd"]), _factor(r, veh["chute_drag_sd"])
    w = v["wind"]
    for r, start, end in _windows(rngs["wind"], late["wind"], span_s):
        for t in _events(r, w["gust_rate_hz"], start, end):
            d.gusts.append((t, float(r.uniform(*w["gust_s"])), float(r.normal(0.0, w["gust_sd_m_s"]))))
    d.baro = _sensor_draw(rngs["barometer"], late["barometer"], v["barometer"], span_s)
    d.accel = _sensor_draw(rngs["accelerometer"], late["accelerometer"], v["accelerometer"], span_s)
    b = v["brownout"]
    r = rngs["brownout"]
    if b["probability"] and r.random() < b["probability"]:
        lo, hi = b["window_s"]
        d.brownout_s = float(r.uniform(lo, hi if cut is None else max(lo, min(hi, cut))))
    return d


class _Windows:
    """Intervals (start, end, value) looked up by time, in order."""

    def __init__(self, spans: list):
        self.spans = sorted(spans)
        self.starts = [s[0] for s in self.spans]
        # a span that starts more than the longest one's length before t cannot cover it: the lookup steps
        # back over those that may (spikes of 5 ms at 1,000 a second stepped back over a minute of them)
        self.longest = max((b - a for a, b, *_ in self.spans), default=0.0)

    def at(self, t: float):
        i = bisect.bisect_right(self.starts, t) - 1
        while i >= 0:  # overlapping spans: the latest that covers t
            s = self.spans[i]
            if s[0] <= t < s[1]:
                return s
            if s[0] < t - self.longest:
                break
            i -= 1
        return None


def _gusts(gusts: list, t_ign: float):
    """The air's vertical velocity at time t: the half-sine gusts summed."""
    spans = sorted((t_ign + t, t_ign + t + n, a) for t, n, a in gusts)
    if not spans:
        return None
    starts = [a for a, _, _ in spans]
    longest = max(b - a for a, b, _ in spans)

    def wind(t: float) -> float:  # called four times a plant step: only the gusts that may cover t
        w = 0.0
        j = bisect.bisect_right(starts, t) - 1
        while j >= 0 and starts[j] > t - longest:
            a, b, peak = spans[j]
            if t < b:
                w += peak * math.sin(math.pi * (t - a) / (b - a))
            j -= 1
        return w

    return wind


def apply(sc, d: Draw) -> None:
    """Makes a rocket scenario fresh from `scenario.load` (with seed
    d.noise_seed) fly run `d`."""
    if sc.kind != "rocket":
        raise ValueError("dispersions apply to the rocket plant")
    p = sc.p
    r = sc.rocket
    if d.impulse is not None:  # the study's draw replaces plant.toml's motor-to-motor spread
        sc.motor_factor = d.impulse
        sc.motor = Motor([(t, f * d.impulse) for t, f in sc.curve])
        r.motor = sc.motor
    r.dry_mass *= d.mass
    r.body_cd_area *= d.drag
    r.chutes = {"drogue": Chute(r.chutes["drogue"].cd_area * d.drogue_drag, r.chutes["drogue"].inflate_s),
                "main": Chute(r.chutes["main"].cd_area * d.main_drag, r.chutes["main"].inflate_s)}
    t_ign = sc.ignition_s if sc.ignition_s is not None else 0.0
    r.wind = _gusts(d.gusts, t_ign)
    sc.baro_noise.sigma *= d.baro.noise_scale
    sc.accel_noise.sigma *= d.accel.noise_scale
    if d.brownout_s is not None and sc.ignition_s is not None:
        sc.reset_at = sc.ignition_s + d.brownout_s
        sc.reset_at_cause = "brownout"
    baro, accel = p["barometer"], p["accelerometer"]
    errs = []
    part_errs = []  # a digital part's: in its physical unit, a dropout holds the part's last value
    for sd, ch, part, per_volt in ((d.baro, sc.channels[0], getattr(sc, "baro_part", None),
                                    1.0 / baro["pa_per_volt"] if baro["pa_per_volt"] else 1.0),
                                   (d.accel, sc.channels[1], getattr(sc, "accel_part", None),
                                    accel["volts_per_g"] or 1.0)):
        if not (sd.bias or sd.spikes or sd.dropouts):
            continue
        if part is not None:
            part_errs.append((part, sd.bias, _Windows([(t_ign + a, t_ign + b, s) for a, b, s in sd.spikes]),
                              _Windows([(t_ign + a, t_ign + b, 0.0) for a, b in sd.dropouts]), sd is d.baro))
            continue
        errs.append((ch, sd.bias * per_volt, _Windows([(t_ign + a, t_ign + b, s * per_volt)
                                                       for a, b, s in sd.spikes]),
                     _Windows([(t_ign + a, t_ign + b, 0.0) for a, b in sd.dropouts]),
                     sd.dropout_volts, sd is d.baro))
    if not errs and not part_errs:
        return
    inputs = sc.inputs
    vref = sc.vref
    held = sc.dropout_held  # part -> its values when a dropout started (the scenario's: saved with it)

    def dispersed_inputs(t: float):
        analog, digital = inputs(t)
        for part, bias, spikes, dropouts, is_baro in part_errs:
            vals = sc.part_values[part]
            key = "pressure" if is_baro else next(k for k in vals if k in ("x", "y", "z"))
            sign = 1.0 if is_baro else sc.accel_axis[1]
            v = vals[key] + sign * bias
            s = spikes.at(t)
            if s is not None:
                v += sign * s[2]
            if dropouts.at(t) is not None:
                v = held.setdefault(part, v)
            else:
                held.pop(part, None)
            vals[key] = v
            if is_baro:
                sc.baro_v = v
            else:
                sc.accel_v = sign * v
        for ch, bias, spikes, dropouts, drop_v, is_baro in errs:
            v = analog[ch] + bias
            s = spikes.at(t)
            if s is not None:
                v += s[2]
            if dropouts.at(t) is not None:
                v = drop_v
            v = min(max(v, 0.0), vref)
            analog[ch] = v
            if is_baro:
                sc.baro_v = v
            else:
                sc.accel_v = v
        return analog, digital

    sc.inputs = dispersed_inputs

