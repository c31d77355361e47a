"""The rocket at 1 kHz with `[time] source clock, unit ms` passed `fsw
check` and `fsw build`, then both machines were safed in flight: the Uno's
millis() moves on every 1.024 ms (16,384 CPU cycles), so between two steps
1 ms apart `G` sometimes stood still, and a machine whose time does not
increase is safed. A time source too coarse for a machine task's rate is
refused where the task is written."""

from __future__ import annotations

import dataclasses
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


def test_machines_faster_than_millis_are_refused(tmp_path):
    """A board whose executor keeps no timer of its own (no `executor.timer`:
    the Arduino core's millis() is the clock) refuses the 1 kHz rocket with
    the millisecond clock where millis() is coarser than a step, at both
    machine tasks."""
    from fswkit.autocode import appcheck
    from fswkit.autocode import model as M
    from fswkit.autocode.board import load_board

    class Said:
        def __init__(self):
            self.lines = []

        def at(self, line, col, msg):
            self.lines.append(f"{line}:{col}: {msg}")

    # an 8 MHz board: millis() moves on every 2.048 ms, slower than 500 steps a second
    rate = 500
    board = dataclasses.replace(load_board("uno"), f_cpu=8_000_000, timer="", timer_pins=frozenset())
    tasks = [M.Task(name, "machine", i, rate, 1, None, "enabled", line)
             for i, (line, name) in enumerate(((24, "nav"), (25, "mission")))]
    r = Said()
    appcheck._clock_steps(tasks, board, "clock", "ms", r)
    text = "\n".join(r.lines)
    assert len(r.lines) == 2, text
    for line, task in ((24, "nav"), (25, "mission")):
        assert f"{line}:1: " in text, text
        assert (f"task `{task}` steps every {1000000 // rate} us, but with `source clock` and `unit ms` the uno's "
                "millis() moves on only every 2048 us: `G` would sometimes not increase between its steps "
                "(use `unit us`, `source cycle`, or a rate of at most 488 Hz)") in text, text


@pytest.mark.parametrize("rate, source, unit, board", [
    (500, "clock", "ms", "uno"),  # 2 ms a step: millis() moves on at least once
    (1000, "clock", "us", "uno"),  # micros() moves on every 4 us
    (1000, "cycle", "ms", "uno"),  # G counts executor cycles: exact
    (500, "clock", "ms", "mega2560"),  # the executor's Timer1 keeps an exact clock
])
def test_time_sources_fine_enough_are_accepted(fsw, tmp_path, rate, source, unit, board):
    r = fsw("check", str(rocket(tmp_path, rate, source, unit, board)))
    assert r.code == 0, r.err


@pytest.mark.parametrize("board", ["uno", "native"])
def test_a_machine_stepping_every_clock_unit_is_refused(fsw, tmp_path, board):
    """Even with an exact millisecond clock (the executor's timer), a machine
    stepping every millisecond would read the same G in a cycle that starts
    late as in the one before it, and be safed: refused where the task is
    written."""
    app = rocket(tmp_path, 1000, board=board)
    r = fsw("check", str(app))
    assert r.code == 1
    rows = app.read_text().splitlines()
    for task in ("nav", "mission"):
        line = next(i for i, row in enumerate(rows, 1) if row.startswith(f"{task} ") and " machine " in row)
        assert f"application config error @ {app}:{line}:1:" in r.err, r.err
        assert (f"task `{task}` steps every 1 ms and `G` is the clock in ms: a cycle that starts late would "
                "step in the same ms as the one before, and a machine whose time does not increase is safed "
                "(use `unit us`, `source cycle`, or a slower rate)") in r.err, r.err
