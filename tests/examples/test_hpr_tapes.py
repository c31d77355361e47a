"""A real flight through examples/hpr: the shortest tape of
../shared/flights/, ndrt2020_raven (91 s of flight, a Featherweight Raven's
recording), replayed whole and open loop on the simulated Uno as `fsw sim
examples/hpr --tape` does: every check passes, the drogue pin comes within
-0.5/+1.0 s of the barometric apogee and the main pin within ±15 m of
MAIN_ALT = 300 m. `make bench` (tools/bench_tapes.py) replays all eight.
Skips only when the tapes' folder is absent (a user's clone) or the AVR
tools are missing."""

from __future__ import annotations

import os
import shutil

import pytest

from conftest import EXAMPLES, ROOT

FLIGHTS = ROOT.parent / "shared" / "flights"
TAPE = FLIGHTS / "ndrt2020_raven.csv"
HPR = EXAMPLES / "hpr"

pytestmark = [
    pytest.mark.skipif(not FLIGHTS.is_dir(), reason=f"{FLIGHTS} is absent (the shared flight tapes live beside "
                       "the kit, not in a clone): no real flight to replay"),
    pytest.mark.skipif(shutil.which("avr-g++") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                       reason="gcc-avr and libsimavr-dev are needed (make setup)"),
]


def test_ndrt2020_raven_replays_through_hpr_with_every_check_passing(tmp_path):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.link.layout import from_app
    from fswkit.plant import tape_replay as tr
    from fswkit.sim.command import build
    from fswkit.target.build import load

    assert TAPE.exists(), f"{TAPE} is missing from {FLIGHTS}"
    diags = Diagnostics()
    app = load(str(HPR), diags)
    assert app is not None, diags.render()
    layout = from_app(app)
    cfg = tr.load_config(app, layout, None)
    tape, truth = tr.load_tape(str(TAPE), cfg)
    built = build(str(HPR), out=str(tmp_path / "firmware"))
    assert not isinstance(built, int), "examples/hpr's firmware did not build"
    elf, board = built
    o = tr.execute(tape, truth, cfg, app, elf, board, layout, None)
    text = o.report.text()
    assert o.report.checks and all(c.passed for c in o.report.checks), text
    n = o.numbers
    assert n["boost_pyro"] == 0, text
    assert -0.5 <= n["apogee_err_s"] <= 1.0, text  # drogue pin − barometric apogee (17.16 s)
    assert cfg.main_alt == 300.0
    assert abs(n["main_err_m"]) <= 15.0, text  # truth altitude at the main pin − 300 m
    assert "landing_err_s" in n, text  # the tape lands: landing is checked

