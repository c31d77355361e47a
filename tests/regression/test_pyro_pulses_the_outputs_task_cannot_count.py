"""A pyro channel's pulse is counted down in runs of the fastest `outputs`
task, in 16 bits (fsw_io.h `PyroGate::left`). examples/hpr with its
executor and outputs task at 100,000 Hz and `pulse=1` passed `fsw check`,
and `fsw build` then stopped ("a pulse of 1 s is 100000 runs of `act`,
more than 65535"): configuration the check accepted did not build. The
check now refuses it at the `pulse=` value and says the longest pulse at
that rate."""

from __future__ import annotations

import shutil

from conftest import EXAMPLES


def hpr(tmp_path, outputs_hz: int, pulse: str = "1"):
    shutil.copytree(EXAMPLES / "hpr", tmp_path / "hpr")
    app = tmp_path / "hpr" / "hpr.app"
    text = app.read_text()
    for old, new in (("rate  100\n", f"rate  {outputs_hz}\n"),
                     ("act      outputs           rate=100", f"act      outputs           rate={outputs_hz}"),
                     ("arm=armSwitch  pulse=1", f"arm=armSwitch  pulse={pulse}")):  # both channels
        assert old in text
        text = text.replace(old, new)
    app.write_text(text)
    return app


def test_a_pulse_of_more_runs_than_the_gate_counts_is_refused_at_its_value(fsw, tmp_path):
    r = fsw("check", str(hpr(tmp_path, 100000)))
    assert r.code == 1, r.out
    assert "hpr.app:58:32:" in r.err
    assert "a pulse of 1 s is 100,000 runs of the fastest `outputs` task, `act` (100000 Hz)" in r.err
    assert "at most 65,535 runs, 0.65535 s at that rate" in r.err
    assert "Traceback" not in r.err


def test_the_longest_pulse_the_gate_counts_is_accepted(fsw, tmp_path):
    r = fsw("check", str(hpr(tmp_path, 100000, "0.65535")))
    assert r.code == 0, r.err
