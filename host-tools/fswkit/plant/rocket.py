"""A one-dimensional sport rocket: the vehicle's axis stays vertical.

Forces: the motor's thrust (a table of (seconds from ignition, newtons),
linearly interpolated), gravity, and drag ½ρv²·CdA against the airspeed (the velocity less
the air's own vertical motion, `wind`: still air unless a study blows gusts),
where CdA is the body's plus each parachute's as it inflates (linearly, over
its inflation time, from the moment its charge fires). The mass burns down
in proportion to the impulse delivered. The air is the ISA troposphere above
a pad at a given altitude. The vehicle sits on the pad until the thrust
exceeds its weight (the pad pushes back, it never sinks), and stops when it
comes back to the ground. Integration: classical Runge-Kutta, fixed step.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

from .atmosphere import G0, density_fn, pressure


class Motor:
    """A thrust curve: points (s from ignition, N), times increasing; no
    thrust before the first point or after the last."""

    def __init__(self, curve: list[tuple[float, float]] | tuple):
        self.times = [float(t) for t, _ in curve]
        self.thrusts = [float(f) for _, f in curve]
        if len(self.times) < 2 or any(b <= a for a, b in zip(self.times, self.times[1:])):
            raise ValueError("a thrust curve needs two or more points at increasing times")
        self.cumulative = [0.0]  # impulse delivered at each point
        for i in range(1, len(self.times)):
            dt = self.times[i] - self.times[i - 1]
            self.cumulative.append(self.cumulative[-1] + dt * (self.thrusts[i] + self.thrusts[i - 1]) / 2)
        self.total = self.cumulative[-1]
        self.burn_time = self.times[-1]

    def thrust(self, t: float) -> float:
        ts = self.times
        if t < ts[0] or t >= ts[-1]:
            return 0.0
        i = bisect.bisect_right(ts, t) - 1
        f0, f1 = self.thrusts[i], self.thrusts[i + 1]
        return f0 + (f1 - f0) * (t - ts[i]) / (ts[i + 1] - ts[i])

    def impulse(self, t: float) -> float:
        """N·s delivered `t` s after ignition."""
        ts = self.times
        if t <= ts[0]:
            return 0.0
        if t >= ts[-1]:
            return self.total
        i = bisect.bisect_right(ts, t) - 1
        f0, f1 = self.thrusts[i], self.thrusts[i + 1]
        ft = f0 + (f1 - f0) * (t - ts[i]) / (ts[i + 1] - ts[i])
        return self.cumulative[i] + (t - ts[i]) * (f0 + ft) / 2

    @property
    def peak(self) -> float:
        return max(self.thrusts)


@dataclass(frozen=True)
class Chute:
    cd_area: float  # m², when fully inflated
    inflate_s: float  # from the charge firing to fully inflated


class Rocket:
    """The vehicle's state (time `t`, altitude `h` above the pad, velocity
    `v` and acceleration `a`, up positive) and its events (ignition,
    liftoff, apogee, chute deployments, touchdown), advanced by `advance`."""

    def __init__(self, *, dry_mass: float, propellant_mass: float, motor: Motor, body_cd_area: float,
                 drogue: Chute, main: Chute, pad_altitude: float = 0.0, g: float = G0):
        self.dry_mass, self.propellant_mass = dry_mass, propellant_mass
        self.motor, self.body_cd_area = motor, body_cd_area
        self.chutes = {"drogue": drogue, "main": main}
        self.pad_altitude, self.g = pad_altitude, g
        self._rho = density_fn(pad_altitude)
        self.t = self.h = self.v = self.a = 0.0
        self.ignition: float | None = None
        self.liftoff: float | None = None
        self.touchdown: float | None = None
        self.deployed: dict[str, float] = {}  # chute -> time its charge fired
        self.apogee_h, self.apogee_t = 0.0, None
        self.wind = None  # t -> the air's vertical velocity, m/s up (gusts: dispersion studies); None: still air

    def save(self) -> tuple:
        """What `ignite`, `deploy` and `advance` change, for `restore` (a
        co-simulation's speculative steps)."""
        return (self.t, self.h, self.v, self.a, self.ignition, self.liftoff, self.touchdown, dict(self.deployed),
                self.apogee_h, self.apogee_t)

    def restore(self, saved: tuple) -> None:
        (self.t, self.h, self.v, self.a, self.ignition, self.liftoff, self.touchdown, deployed,
         self.apogee_h, self.apogee_t) = saved
        self.deployed = dict(deployed)

    # -- inputs --
    def ignite(self, t: float) -> None:
        if self.ignition is None:
            self.ignition = t

    def deploy(self, chute: str, t: float) -> None:
        if chute not in self.deployed:
            self.deployed[chute] = t

    # -- what the vehicle is at time t --
    def burn_time(self, t: float) -> float | None:
        return None if self.ignition is None else t - self.ignition

    def thrust(self, t: float) -> float:
        return 0.0 if self.ignition is None else self.motor.thrust(t - self.ignition)

    def mass(self, t: float) -> float:
        if self.ignition is None or self.motor.total == 0:
            return self.dry_mass + self.propellant_mass
        burnt = self.motor.impulse(t - self.ignition) / self.motor.total
        return self.dry_mass + self.propellant_mass * (1.0 - burnt)

    def inflation(self, chute: str, t: float) -> float:
        """0 (packed) to 1 (fully inflated)."""
        at = self.deployed.get(chute)
        if at is None or t < at:
            return 0.0
        c = self.chutes[chute]
        return 1.0 if c.inflate_s <= 0 else min(1.0, (t - at) / c.inflate_s)

    def cd_area(self, t: float) -> float:
        """The body's CdA plus each chute's as inflated at `t` (the chutes'
        sum first, in their order: `inflation`'s arithmetic, worked out here
        in line, as the integrator asks every step)."""
        deployed = self.deployed
        total = 0
        for n, c in self.chutes.items():
            at = deployed.get(n)
            if at is None or t < at:
                total += c.cd_area * 0.0
            else:
                total += c.cd_area * (1.0 if c.inflate_s <= 0 else min(1.0, (t - at) / c.inflate_s))
        return self.body_cd_area + total

    def density(self, h: float | None = None) -> float:
        return self._rho(self.h if h is None else h)

    def static_pressure(self) -> float:
        return pressure(self.pad_altitude + self.h)

    def specific_force(self) -> float:
        """What an accelerometer on the vehicle's axis measures, m/s²:
        acceleration minus gravity's (+g at rest on the pad)."""
        return self.a + self.g

    @property
    def on_ground(self) -> bool:
        return self.liftoff is None or self.touchdown is not None

    def _accel(self, t: float, h: float, v: float, cda: float) -> float:
        if self.wind is not None:
            v -= self.wind(t)  # drag acts on the airspeed
        drag = -0.5 * self._rho(h) * v * abs(v) * cda
        return (self.thrust(t) + drag) / self.mass(t) - self.g

    # -- time --
    def advance(self, dt: float) -> None:
        """Integrates `dt` seconds (RK4; the chutes' CdA at mid-step)."""
        t, h, v = self.t, self.h, self.v
        t1 = t + dt
        if self.touchdown is not None:
            self.t, self.a = t1, 0.0
            return
        if self.liftoff is None:
            # on the pad: it pushes back until the thrust exceeds the weight
            if self.thrust(t1) <= self.mass(t1) * self.g:
                self.t, self.a = t1, 0.0
                return
            self.liftoff = t
        cda = self.cd_area(t + dt / 2)
        f = self._accel
        eps = dt * 1e-6  # the ends are evaluated just inside the step: a thrust curve's steps fall between
        ign = self.ignition
        if self.wind is None and (ign is None or min(t + eps, t + dt / 2, t1 - eps, t1) - ign >= self.motor.burn_time):
            # no thrust anywhere in the step (before ignition, after burn-out) and still air: the thrust and
            # the mass are the same at every instant _accel is asked about, worked out once here, and the
            # accelerations are _accel's own arithmetic, operation for operation
            thr, m, g, rho = self.thrust(t1), self.mass(t1), self.g, self._rho
            a1 = (thr + -0.5 * rho(h) * v * abs(v) * cda) / m - g
            v2 = v + a1 * dt / 2
            a2 = (thr + -0.5 * rho(h + v * dt / 2) * v2 * abs(v2) * cda) / m - g
            v3 = v + a2 * dt / 2
            a3 = (thr + -0.5 * rho(h + v2 * dt / 2) * v3 * abs(v3) * cda) / m - g
            v4 = v + a3 * dt
            a4 = (thr + -0.5 * rho(h + v3 * dt) * v4 * abs(v4) * cda) / m - g
        else:
            thr = None
            a1 = f(t + eps, h, v, cda)
            v2 = v + a1 * dt / 2
            a2 = f(t + dt / 2, h + v * dt / 2, v2, cda)
            v3 = v + a2 * dt / 2
            a3 = f(t + dt / 2, h + v2 * dt / 2, v3, cda)
            v4 = v + a3 * dt
            a4 = f(t1 - eps, h + v3 * dt, v4, cda)
        h += dt * (v + 2 * v2 + 2 * v3 + v4) / 6
        v += dt * (a1 + 2 * a2 + 2 * a3 + a4) / 6
        if not (math.isfinite(h) and math.isfinite(v)):
            raise FloatingPointError(f"the rocket's altitude or velocity overflowed at {t1:.6g} s "
                                     f"(thrust {self.thrust(t):.6g} N, mass {self.mass(t):.6g} kg)")
        self.t = t1
        if self.apogee_t is None and h <= 0.0:  # thrust barely above the weight: still on the rail's foot
            h, v = 0.0, max(v, 0.0)
        elif h <= 0.0 and v < 0.0:  # back on the ground
            self.touchdown = t1
            self.h = self.v = self.a = 0.0
            return
        self.h, self.v = h, v
        if thr is None:
            self.a = f(t1, h, v, cda)
        else:  # _accel's arithmetic with the step's thrust and mass (those at t1)
            self.a = (thr + -0.5 * rho(h) * v * abs(v) * cda) / m - g
        if h > self.apogee_h:
            self.apogee_h, self.apogee_t = h, t1
