"""A channel table's rows are run by the `inputs` task (its `i` rows) and
the `outputs` task (its `o` rows). A sensor table without an `inputs` task
and pyro channels without an `outputs` task were refused, but channel rows
were not: the tank rig with its `sense inputs` task removed passed
`fsw check` and built, and its pressure transducer was never read
(`tankPressure` stayed 0, the vent never opened); without `act outputs`
the valve's pin was never driven. Now a table with input rows and no
`inputs` task, or output rows (other than pyro channels, which report
their own) and no `outputs` task, is an error at the table's `io` line of
the .app."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES, run_fsw

TANK = EXAMPLES / "tank"
ROCKET = EXAMPLES / "rocket"


def copy(src, dst, names):
    for name in names:
        (dst / name).write_bytes((src / name).read_bytes())
    return dst


def drop(path, line_start):
    lines = path.read_text().splitlines(keepends=True)
    kept = [ln for ln in lines if not ln.startswith(line_start)]
    assert len(kept) == len(lines) - 1
    path.write_text("".join(kept))


def io_line(app_text, table):
    return next(n for n, ln in enumerate(app_text.splitlines(), 1) if ln.startswith("io") and table in ln)


@pytest.fixture
def tank(tmp_path):
    return copy(TANK, tmp_path, ("tank.sv", "tank.sm", "tank.app", "tank.aio", "tank.dio"))


def test_input_rows_without_an_inputs_task_are_refused(tank):
    drop(tank / "tank.app", "sense ")
    r = run_fsw("check", "tank.app", cwd=tank)
    assert r.code == 1 and "internal error" not in r.err, r.err
    line = io_line((tank / "tank.app").read_text(), "tank.aio")
    assert f"application config error @ tank.app:{line}:" in r.err, r.err
    assert "`inputs` task" in r.err and "tankPressure" in r.err, r.err
    assert "tank.dio" not in r.err  # its one row is an output


def test_output_rows_without_an_outputs_task_are_refused(tank):
    drop(tank / "tank.app", "act ")
    r = run_fsw("check", "tank.app", cwd=tank)
    assert r.code == 1, r.err
    line = io_line((tank / "tank.app").read_text(), "tank.dio")
    assert f"application config error @ tank.app:{line}:" in r.err, r.err
    assert "`outputs` task" in r.err and "valveOpen" in r.err, r.err


def test_pyro_outputs_are_reported_once_by_the_pyro_check(tmp_path):
    rocket = copy(ROCKET, tmp_path, [p.name for p in ROCKET.iterdir() if p.is_file()])
    (rocket / "rocket.dio").write_text("i 2 armSwitch\no 5 drogue\no 6 main\n")
    drop(rocket / "rocket.app", "act ")
    r = run_fsw("check", "rocket.app", cwd=rocket)
    assert r.code == 1, r.err
    assert "pyro channels need an `outputs` task" in r.err, r.err
    assert r.err.count("error @") == 1, r.err


def test_the_tank_with_both_tasks_is_accepted(tank):
    r = run_fsw("check", "tank.app", cwd=tank)
    assert r.code == 0, r.err
