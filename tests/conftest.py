"""Shared fixtures: paths and a runner for the `fsw` command in-process
(fswkit.testing.runner, which the tools use too)."""

from __future__ import annotations

import gc
import json
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from fswkit.testing.runner import Ran, run_fsw

# The commands' tests stop runs with SIGHUP as a closed terminal does, and
# a run under `nohup` (or a supervisor that ignores hang-ups) would pass on
# its ignored SIGHUP to every command the tests start, which then rightly
# keep ignoring it: the tests take the terminal's default, as an
# interactive `make test` has it.
if hasattr(signal, "SIGHUP") and signal.getsignal(signal.SIGHUP) == signal.SIG_IGN:
    signal.signal(signal.SIGHUP, signal.SIG_DFL)

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
SHARED = ROOT.parent / "shared"

__all__ = ["ROOT", "EXAMPLES", "SHARED", "Ran", "run_fsw", "fsw", "pio_exe", "needs_pio", "project_config"]

# Tests that press Ctrl-C (SIGINT) on a command need it to reach the command.
# A suite started in the background by a non-interactive shell (`make test &`,
# some CI runners) inherits SIGINT ignored, and an ignored signal stays
# ignored across exec: the commands would never see it. Python's own handler
# here is reset to the default in every child instead.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture
def fsw():
    return run_fsw


# ---- PlatformIO (tests/integrations, tests/new) ----------------------------------

def pio_exe() -> str | None:
    for exe in (os.path.join(os.path.dirname(sys.executable), "pio"), shutil.which("pio")):
        if exe and os.path.isfile(exe):
            return exe
    return None


needs_pio = pytest.mark.skipif(pio_exe() is None, reason="PlatformIO not installed (pip install platformio)")


def project_config(project_dir, tmp_path) -> dict[str, dict]:
    env = dict(os.environ, PLATFORMIO_CORE_DIR=str(tmp_path / "pio-core"),
               PLATFORMIO_SETTING_ENABLE_TELEMETRY="No", PLATFORMIO_SETTING_CHECK_PLATFORMIO_INTERVAL="3650")
    r = subprocess.run([pio_exe(), "project", "config", "-d", str(project_dir), "--json-output"],
                       capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 0, r.stderr + r.stdout
    return {section: dict(options) for section, options in json.loads(r.stdout[r.stdout.index("["):])}


# ---- the collector (Python's cyclic garbage collector) ----

def pytest_collection_finish(session):
    """The cyclic garbage collector's young generation collected every
    20,000 allocations where it was every 700, and each older one after 20
    collections of the one below where it was 10: a worker holds
    everything collection made (the test modules, the kit's modules,
    pytest's items), which each full collection walks again (a system-wide
    profile of `make test` put 5 % of its CPU in the workers' collector).
    Objects are still freed by their reference counts as before; only
    cycles wait longer. (`gc.freeze()` after collection is not used: it
    hides what it froze from `gc.get_referrers`, and Hypothesis's check of
    a registered random generator then warns.)"""
    gc.collect()
    gc.set_threshold(20000, 20, 20)


# ---- the order files are handed out in (make test: pytest-xdist, --dist loadfile) ----

def pytest_configure(config):
    config.addinivalue_line(
        "markers", "costly(seconds, waits=False): a test file's measured cost (wall seconds on one core, its "
        "set-up included; waits=True: most of it spent waiting on the wall clock, a board paced to it or a "
        "browser, not on the CPU): such files are handed to workers first, the costliest first, those that "
        "wait between those that compute")


def pytest_collection_modifyitems(config, items):
    """The costly files first, costliest first, then the rest in their order.
    pytest-xdist hands whole files (--dist loadfile) to the worker that asks
    next in this order (make test passes --no-loadscope-reorder: xdist would
    otherwise put the files with the most tests first): a long file started
    last would keep one core busy after the others are done. Costly files
    that mostly wait (`waits=True`) go out between those that compute, one
    of each in turn: the first four workers got three that wait and one
    that computes, and one core stood idle for the run's first 40 s."""
    def cost(item) -> float:
        mark = item.get_closest_marker("costly")
        return float(mark.args[0]) if mark and mark.args else 0.0

    def waits(item) -> bool:
        mark = item.get_closest_marker("costly")
        return bool(mark and mark.kwargs.get("waits", False))

    order = {id(item): i for i, item in enumerate(items)}
    items.sort(key=lambda item: (-cost(item), item.path.as_posix() if cost(item) else "", order[id(item)]))
    costly = [item for item in items if cost(item)]
    rest = items[len(costly):]
    files: dict = {}  # path -> the file's items, the costliest file first
    for item in costly:
        files.setdefault(item.path, []).append(item)
    computing = [f for f in files.values() if not waits(f[0])]
    waiting = [f for f in files.values() if waits(f[0])]
    turns: list = []
    for i in range(max(len(computing), len(waiting))):
        turns += computing[i:i + 1] + waiting[i:i + 1]
    items[:] = [item for f in turns for item in f] + rest
