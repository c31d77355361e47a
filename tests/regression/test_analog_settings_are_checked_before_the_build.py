"""`fsw sim PROJECT --analog PIN=VOLTS` and `--fw-params FILE` (the board
alone, no plant) were checked only after building the firmware: a pin the
board does not have, or a parameter the project does not declare, built
the whole firmware (into the build folder) before saying so; with a plant
or a tape, `--fw-params` was checked first. And a pin given by its number
(`14=1.0`, A0 on an Uno), which the I/O tables and the simulated board
both take, was refused. Both are now checked before any build, and a pin
number names the board's analog input at that pin."""

from __future__ import annotations

import shutil

from conftest import EXAMPLES, run_fsw


def test_a_pin_the_board_lacks_is_refused_before_the_build(tmp_path):
    out = tmp_path / "out"
    r = run_fsw("sim", str(EXAMPLES / "tank"), "--board", "uno", "--analog", "A9=1", "--out", str(out))
    assert r.code == 2 and "no analog input `A9`" in r.err, r.err
    assert "built" not in r.err and not out.exists(), r.err
    r = run_fsw("sim", str(EXAMPLES / "tank"), "--board", "uno", "--analog", "A0", "--out", str(out))
    assert r.code == 2 and "expected PIN=VOLTS" in r.err and not out.exists(), r.err


def test_a_pin_number_names_the_analog_input_at_that_pin(tmp_path):
    proj = tmp_path / "tank"
    shutil.copytree(EXAMPLES / "tank", proj, ignore=shutil.ignore_patterns("build"))
    out = tmp_path / "out"
    r = run_fsw("sim", str(proj), "--board", "uno", "--analog", "14=1.0", "--duration", "0.2", "--fast",
                "--out", str(out))
    assert r.code == 0, r.err
    assert "duration reached" in r.err, r.err
    r = run_fsw("sim", str(proj), "--board", "uno", "--analog", "13=1.0", "--duration", "0.2", "--out", str(out))
    assert r.code == 2 and "no analog input `13`" in r.err and "A0 (14)" in r.err, r.err


def test_firmware_parameters_are_checked_before_the_build(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("NOPE = 3\n")
    out = tmp_path / "out"
    r = run_fsw("sim", str(EXAMPLES / "rocket"), "--fw-params", str(bad), "--duration", "0.1", "--out", str(out))
    assert r.code == 2 and f"{bad}:1:1: unknown parameter `NOPE`" in r.err, r.err
    assert "built" not in r.err and not out.exists(), r.err
