"""A pressurised gas tank with a vent valve: ideal gas at a constant
temperature (the tank's walls hold it), fed by a pressurant supply through a
regulator whose flow does not depend on the tank's pressure (the supply is
choked: its pressure is more than twice the tank's), and vented to ambient
through an orifice when the valve is open. The vent's flow is the
compressible orifice equation — choked, and so proportional to the tank's
pressure, above the critical pressure ratio (1.89 for nitrogen). The valve
opens and closes as a first-order lag (a solenoid's response)."""

from __future__ import annotations

import math

PSI = 6894.757293168  # Pa
AMBIENT = 101325.0  # Pa


class Tank:
    def __init__(self, *, volume: float, temperature: float, gas_constant: float, gamma: float,
                 initial_pa: float, vent_cd_area: float, valve_time: float, ambient_pa: float = AMBIENT):
        self.volume, self.temperature, self.r, self.gamma = volume, temperature, gas_constant, gamma
        self.vent_cd_area, self.valve_time, self.ambient = vent_cd_area, valve_time, ambient_pa
        self.rt = gas_constant * temperature
        self.mass = initial_pa * volume / self.rt
        self.t = 0.0
        self.valve = 0.0  # 0 closed .. 1 open
        self.inflow = self.outflow = 0.0  # kg/s during the last step
        g = gamma
        self._critical = (2.0 / (g + 1.0)) ** (g / (g - 1.0))  # p_out/p_in at which the flow chokes
        self._choked = math.sqrt(g / self.rt) * (2.0 / (g + 1.0)) ** ((g + 1.0) / (2.0 * (g - 1.0)))

    def save(self) -> tuple:
        """What `advance` changes, for `restore` (a co-simulation's speculative steps)."""
        return self.mass, self.t, self.valve, self.inflow, self.outflow

    def restore(self, saved: tuple) -> None:
        self.mass, self.t, self.valve, self.inflow, self.outflow = saved

    @property
    def pressure(self) -> float:
        """Pa, absolute."""
        return self.mass * self.rt / self.volume

    @property
    def gauge_psi(self) -> float:
        return (self.pressure - self.ambient) / PSI

    def vent_flow(self, p: float, opening: float) -> float:
        """kg/s through the vent at tank pressure `p` with the valve `opening` open."""
        if opening <= 0.0 or p <= self.ambient:
            return 0.0
        cda = self.vent_cd_area * opening
        ratio = self.ambient / p
        if ratio <= self._critical:
            return cda * p * self._choked
        g = self.gamma
        return cda * p * math.sqrt(2.0 * g / ((g - 1.0) * self.rt) * (ratio ** (2.0 / g) - ratio ** ((g + 1.0) / g)))

    def advance(self, dt: float, inflow: float, valve_command: bool) -> None:
        """`dt` seconds with `inflow` kg/s of pressurant and the valve driven
        open (True) or closed."""
        target = 1.0 if valve_command else 0.0
        if self.valve_time > 0:
            self.valve += (target - self.valve) * (1.0 - math.exp(-dt / self.valve_time))
        else:
            self.valve = target
        # midpoint rule: the vent's flow depends on the pressure it lowers
        out1 = self.vent_flow(self.pressure, self.valve)
        m_mid = self.mass + (inflow - out1) * dt / 2
        out = self.vent_flow(m_mid * self.rt / self.volume, self.valve)
        self.mass = max(0.0, self.mass + (inflow - out) * dt)
        if not math.isfinite(self.mass) or not math.isfinite(self.pressure):
            raise FloatingPointError(f"the tank's gas mass or pressure overflowed at {self.t + dt:.6g} s")
        self.inflow, self.outflow = inflow, out
        self.t += dt
