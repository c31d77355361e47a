"""The simulated board's harness is compiled once and cached; two threads of
one process (a test's or a study's pool of flights) that need it at the same
moment on an empty cache each get a working one, and no temporary folder is
left behind."""

from __future__ import annotations

import os
import shutil
from concurrent.futures import ThreadPoolExecutor

import pytest

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                reason="gcc and libsimavr-dev are needed (make setup)")


def test_two_threads_build_the_harness_at_once(tmp_path, monkeypatch):
    from fswkit.sim.board import cache_dir, harness

    monkeypatch.setenv("FSW_CACHE_DIR", str(tmp_path))
    with ThreadPoolExecutor(2) as pool:
        exes = list(pool.map(lambda _: harness(), range(2)))
    assert exes[0] == exes[1] and os.access(exes[0], os.X_OK)
    assert [n for n in os.listdir(cache_dir()) if ".tmp" in n] == []
