"""The rocket with its flight recorder on an SPI NOR flash
(tools/bench_recorder.py's variant): every flight element at 100 Hz from
launch to landing, a closed-loop flight on the simulated Uno with the
harness's W25Q chip on D10. The record covers the flight without a gap and
matches the telemetry value for value."""

from __future__ import annotations

import os
import shutil

import pytest

from conftest import run_fsw
from support.tools import tool

pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                reason="gcc-avr and libsimavr-dev are needed (make setup)")


def bench_recorder():
    return tool("bench_recorder")


def test_the_rocket_records_every_flight_element_at_100_hz_on_a_flash(tmp_path):
    project = bench_recorder().variant_spi(tmp_path / "rocket-spi")
    r = run_fsw("sim", str(project), "--plant", "rocket", "--out", str(tmp_path / "out"))
    assert r.code == 0, r.out + r.err
    assert "an SPI NOR flash of 1,048,576 B" in r.out
    assert ("PASS  the record covers 0.5 s before launch to landing at the log's rates (100/10 Hz)" in r.out
            and "no sample missing" in r.out)
    assert "PASS  the record matches the telemetry value for value" in r.out
    log = tmp_path / "out" / "record.log"
    rows = run_fsw("log2csv", str(log)).out.splitlines()
    assert rows[0].split(",")[4:] == ["state", "state name", "altitude", "accel", "pressure", "drogue", "main"]
    assert len(rows) > 4000  # 100 Hz over a 43 s flight
