"""A dispersion study draws a brown-out's time in its window; a run whose
flight ended (landed, or was cut) before that time had no reset. Its line
under "failing runs" still said `[brown-out 41.20 s after ignition]`, as if
the MCU had reset then, which sent the reader to look for a reset that
never was. The line now says a brown-out only where the run had one, and
otherwise that the one drawn came after the run's end."""

from __future__ import annotations

from types import SimpleNamespace

from fswkit.plant.dispersion import Draw
from fswkit.plant.study import RunResult, text


def _text(resets):
    setup = SimpleNamespace(layout=SimpleNamespace(name="rocket"), seed=1,
                            command=["fsw", "sim", "examples/rocket", "--plant", "rocket"])
    r = RunResult(index=7, draw=Draw(seed=1, index=7, noise_seed=8, brownout_s=41.2), resets=resets,
                  checks=[("landed", "landing detected", False, "never")])
    return text(setup, [r], 1, 1, 1.0, True, None)


def test_a_brownout_after_the_runs_end_is_said_so():
    out = _text([])
    line = next(x for x in out.splitlines() if x.startswith("  run 7"))
    assert "brown-out drawn at 41.20 s after ignition, after the run's end: no reset" in line, line
    assert "[brown-out 41.20 s after ignition]" not in line


def test_a_brownout_that_happened_is_said_as_before():
    out = _text([45.2])
    line = next(x for x in out.splitlines() if x.startswith("  run 7"))
    assert "[brown-out 41.20 s after ignition]" in line, line
