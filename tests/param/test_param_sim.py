"""Parameters on the simulated Uno (tests/param/many: 64 F32 parameters,
its link at 9,600 baud): a list and a whole file loaded through a link that
drops 20 % of the frames each way complete and verify; a power cut after
any EEPROM byte write of a load or a save leaves the old set or the new
one, never a mix, from a bank whose CRC holds (every 9th write here, every
one in `make bench`); `fsw sim --params` boots a firmware with a file's
values. Timings are in tools/bench_params.py, not here."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                reason="gcc-avr and libsimavr-dev are needed (make setup)")
MANY = Path(__file__).resolve().parent / "many"


@pytest.fixture(scope="module")
def many(tmp_path_factory):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import firmware, load

    app = load(str(MANY), Diagnostics())
    assert app is not None
    built = firmware(app, str(tmp_path_factory.mktemp("many")))
    assert built.fits, built.report
    return app, built.artifact


@pytest.mark.parametrize("seed", [1, 2])
def test_list_and_load_through_a_lossy_link(many, seed):
    from fswkit.param.sim import lossy_list_and_load

    app, elf = many
    r = lossy_list_and_load(elf, "uno", app, 0.2, seed)
    assert r.up_dropped > 0 and r.down_dropped > 0  # the link did lose frames
    assert r.resent > 0
    assert r.verified and r.values_ok


@pytest.mark.parametrize("op", ["load", "save"])
def test_a_power_cut_at_a_write_leaves_the_old_or_the_new_set(many, op):
    from fswkit.param.sim import power_cuts

    app, elf = many
    r = power_cuts(elf, "uno", app, stride=9, op=op)
    assert r.writes == 1 + 256 + 9  # clear the magic, 64 values, the header, the magic
    assert r.bad == []
    assert r.new == 1 and r.old == r.cases - 1  # only the cut after the magic keeps the new set
