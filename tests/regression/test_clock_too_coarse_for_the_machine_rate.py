"""The rocket at 1 kHz with `[time] source clock, unit ms` passed `fsw
check` and `fsw build`, then both machines were safed in flight: the Uno's
millis() moves on every 1.024 ms (16,384 CPU cycles), so between two steps
1 ms apart `G` sometimes stood still, and a machine whose time does not
increase is safed. A time source too coarse for a machine task's rate is
refused where the task is written."""

from __future__ import annotations

import re
import shutil

import pytest

from conftest import EXAMPLES


def rocket(tmp_path, rate: int, source: str = "clock", unit: str = "ms", board: str = "uno"):
    project = tmp_path / "rocket"
    shutil.copytree(EXAMPLES / "rocket", project, ignore=shutil.ignore_patterns("build"))
    app = project / "rocket.app"
    text = app.read_text()
    text = re.sub(r"rate=100\b", f"rate={rate}", text).replace("rate  100", f"rate  {rate}")
    text = text.replace("source clock", f"source {source}").replace("unit   ms", f"unit   {unit}")
    app.write_text(text.replace("board uno", f"board {board}"))
    return app


def test_machines_faster_than_millis_are_refused(fsw, tmp_path):
    rate = 1000  # the one rate between millis()'s 976.6 Hz and `G`'s own 1000 Hz that divides 1,000,000
    app = rocket(tmp_path, rate)
    r = fsw("check", str(app))
    assert r.code == 1
    for line, task in ((24, "nav"), (25, "mission")):
        assert f"application config error @ {app}:{line}:1:" in r.err, r.err
        assert (f"task `{task}` steps every {1000000 // rate} us, but with `source clock` and `unit ms` the uno's "
                "millis() moves on only every 1024 us: `G` would sometimes not increase between its steps "
                "(use `unit us`, `source cycle`, or a rate of at most 976 Hz)") in r.err, r.err


@pytest.mark.parametrize("rate, source, unit, board", [
    (500, "clock", "ms", "uno"),  # 2 ms a step: millis() moves on at least once
    (1000, "clock", "us", "uno"),  # micros() moves on every 4 us
    (1000, "cycle", "ms", "uno"),  # G counts executor cycles: exact
    (1000, "clock", "ms", "native"),  # the native build's clock is exact
])
def test_time_sources_fine_enough_are_accepted(fsw, tmp_path, rate, source, unit, board):
    r = fsw("check", str(rocket(tmp_path, rate, source, unit, board)))
    assert r.code == 0, r.err
