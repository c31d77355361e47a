"""The one build service (fswkit.target.build.firmware: generate, make,
size, budget) behind `fsw build`, `fsw flash`, `fsw sim` and the plant
runs. `fsw sim`, with or without a plant, refuses firmware over the
application's [budget] with the message `fsw build` gives: which memory, by
how much, and what uses it, named by the config lines it comes from."""

from __future__ import annotations

import os
import shutil

import pytest

from conftest import EXAMPLES

TANK = EXAMPLES / "tank"
needs_avr = pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")
FLASH_BUDGET = 4096  # the tank's firmware is about 10 KB


def _over_budget(tmp_path):
    project = tmp_path / "tank"
    shutil.copytree(TANK, project, ignore=shutil.ignore_patterns("build"))
    with open(project / "tank.app", "a") as f:
        f.write(f"\n[budget]\nflash {FLASH_BUDGET}\n")
    return project


@pytest.fixture(scope="module")
def over_budget(tmp_path_factory):
    """The tank over its [budget], copied once for the module: its tests
    build it into its own build folder (build/uno), where each after the
    first finds it built."""
    return _over_budget(tmp_path_factory.mktemp("over"))


def _load(project):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import load

    app = load(str(project), Diagnostics())
    assert app is not None
    return app


@needs_avr
def test_the_service_builds_sizes_and_judges_the_budget(over_budget):
    from support.simfw import kept_folder

    from fswkit.target.build import budget, firmware

    app = _load(over_budget)
    assert budget(app) == {"flash": (FLASH_BUDGET, "the application's [budget]"),
                           "RAM": (2048, "the uno's memory")}
    out = over_budget / "build" / "uno"
    built = firmware(app, str(out))
    assert built.elf == str(out / "tank.elf") and os.path.isfile(built.hex)
    assert built.size.flash > FLASH_BUDGET == built.size.flash_budget and not built.fits
    assert built.report.startswith("the firmware does not fit the application's [budget]: flash ")
    assert "what uses flash, largest first:" in built.report
    within = firmware(_load(TANK), str(kept_folder(TANK, "uno")))  # kept between runs (support.simfw)
    assert within.fits and within.report is None and within.size.flash_budget == 32256


def test_a_native_build_has_no_size_to_judge(tmp_path):
    if shutil.which("g++") is None:
        pytest.skip("no host C++ compiler")
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import firmware, load

    built = firmware(load(str(TANK), Diagnostics(), "native"), str(tmp_path / "native"))
    assert built.size is None and built.fits and built.elf is None and built.hex is None
    assert os.access(built.artifact, os.X_OK)


@needs_avr
def test_fsw_sim_honours_the_budget_as_fsw_build_does(fsw, over_budget, tmp_path):
    # all three into the project's build folder (the first may find it built)
    project = over_budget
    b = fsw("build", str(project))
    assert b.code == 1, b.err
    report = b.err.split("fsw build: ", 1)[1]
    assert report.startswith("the firmware does not fit the application's [budget]: flash ")
    assert f" B of {FLASH_BUDGET:,} B, " in report and "B  machine tank, tank.sm: its states' code" in report

    s = fsw("sim", str(project), "--fast", "--duration", "0.1")
    assert s.code == 1 and s.out == ""
    assert "fsw sim: " + report in s.err

    flight = tmp_path / "flight"
    p = fsw("sim", str(project), "--plant", "tank", "--out", str(flight))
    assert p.code == 1 and p.out == ""
    assert "fsw sim: " + report in p.err
    assert not (flight / "summary.txt").exists()
