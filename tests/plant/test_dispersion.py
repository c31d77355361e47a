"""Dispersion files and draws (fswkit.plant.dispersion): the example file
loads, every bad value is located at its line, a run's parameters depend
only on (study seed, run index), and `apply` changes a scenario as the draw
says (and nothing when there is no dispersion)."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import EXAMPLES
from fswkit.plant import dispersion as D
from fswkit.plant.params import ParamsError
from fswkit.plant.run import prepare
from fswkit.plant.study import wilson

ROCKET = EXAMPLES / "rocket"
EXAMPLE = ROCKET / "dispersion.toml"


def test_the_example_file_loads():
    d = D.load(str(EXAMPLE))
    assert d.values["motor"]["impulse_sd"] == 0.03
    assert d.values["barometer"]["noise_scale"] == (1.0, 2.0)
    assert d.values["brownout"]["probability"] == 0.01


def _file(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "d.toml"
    p.write_text(text)
    return p


@pytest.mark.parametrize("text, line, message", [
    ("[motor]\nimpulse_sd = 0.5\n", 2, "[motor] impulse_sd: 0.5 is out of range (0 to 0.2)"),
    ("[motor]\nimpulse = 0.1\n", 2, "[motor] unknown key `impulse` (known: impulse_sd)"),
    ("[wind]\ngust_rate_hz = \"often\"\n", 2, "[wind] gust_rate_hz: expected a number, found a string"),
    ("[barometer]\nnoise_scale = [2, 1]\n", 2, "the range's low end 2 is above its high end 1"),
    ("[barometer]\nspike = 300\n", 2, "[barometer] spike: expected a range [low, high] of two numbers"),
    ("[accelerometer]\ndropout_s = [0, 100]\n", 2, "[accelerometer] dropout_s: 100 is out of range (0 to 60)"),
    ("\n[brownout]\nprobability = 1.5\n", 3, "[brownout] probability: 1.5 is out of range (0 to 1)"),
    ("[sun]\nflare = 1\n", 1, "unknown table [sun]"),
    ("[motor\nimpulse_sd = 0.1\n", 1, ""),
])
def test_bad_files_are_located(tmp_path: Path, text, line, message):
    p = _file(tmp_path, text)
    with pytest.raises(ParamsError) as e:
        D.load(str(p))
    assert any(err.startswith(f"{p}:{line}") and message in err for err in e.value.errors), e.value.errors


def test_a_missing_file(tmp_path: Path):
    with pytest.raises(ParamsError, match="no such file .*Dispersion studies"):
        D.load(str(tmp_path / "none.toml"))


def test_a_run_is_its_seed_and_index():
    d = D.load(str(EXAMPLE))
    a, b = D.draw(d, 7, 3), D.draw(d, 7, 3)
    assert a == b
    assert D.draw(d, 7, 4) != a and D.draw(d, 8, 3) != a
    assert a.noise_seed == b.noise_seed and a.noise_seed != D.draw(d, 7, 4).noise_seed
    assert a.gusts and a.baro.noise_scale >= 1.0


def test_each_kind_draws_from_its_own_stream(tmp_path: Path):
    """Adding a kind of dispersion leaves the others' draws as they were."""
    only_motor = D.load(str(_file(tmp_path, "[motor]\nimpulse_sd = 0.03\n")))
    full = D.load(str(EXAMPLE))
    for i in range(5):
        assert D.draw(only_motor, 1, i).impulse == D.draw(full, 1, i).impulse


def test_brownouts_come_at_their_rate(tmp_path: Path):
    d = D.load(str(_file(tmp_path, "[brownout]\nprobability = 0.25\nwindow_s = [1, 2]\n")))
    times = [D.draw(d, 1, i).brownout_s for i in range(400)]
    hit = [t for t in times if t is not None]
    assert 70 < len(hit) < 130
    assert all(1 <= t <= 2 for t in hit)


def test_apply_changes_the_scenario_as_drawn():
    _app, _layout, plain = prepare(str(ROCKET), "rocket", seed=5)
    _app, _layout, sc = prepare(str(ROCKET), "rocket", seed=5)
    d = D.draw(D.load(str(EXAMPLE)), 1, 0)
    d.brownout_s = 2.5
    D.apply(sc, d)
    r, p = sc.rocket, plain.rocket
    assert r.dry_mass == pytest.approx(p.dry_mass * d.mass)
    assert r.body_cd_area == pytest.approx(p.body_cd_area * d.drag)
    assert sc.motor.total == pytest.approx(sum(
        (t1 - t0) * (f0 + f1) / 2 for (t0, f0), (t1, f1) in zip(sc.curve, sc.curve[1:])) * d.impulse)
    assert sc.reset_at == sc.ignition_s + 2.5
    assert r.wind is not None
    a, _ = sc.inputs(0.0)
    b, _ = plain.inputs(0.0)
    baro = sc.channels[0]
    bias_v = d.baro.bias / sc.p["barometer"]["pa_per_volt"]
    assert a[baro] == pytest.approx(b[baro] + bias_v, abs=5 * 12 * d.baro.noise_scale / 6250 + 1e-6)


def test_no_dispersion_leaves_the_flight_as_plant_toml_says():
    _app, _layout, plain = prepare(str(ROCKET), "rocket", seed=5)
    _app, _layout, sc = prepare(str(ROCKET), "rocket", seed=5)
    d = D.draw(D.Dispersion.none(), 1, 0)
    D.apply(sc, d)
    assert sc.motor.total == plain.motor.total
    assert sc.rocket.dry_mass == plain.rocket.dry_mass and sc.rocket.wind is None
    assert getattr(sc, "reset_at", None) is None
    assert sc.inputs(0.0) == plain.inputs(0.0)


def test_wilson_interval():
    lo, hi = wilson(990, 1000)
    assert lo == pytest.approx(0.9817, abs=1e-4) and hi == pytest.approx(0.9946, abs=1e-4)
    assert wilson(0, 10)[0] == 0.0 and wilson(10, 10)[1] == pytest.approx(1.0)
    assert wilson(0, 0) == (0.0, 1.0)


def test_gusts_sum_the_half_sines_that_cover_a_time():
    import math

    gusts = [(1.0, 2.0, 3.0), (2.0, 0.5, -1.0), (10.0, 1.0, 2.0)]
    wind = D._gusts(gusts, 3.0)

    def by_hand(t):
        return sum(p * math.sin(math.pi * (t - 3 - a) / n) for a, n, p in gusts if 3 + a <= t < 3 + a + n)

    for k in range(2001):
        t = k / 100
        assert wind(t) == pytest.approx(by_hand(t), abs=1e-12)
    assert D._gusts([], 3.0) is None


def test_a_window_lookup_finds_the_latest_span_covering_a_time_and_looks_no_further_back_than_it_must():
    """`_Windows.at` (the sensors' spikes and dropouts by time) against a
    search of every span, over overlapping spans of mixed lengths; and at
    1,000 spikes a second it steps back over a handful, not over a minute
    of them (it did: a flight 20 times its CPU)."""
    import random

    from fswkit.plant.dispersion import _Windows

    rng = random.Random(5)
    spans = [(a, a + rng.choice((0.005, 0.05, 0.5, 3.0)), k) for k, a in
             enumerate(sorted(rng.uniform(0, 60) for _ in range(400)))]
    w = _Windows(spans)
    for _ in range(3000):
        t = rng.uniform(-1, 65)
        covering = [s for s in spans if s[0] <= t < s[1]]
        assert w.at(t) == (max(covering) if covering else None)
    dense = _Windows([(k / 1000, k / 1000 + 0.0005, k) for k in range(60_000)])  # 0.5 ms spikes, 1,000 a second
    steps = []

    class Counting(list):
        def __getitem__(self, i):
            steps.append(i)
            return list.__getitem__(self, i)
    dense.spans = Counting(dense.spans)
    assert dense.at(59.9992)[2] == 59_999
    assert dense.at(30.0107) is None  # between two spikes: nothing covers it
    assert len(steps) <= 10, len(steps)
