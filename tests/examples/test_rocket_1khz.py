"""The rocket at 1 kHz: tools/bench_busy.py writes it from examples/rocket's
own configs (rate 1000 for the application and every task; the millisecond
clock if `fsw check` accepts it at that rate, else `[time] source cycle`)
and flies it whole (make bench). Here: it is written as said, checks
cleanly and builds within the rocket's budget."""

from __future__ import annotations

import re
import shutil

import pytest

from conftest import ROOT
from support.tools import tool


def bench_busy():
    return tool("bench_busy")


def test_the_1khz_rocket_is_the_example_at_1khz(tmp_path, fsw):
    folder, source = bench_busy().variant_1khz(str(tmp_path / "rocket-1khz"))
    app = (tmp_path / "rocket-1khz" / "rocket.app").read_text()
    assert re.search(r"(?m)^rate\s+1000$", app)
    tasks = len(re.findall(r"(?m)^\w+\s+(?:uplink|inputs|machine \w+|outputs|telemetry|recorder)\s", app))
    assert tasks == 7 and len(re.findall(r"rate=1000$", app, re.M)) == tasks and "rate=100\n" not in app
    assert source in ("clock", "cycle") and re.search(rf"(?m)^source\s+{source}$", app)
    example = (ROOT / "examples" / "rocket")
    for name in ("nav.sm", "mission.sm", "rocket.sv", "rocket.aio", "rocket.dio", "plant.toml"):
        assert (tmp_path / "rocket-1khz" / name).read_text() == (example / name).read_text()
    r = fsw("check", "--strict", folder)
    assert r.code == 0, r.err


@pytest.mark.skipif(shutil.which("avr-gcc") is None, reason="gcc-avr is needed (make setup)")
def test_the_1khz_rocket_builds_within_the_budget(tmp_path, fsw):
    folder, _ = bench_busy().variant_1khz(str(tmp_path / "rocket-1khz"))
    r = fsw("build", folder, "--out", str(tmp_path / "build"))
    assert r.code == 0, r.err
    assert (tmp_path / "build" / "rocket.elf").exists()
