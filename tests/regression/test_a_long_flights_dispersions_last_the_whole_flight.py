"""A dispersion study drew its spikes, dropouts and gusts over the first
120 s after ignition only (fswkit.plant.dispersion.SPAN_S, "longer than
any flight of the example"): a study of a longer flight, examples/hpr's
(its main descent lands some 3 minutes after ignition, max_s 400), flew
its last minute and its landing with no sensor spike, no dropout and no
gust whatever the dispersion file said, and the table did not say so.

Now each run's events are drawn up to the end of its flight (plant.toml's
max_s less ignition_s): over the first 120 s exactly as before (a study
of a shorter flight, examples/rocket's, draws what it drew), and past
them from a generator of their own. Nothing is flown here: the draws, and
the study's setup as `fsw sim --runs` builds it (its build and its flights
replaced)."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import EXAMPLES, run_fsw

from fswkit.plant import dispersion, study

RATES = ("[barometer]\nspike_rate_hz = 0.5\ndropout_rate_hz = 0.5\n[accelerometer]\nspike_rate_hz = 0.5\n"
         "dropout_rate_hz = 0.5\n[wind]\ngust_rate_hz = 0.5\ngust_sd_m_s = 2\n")


def _disp(tmp_path: Path) -> dispersion.Dispersion:
    f = tmp_path / "d.toml"
    f.write_text(RATES)
    return dispersion.load(str(f))


def _times(d: dispersion.Draw) -> dict:
    return {"baro spikes": [s[0] for s in d.baro.spikes], "baro dropouts": [s[0] for s in d.baro.dropouts],
            "accel spikes": [s[0] for s in d.accel.spikes], "accel dropouts": [s[0] for s in d.accel.dropouts],
            "gusts": [g[0] for g in d.gusts]}


def test_events_cover_a_long_flight(tmp_path: Path):
    disp = _disp(tmp_path)
    for index in range(3):
        long = _times(dispersion.draw(disp, 1, index, span_s=395.0))
        for kind, ts in long.items():
            assert any(t > 300 for t in ts), (kind, ts)  # 0.5 a second: ~47 past 300 s
            assert all(0 <= t < 395 for t in ts), kind


def test_the_first_120_s_are_drawn_as_before(tmp_path: Path):
    disp = _disp(tmp_path)
    for index in range(3):
        short, long = dispersion.draw(disp, 1, index), dispersion.draw(disp, 1, index, span_s=395.0)
        assert short.baro.bias == long.baro.bias and short.accel.noise_scale == long.accel.noise_scale
        for kind, ts in _times(long).items():
            assert [t for t in ts if t < dispersion.SPAN_S] == _times(short)[kind], kind
        assert long.baro.spikes[:len(short.baro.spikes)] == short.baro.spikes
        assert long.gusts[:len(short.gusts)] == short.gusts


def test_a_shorter_flight_draws_what_it_drew(tmp_path: Path):
    disp = _disp(tmp_path)
    assert _times(dispersion.draw(disp, 1, 0, span_s=87.0)) == _times(dispersion.draw(disp, 1, 0))


@pytest.mark.parametrize("project, span", [("hpr", 395.0), ("rocket", 87.0)])
def test_a_study_draws_up_to_its_flights_end(tmp_path: Path, monkeypatch, project, span):
    seen = {}

    def run_study(setup, runs, jobs, on_result=None):
        seen["setup"] = setup
        seen["draw"] = study.draw_run(setup, 0)
        return [], True

    import fswkit.sim.command as command

    monkeypatch.setattr(study, "run_study", run_study)
    monkeypatch.setattr(command, "build", lambda project, board: ("unused.elf", type("B", (), {"name": "uno"})()))
    f = tmp_path / "d.toml"
    f.write_text(RATES)
    r = run_fsw("sim", str(EXAMPLES / project), "--plant", "rocket", "--runs", "1", "--dispersion", str(f),
                "--out", str(tmp_path / "study"))
    assert "Traceback" not in r.err, r.err
    assert seen["setup"].span_s == span
    assert _times(seen["draw"]) == _times(dispersion.draw(dispersion.load(str(f)), 1, 0, span_s=span))


def test_events_a_run_cannot_hold_are_located(tmp_path: Path, monkeypatch):
    """Drawn to the flight's end, a rate's events grow with max_s: 1,000
    spikes a second over a flight of an hour would be 3.6 million a run per
    sensor. A rate whose events over the flight pass MAX_EVENTS is an error
    at its line, before anything is built."""
    text = (EXAMPLES / "rocket" / "plant.toml").read_text()
    assert "max_s      = 90" in text
    plant = tmp_path / "plant.toml"
    plant.write_text(text.replace("max_s      = 90", "max_s      = 3600"))
    f = tmp_path / "d.toml"
    f.write_text("[barometer]\nspike_rate_hz = 1000\n[wind]\ngust_rate_hz = 100\n")
    r = run_fsw("sim", str(EXAMPLES / "rocket"), "--plant", "rocket", "--params", str(plant), "--runs", "1",
                "--dispersion", str(f), "--out", str(tmp_path / "study"))
    assert r.code == 2, r.err
    assert (f"{f}:2: [barometer] spike_rate_hz: 1000 a second over a flight of 3,597 s is 3,597,000 events a run: "
            f"at most {dispersion.MAX_EVENTS:,} (a lower rate, or a shorter max_s)") in r.err, r.err
    assert f"{f}:4: [wind] gust_rate_hz: 100 a second over a flight of 3,597 s is 359,700 events a run" in r.err
    assert "built" not in r.err
    # within the bound over the example's flight (87 s): taken
    assert dispersion.load(str(f)).past_flight(87.0) == []
