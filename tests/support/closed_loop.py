"""Closed-loop flights of an example's real firmware on the simulated Uno
(tests/safety): one build of the project, then each flight its plant
flies with seed 1, two at a time."""

from __future__ import annotations

import os
import shutil
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

needs_avr_sim = pytest.mark.skipif(shutil.which("avr-gcc") is None
                                   or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                   reason="gcc-avr and libsimavr-dev are needed (make setup)")


def build_project(project: Path) -> tuple[str, str]:
    """`project`'s firmware built into build/sim-tests/ (kept between runs,
    built once for every test file: support.simfw.kept_sim): (its ELF, its
    board)."""
    from support.simfw import kept_sim

    return kept_sim(project)


def fly(project: Path, built: tuple[str, str], fault: str | None = None, params: str | None = None,
        reset: tuple[str, float, str] | None = None):
    """One flight of `project`'s plant (the `rocket` vehicle, seed 1) on the
    `built` firmware, with `fault` and the plant file `params` if given, and
    one reset in flight if `reset` is (state, seconds after telemetry first
    showed it, cause): (the application, the flight)."""
    from fswkit.plant.run import execute, prepare

    elf, board = built
    app, layout, sc = prepare(str(project), "rocket", seed=1, fault=fault, params=params)
    if reset is not None:
        sc.reset_state, sc.reset_after_s, sc.reset_cause = reset
    return app, execute(sc, elf, board, layout, None, quiet=True)


def fly_all(project: Path, built: tuple[str, str], jobs: dict[str, dict]) -> dict[str, tuple]:
    """Each job's flight (`fly`'s keyword arguments), two at a time: job
    name -> (the application, the flight)."""
    with ThreadPoolExecutor(2) as pool:
        futures = {name: pool.submit(fly, project, built, **kw) for name, kw in jobs.items()}
        return {name: f.result() for name, f in futures.items()}
