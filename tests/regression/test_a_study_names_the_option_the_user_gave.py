"""`fsw sim PROJECT --plant rocket --runs N --params FW.toml`, where FW.toml
holds the firmware's parameters (top-level `NAME = value` lines) rather
than a plant's, was refused as "--fw-params flies one firmware's
parameters; a study draws its own flights": an option the user never
typed. Now the message names what the user gave: `--params FW.toml` and
what it holds."""

from __future__ import annotations

from pathlib import Path

from conftest import EXAMPLES, run_fsw

ROCKET = EXAMPLES / "rocket"


def test_params_of_the_firmware_with_a_study(tmp_path: Path):
    fw = tmp_path / "fw.toml"
    fw.write_text("MAIN_ALT = 100\n")
    r = run_fsw("sim", str(ROCKET), "--plant", "rocket", "--runs", "2", "--params", str(fw))
    assert r.code == 2, r.err
    assert r.err == (f"fsw sim: --params {fw} holds the firmware's parameters (NAME = value lines, as --fw-params "
                     "takes); a study flies the firmware as built (not with --runs, --jobs, --run or --dispersion)\n")


def test_fw_params_with_a_study(tmp_path: Path):
    fw = tmp_path / "fw.toml"
    fw.write_text("MAIN_ALT = 100\n")
    r = run_fsw("sim", str(ROCKET), "--plant", "rocket", "--run", "2", "--fw-params", str(fw))
    assert r.code == 2, r.err
    assert r.err == ("fsw sim: --fw-params flies one firmware's parameters; a study flies the firmware as built "
                     "(not with --runs, --jobs, --run or --dispersion)\n")
