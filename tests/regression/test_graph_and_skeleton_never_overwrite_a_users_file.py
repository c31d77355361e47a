"""`fsw skeleton tank.sm -o tank.ss` replaced the state script a user had
written beside the machine, and `fsw graph -o` any file at all, without a
word. Each replaces only its own earlier output (its text names the command
in its first lines) or an empty file; anything else needs --force, and is
then replaced whole."""

from __future__ import annotations

import shutil

import pytest
from conftest import EXAMPLES, run_fsw


@pytest.fixture
def tank(tmp_path):
    for name in ("tank.sm", "tank.sv", "tank.ss"):
        shutil.copy(EXAMPLES / "tank" / name, tmp_path / name)
    return tmp_path


@pytest.mark.parametrize("command,args", [("skeleton", ()), ("graph", ()), ("graph", ("--format", "mermaid"))])
def test_a_file_the_user_wrote_is_not_replaced_unasked(tank, command, args):
    script = tank / "tank.ss"
    mine = script.read_bytes()
    r = run_fsw(command, str(tank / "tank.sm"), *args, "-o", str(script))
    assert r.code == 1, r.err
    assert f"{script}" in r.err and "--force" in r.err and "Traceback" not in r.err
    assert script.read_bytes() == mine
    notes = tank / "notes.txt"
    notes.write_text("launch checklist\n")
    assert run_fsw(command, str(tank / "tank.sm"), *args, "-o", str(notes)).code == 1
    assert notes.read_text() == "launch checklist\n"
    r = run_fsw(command, str(tank / "tank.sm"), *args, "-o", str(notes), "--force")
    assert r.code == 0, r.err
    assert f"fsw {command}" in notes.read_text()[:300]


@pytest.mark.parametrize("command,args", [("skeleton", ()), ("graph", ()), ("graph", ("--format", "mermaid"))])
def test_its_own_output_and_an_empty_file_are_replaced(tank, command, args):
    out = tank / "out.txt"
    out.write_text("")
    assert run_fsw(command, str(tank / "tank.sm"), *args, "-o", str(out)).code == 0
    first = out.read_text()
    assert first and f"fsw {command}" in first[:300]
    r = run_fsw(command, str(tank / "tank.sm"), *args, "-o", str(out))
    assert r.code == 0, r.err
    assert out.read_text() == first
    # the other format of `fsw graph` is its output too
    if command == "graph":
        other = ("--format", "dot") if args else ("--format", "mermaid")
        assert run_fsw(command, str(tank / "tank.sm"), *other, "-o", str(out)).code == 0


def test_a_trace_replaces_only_an_earlier_trace(tank):
    """`fsw test --trace FILE` wrote its CSV over any file: a trace replaces
    an earlier trace (its header begins `step,`) or an empty file only."""
    notes = tank / "notes.csv"
    notes.write_text("date,what\n2026-12-06,hot fire\n")
    r = run_fsw("test", str(tank / "tank.ss"), "--trace", str(notes))
    assert r.code == 1 and "--force" in r.err, r.err
    assert notes.read_text() == "date,what\n2026-12-06,hot fire\n"
    trace = tank / "trace.csv"
    assert run_fsw("test", str(tank / "tank.ss"), "--trace", str(trace)).code == 0
    first = trace.read_text()
    assert first.startswith("step,")
    assert run_fsw("test", str(tank / "tank.ss"), "--trace", str(trace)).code == 0
    assert trace.read_text() == first
    assert run_fsw("test", str(tank / "tank.ss"), "--trace", str(notes), "--force").code == 0
    assert notes.read_text() == first
