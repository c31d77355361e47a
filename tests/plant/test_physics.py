"""The plant models against physics done by hand: the ISA table, a
vacuum flight against the rocket equation, terminal velocity under a
canopy, the pad and the ground as constraints, mass burn-down, the tank's
fill rate and its choked blowdown."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fswkit.plant import atmosphere as isa
from fswkit.plant.rocket import Chute, Motor, Rocket
from fswkit.plant.scenario import Noise, Pyro
from fswkit.plant.tank import PSI, Tank

G = isa.G0
NO_CHUTE = Chute(1e-9, 0.0)


def vehicle(curve, *, dry=1.0, prop=0.1, cda=0.0, drogue=NO_CHUTE, main=NO_CHUTE, pad=0.0) -> Rocket:
    return Rocket(dry_mass=dry, propellant_mass=prop, motor=Motor(curve), body_cd_area=cda, drogue=drogue,
                  main=main, pad_altitude=pad)


def step(r: Rocket, dt: float = 0.001) -> None:
    """One step on an exact time grid (as the co-simulation steps: no drift
    of the step boundaries against the thrust curve's points)."""
    r.t = round(r.t / dt) * dt
    r.advance(dt)


def fly_to_apogee(r: Rocket, dt: float = 0.001, limit: float = 200.0) -> None:
    while r.t < limit and not (r.apogee_t is not None and r.v < 0):
        step(r, dt)


# ---- the atmosphere ---------------------------------------------------------------------

def test_isa_table_values():
    assert isa.pressure(0) == pytest.approx(101325.0)
    assert isa.pressure(1000) == pytest.approx(89874.6, abs=1.0)  # ISA table: 89,875 Pa
    assert isa.pressure(5000) == pytest.approx(54019.9, abs=5.0)
    assert isa.density(0) == pytest.approx(1.2250, abs=1e-4)
    assert isa.density(1000) == pytest.approx(1.1117, abs=1e-4)
    assert isa.temperature(11000) == pytest.approx(216.65)


def test_altitude_inverts_pressure_and_the_fast_density_matches():
    for h in (0.0, 123.4, 1500.0, 8000.0):
        assert isa.altitude(isa.pressure(h)) == pytest.approx(h, abs=1e-6)
    rho = isa.density_fn(1400.0)
    for h in (0.0, 250.0, 900.0):
        assert rho(h) == pytest.approx(isa.density(1400.0 + h), rel=1e-12)


# ---- the motor --------------------------------------------------------------------------

def test_thrust_curve_interpolates_and_integrates():
    m = Motor([(0.0, 0.0), (0.1, 100.0), (1.1, 50.0), (1.2, 0.0)])
    assert m.thrust(-0.01) == 0.0 and m.thrust(1.3) == 0.0
    assert m.thrust(0.05) == pytest.approx(50.0)
    assert m.thrust(0.6) == pytest.approx(75.0)
    assert m.total == pytest.approx(0.1 * 50 + 1.0 * 75 + 0.1 * 25)
    # impulse(t) is the integral of thrust(t): compare with a fine trapezoid sum
    ts = np.linspace(0, 0.8, 16001)
    fs = np.array([m.thrust(t) for t in ts])
    assert m.impulse(0.8) == pytest.approx(float(((fs[1:] + fs[:-1]) / 2 * np.diff(ts)).sum()), rel=1e-6)
    assert m.impulse(5.0) == m.total


def test_thrust_curve_must_have_increasing_times():
    with pytest.raises(ValueError):
        Motor([(0.0, 10.0)])
    with pytest.raises(ValueError):
        Motor([(0.0, 10.0), (0.5, 5.0), (0.5, 0.0)])


def test_mass_burns_down_in_proportion_to_the_impulse():
    curve = [(0.0, 0.0), (0.1, 100.0), (1.1, 50.0), (1.2, 0.0)]
    r = vehicle(curve, dry=1.0, prop=0.2)
    assert r.mass(0.0) == pytest.approx(1.2)
    r.ignite(2.0)
    m = Motor(curve)
    for t in (0.05, 0.3, 0.9, 1.15):
        assert r.mass(2.0 + t) == pytest.approx(1.0 + 0.2 * (1 - m.impulse(t) / m.total))
    assert r.mass(10.0) == pytest.approx(1.0)


# ---- flight -----------------------------------------------------------------------------

def test_vacuum_apogee_matches_the_rocket_equation():
    """Constant thrust F for tb seconds, mass falling linearly from m0 to m1
    (burn-down proportional to impulse): v(tb) = ve ln(m0/m1) - g tb with
    ve = F tb / (m0 - m1); h(tb) = ve/mdot ((m0-m1) - m1 ln(m0/m1)) - g tb²/2;
    apogee = h(tb) + v(tb)²/(2g)."""
    F, tb, m0, m1 = 60.0, 2.0, 1.5, 1.2
    r = vehicle([(0.0, F), (tb, F)], dry=m1, prop=m0 - m1)
    r.ignite(0.0)
    mdot = (m0 - m1) / tb
    ve = F / mdot
    v_b = ve * math.log(m0 / m1) - G * tb
    h_b = ve / mdot * ((m0 - m1) - m1 * math.log(m0 / m1)) - G * tb ** 2 / 2
    while r.t < tb - 1e-9:
        step(r)
    assert r.v == pytest.approx(v_b, rel=1e-4)
    assert r.h == pytest.approx(h_b, rel=1e-4)
    fly_to_apogee(r)
    assert r.apogee_h == pytest.approx(h_b + v_b ** 2 / (2 * G), rel=1e-4)
    assert r.apogee_t == pytest.approx(tb + v_b / G, abs=0.002)


def test_coasting_without_drag_conserves_energy():
    r = vehicle([(0.0, 80.0), (0.5, 80.0)], dry=1.0, prop=0.0)
    r.ignite(0.0)
    while r.t < 0.5 - 1e-9:
        r.advance(0.001)
    e0 = 0.5 * r.v ** 2 + G * r.h
    for _ in range(3000):
        r.advance(0.001)
        assert 0.5 * r.v ** 2 + G * r.h == pytest.approx(e0, rel=1e-9)


def test_drag_lowers_the_apogee():
    curve = [(0.0, 80.0), (1.0, 80.0)]
    vac, air = vehicle(curve), vehicle(curve, cda=0.002)
    for r in (vac, air):
        r.ignite(0.0)
        fly_to_apogee(r)
    assert air.apogee_h < vac.apogee_h * 0.95


def test_terminal_velocity_under_the_main():
    """Falling under a full canopy the vehicle settles at sqrt(2 m g / (rho CdA)),
    with rho the air's density where it is."""
    main = Chute(0.4, 0.5)
    r = vehicle([(0.0, 200.0), (1.0, 200.0)], dry=1.25, prop=0.0, main=main, pad=200.0)
    r.ignite(0.0)
    fly_to_apogee(r)
    r.deploy("main", r.t)
    while r.t < r.apogee_t + 20:
        r.advance(0.001)
    assert r.touchdown is None
    cda = r.cd_area(r.t)
    assert cda == pytest.approx(0.4)  # the body's CdA is 0 here
    v_term = math.sqrt(2 * 1.25 * G / (isa.density(200.0 + r.h) * cda))
    assert -r.v == pytest.approx(v_term, rel=2e-3)
    assert abs(r.specific_force() / G - 1.0) < 0.01  # the canopy holds the vehicle's weight


def test_chute_inflates_linearly_from_its_charge():
    drogue = Chute(0.05, 0.3)
    r = vehicle([(0.0, 30.0), (1.0, 30.0)], drogue=drogue)
    r.deploy("drogue", 10.0)
    r.deploy("drogue", 11.0)  # a second firing changes nothing
    assert r.inflation("drogue", 9.99) == 0.0
    assert r.inflation("drogue", 10.15) == pytest.approx(0.5)
    assert r.inflation("drogue", 10.4) == 1.0
    assert r.inflation("main", 20.0) == 0.0


def test_the_pad_holds_the_vehicle_until_thrust_exceeds_weight():
    # thrust ramps through the weight (1.1 kg: 10.8 N) at 10.8/200 s after ignition
    r = vehicle([(0.0, 0.0), (0.1, 20.0), (2.0, 20.0)], dry=1.0, prop=0.1)
    for _ in range(1000):  # on the pad, not lit: no sinking, +1 g measured
        r.advance(0.001)
    assert (r.h, r.v, r.a, r.liftoff) == (0.0, 0.0, 0.0, None)
    assert r.specific_force() == pytest.approx(G)
    r.ignite(1.0)
    while r.t < 1.05:
        r.advance(0.001)
        assert r.h == 0.0 and r.v == 0.0  # thrust still below the weight
    while r.liftoff is None:
        r.advance(0.001)
    assert r.liftoff == pytest.approx(1.0 + 0.1 * G * 1.1 / 20.0, abs=0.0025)


def test_the_vehicle_stops_on_the_ground():
    r = vehicle([(0.0, 40.0), (0.5, 40.0)])
    r.ignite(0.0)
    while r.touchdown is None and r.t < 60:
        r.advance(0.001)
        assert r.h >= 0.0
    assert r.touchdown is not None
    for _ in range(100):
        r.advance(0.001)
    assert (r.h, r.v, r.a) == (0.0, 0.0, 0.0)
    assert r.specific_force() == pytest.approx(G)


# ---- the tank ---------------------------------------------------------------------------

def make_tank(**kw) -> Tank:
    args = dict(volume=0.01, temperature=293.15, gas_constant=296.8, gamma=1.4, initial_pa=5e6,
                vent_cd_area=5e-6, valve_time=0.0)
    args.update(kw)
    return Tank(**args)


def test_tank_fills_at_rt_over_v_per_kilogram():
    t = make_tank()
    p0 = t.pressure
    for _ in range(1000):
        t.advance(0.001, 0.030, False)
    assert t.pressure - p0 == pytest.approx(0.030 * 1.0 * 296.8 * 293.15 / 0.01, rel=1e-9)
    assert t.gauge_psi == pytest.approx((t.pressure - 101325.0) / PSI)


def test_choked_blowdown_decays_exponentially():
    """While choked, the vent's flow is k p, so p(t) = p0 exp(-k R T t / V)."""
    t = make_tank()
    g, rt = 1.4, 296.8 * 293.15
    k = 5e-6 * math.sqrt(g / rt) * (2 / (g + 1)) ** ((g + 1) / (2 * (g - 1)))
    p0 = t.pressure
    for _ in range(2000):
        t.advance(0.001, 0.0, True)
    assert t.pressure == pytest.approx(p0 * math.exp(-k * rt / 0.01 * 2.0), rel=1e-5)


def test_vent_flow_is_continuous_at_the_critical_ratio_and_zero_at_ambient():
    t = make_tank()
    crit = 101325.0 / (2 / 2.4) ** (1.4 / 0.4)
    assert t.vent_flow(crit * (1 + 1e-9), 1.0) == pytest.approx(t.vent_flow(crit * (1 - 1e-9), 1.0), rel=1e-6)
    assert t.vent_flow(101325.0, 1.0) == 0.0
    assert t.vent_flow(5e6, 0.0) == 0.0


def test_valve_opens_as_a_first_order_lag():
    t = make_tank(valve_time=0.008)
    for _ in range(8):
        t.advance(0.001, 0.0, True)
    assert t.valve == pytest.approx(1 - math.exp(-1), rel=1e-9)


# ---- sensors and pyros ------------------------------------------------------------------

def test_noise_is_seeded_and_has_its_sigma():
    a = Noise(np.random.Generator(np.random.PCG64(7)), 2.0, block=100)
    b = Noise(np.random.Generator(np.random.PCG64(7)), 2.0, block=1000)
    xs = [a() for _ in range(5000)]
    assert xs == [b() for _ in range(5000)]  # the block size does not change the sequence
    assert np.std(xs) == pytest.approx(2.0, rel=0.05)
    assert Noise(np.random.Generator(np.random.PCG64(7)), 0.0)() == 0.0


def test_pyro_fires_only_when_held_high_long_enough():
    p = Pyro(0.020)
    p.edge(1.000, True)
    p.edge(1.010, False)  # a 10 ms glitch: no fire
    assert p.poll(1.5) is None
    p.edge(2.000, True)
    assert p.poll(2.015) is None
    assert p.poll(2.021) == pytest.approx(2.020)
    assert p.poll(2.030) is None  # fires once
