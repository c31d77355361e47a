"""A dispersion file's `[brownout] window_s` may reach 3,600 s after
ignition, and a brown-out was drawn anywhere in it: with `window_s = [0,
3600]` and examples/rocket's flight (max_s 90, ignition at 3 s), 97 % of
the brown-outs drawn fell after the run had ended and never happened, so a
study of `probability = 0.5` reset about one flight in 70, and the table
and the CSV still showed each drawn brown-out; a window wholly past the
flight drew only brown-outs that never happen.

Now a study cuts a window that ends past the end of the flight (plant.toml's
max_s less ignition_s) there, so that `probability` is the share of
flights that reset in flight; a window that starts past it is an error at
its line naming that end, exit 2, before anything is built. Nothing is
flown here."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import EXAMPLES, run_fsw

from fswkit.plant import dispersion, study

ROCKET = EXAMPLES / "rocket"


@pytest.mark.parametrize("window", ["[88, 90]", "[87, 3600]"])
def test_a_window_past_the_flight_is_refused(tmp_path: Path, window):
    d = tmp_path / "d.toml"
    d.write_text(f"[brownout]\nprobability = 0.5\nwindow_s = {window}\n")
    r = run_fsw("sim", str(ROCKET), "--plant", "rocket", "--runs", "2", "--dispersion", str(d),
                "--out", str(tmp_path / "study"))
    assert "Traceback" not in r.err, r.err
    assert r.code == 2, r.err
    assert (f"{d}:3: [brownout] window_s: {window} starts after the end of the flight, 87 s after ignition "
            "(the plant's max_s less its ignition_s): no brown-out could happen in flight") in r.err, r.err
    assert "built" not in r.err and not (tmp_path / "study" / "study.txt").exists()


def test_a_window_that_ends_past_the_flight_is_cut_there(tmp_path: Path, monkeypatch):
    import fswkit.sim.command as command

    seen = {}

    def run_study(setup, runs, jobs, on_result=None):
        seen["draws"] = [study.draw_run(setup, i) for i in range(runs)]
        return [], True

    monkeypatch.setattr(study, "run_study", run_study)
    monkeypatch.setattr(command, "build", lambda project, board: ("unused.elf", type("B", (), {"name": "uno"})()))
    d = tmp_path / "d.toml"
    d.write_text("[brownout]\nprobability = 1\nwindow_s = [0, 3600]\n")
    r = run_fsw("sim", str(ROCKET), "--plant", "rocket", "--runs", "40", "--dispersion", str(d),
                "--out", str(tmp_path / "study"))
    assert r.code == 0 and "window_s" not in r.err, r.err
    times = [x.brownout_s for x in seen["draws"]]
    assert all(t is not None and 0 <= t <= 87 for t in times), times
    assert max(times) > 60  # uniform over the flight, not its first 30 s


def test_a_window_within_the_flight_is_drawn_as_before(tmp_path: Path):
    d = tmp_path / "d.toml"
    d.write_text("[brownout]\nprobability = 0.5\nwindow_s = [0, 30]\n")
    disp = dispersion.load(str(d))
    for i in range(20):
        assert dispersion.draw(disp, 1, i, span_s=87.0).brownout_s == dispersion.draw(disp, 1, i).brownout_s
