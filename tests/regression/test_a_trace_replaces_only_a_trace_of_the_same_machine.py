"""`fsw test --trace FILE` took any CSV whose first line began `step,` for
an earlier trace and replaced it without `--force`: a test-stand crew's own
`steps.csv` (`step,valve,seconds`, a hot-fire sequence) was gone. A trace
now replaces, unasked, only a file whose whole first line is the header this
machine's trace has (`step,` and its variables, in the trace's order); any
other file, another machine's trace included, only with `--force`."""

from __future__ import annotations

import shutil

import pytest

from conftest import EXAMPLES, run_fsw


@pytest.fixture
def tank(tmp_path):
    shutil.copytree(EXAMPLES / "tank", tmp_path / "tank", ignore=shutil.ignore_patterns("build"))
    return tmp_path / "tank"


def test_a_users_csv_beginning_step_is_kept(tank):
    steps = tank / "steps.csv"
    steps.write_text("step,valve,seconds\n1,open,2.5\n2,closed,0\n")
    r = run_fsw("test", str(tank / "tank.ss"), "--trace", str(steps))
    assert r.code == 1 and "--force" in r.err, r.err
    assert steps.read_text() == "step,valve,seconds\n1,open,2.5\n2,closed,0\n"


def test_an_earlier_trace_of_the_machine_is_replaced(tank):
    trace = tank / "trace.csv"
    assert run_fsw("test", str(tank / "tank.ss"), "--trace", str(trace)).code == 0
    first = trace.read_bytes()
    trace.write_bytes(first[:first.index(b"\n") + 1] + b"1,0\n")  # cut short: a header of its own still
    r = run_fsw("test", str(tank / "tank.ss"), "--trace", str(trace))
    assert r.code == 0, r.err
    assert trace.read_bytes() == first


def test_a_header_that_only_begins_as_the_traces_is_kept(tank):
    trace = tank / "trace.csv"
    assert run_fsw("test", str(tank / "tank.ss"), "--trace", str(trace)).code == 0
    head = trace.read_bytes().split(b"\r\n", 1)[0]
    mine = tank / "mine.csv"
    mine.write_bytes(head + b",myNotes\r\n1,0\r\n")  # the trace's columns and one more of the user's
    r = run_fsw("test", str(tank / "tank.ss"), "--trace", str(mine))
    assert r.code == 1 and "--force" in r.err, r.err
    assert mine.read_bytes() == head + b",myNotes\r\n1,0\r\n"
