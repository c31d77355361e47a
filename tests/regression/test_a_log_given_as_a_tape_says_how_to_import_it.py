"""A recorder's log given where a tape goes (`fsw sim PROJECT --tape
LOG.csv`, `fsw tape show LOG.csv`) -- the step a team most often skips --
was `not a fswkit sensor tape: its first line must be ...`, without a
word of the command that makes a tape of it. The message now names
`fsw tape import`."""

from __future__ import annotations

from conftest import run_fsw


def test_a_log_shown_as_a_tape_names_the_import(tmp_path):
    log = tmp_path / "flight.csv"
    log.write_text("ts,filtered_altitude_AGL,filtered_acceleration\n0,0,0\n")
    r = run_fsw("tape", "show", str(log))
    assert r.code == 1
    assert r.err.startswith(f"fsw tape show: {log}:1:1: not a fswkit sensor tape: its first line must be "), r.err
    assert "fsw tape import FORMAT LOG -o TAPE.csv" in r.err, r.err
