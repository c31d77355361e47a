"""Power cuts while the recorder writes, on the simulated Uno
(fswkit.testing.recorder_cuts): resets at random moments and cuts after
random EEPROM byte writes. No corrupt record is accepted, nothing but the
record being written is lost, earlier records stay byte for byte. `make
bench` runs 1,000 cuts (tools/bench_recorder.py); this runs 200."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.app import load_app
from fswkit.autocode.recorder import RECORDER_SIZE, plan
from fswkit.testing.recorder_cuts import power_cuts
from support.simfw import kept_sim
pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                reason="gcc-avr and libsimavr-dev are needed (make setup)")
RIG = Path(__file__).resolve().parent / "logged"


@pytest.fixture(scope="module")
def built():
    elf, _board = kept_sim(RIG)
    app = load_app(str(RIG / "logged.app"), Diagnostics())
    return Path(elf), plan(app)


def test_the_recorder_record_is_the_size_the_tools_count(built):
    from fswkit.sim.board import SimBoard

    elf, p = built
    with SimBoard(str(elf), "uno", uart="none") as b:
        _, size = b.symbol("fsw_gen::(anonymous namespace)::rec")
        ring = b.symbol("fsw_gen::(anonymous namespace)::log_ring")[1]
        fifo = b.symbol("fsw_gen::(anonymous namespace)::log_fifo")[1]
        last = b.symbol("fsw_gen::(anonymous namespace)::log_last")[1]
    assert size == RECORDER_SIZE
    assert size + ring + fifo + last == p.ram


def test_power_cuts_lose_only_the_record_being_written(built):
    elf, p = built
    rep = power_cuts(str(elf), p, 200, seed=7)
    assert rep.problems == []
    assert rep.cuts == 200 and rep.resets == 100 and rep.write_cuts == 100
    assert rep.flights >= 150 and rep.erases >= 10  # most boots recorded a flight; the store filled again and again
    assert rep.records_checked >= 300 and rep.samples_checked >= 2000
    assert rep.lost_in_progress >= 50  # the random resets did land while a record was being built
