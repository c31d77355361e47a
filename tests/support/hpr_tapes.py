"""Real flights through examples/hpr (tests/examples/test_hpr_tapes*.py):
every tape of ../shared/flights/ replayed whole and open loop on the
simulated Uno as `fsw sim examples/hpr --tape` does, through the main's
deployment (the 2,239 s of the eight tapes whole are `make bench`'s). The tapes are shared out
over three test files so that pytest-xdist, which keeps a file on one
worker, spreads them over the cores; `group` says which file replays a
tape, and every tape of the folder falls in exactly one group. The
costliest replay is the longest one through the main, not the longest
tape: halcyon's 659 s end 90 s in (its log ends above the main's
altitude), lince's 445 s run 406 s.
Skips only when the tapes' folder is absent (a user's clone) or the AVR
tools are missing."""

from __future__ import annotations

import os
import shutil

import pytest

from conftest import EXAMPLES, ROOT

FLIGHTS = ROOT.parent / "shared" / "flights"
TAPES = sorted(p.stem for p in FLIGHTS.glob("*.csv")) if FLIGHTS.is_dir() else []
HPR = EXAMPLES / "hpr"
LONGEST = "lince_cats"  # 406 s replayed, the most of any tape (a third of the CPU): a file of its own

MARKS = [
    pytest.mark.skipif(not FLIGHTS.is_dir(), reason=f"{FLIGHTS} is absent (the shared flight tapes live beside "
                       "the kit, not in a clone): no real flight to replay"),
    pytest.mark.skipif(shutil.which("avr-g++") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                       reason="gcc-avr and libsimavr-dev are needed (make setup)"),
]


def group(name: str) -> str:
    """The file that replays tape `name`: "longest", "altos_raven" or "cats"."""
    if name == LONGEST:
        return "longest"
    if any(k in name for k in ("telemega", "telemetrum", "raven")):
        return "altos_raven"
    return "cats"


def tapes(of: str) -> list[str]:
    return [t for t in TAPES if group(t) == of]


def build_hpr(project=HPR):
    """(app, layout, tape config, elf, board) of examples/hpr, or of another
    project that replays tapes (examples/hpr_digital), its firmware kept
    in build/sim-tests/ (support.simfw.kept_sim: built once for every test
    file, and again only for what changed)."""
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.link.layout import from_app
    from fswkit.plant import tape_replay as tr
    from fswkit.target.build import load
    from support.simfw import kept_sim

    diags = Diagnostics()
    app = load(str(project), diags)
    assert app is not None, diags.render()
    layout = from_app(app)
    cfg = tr.load_config(app, layout, None)
    elf, board = kept_sim(project)  # built into build/sim-tests/, once for every test file
    return app, layout, cfg, elf, board


def through_main(tape, truth, main_alt: float):
    """The tape and its truth cut 15 s after the barometric altitude comes
    down to `main_alt` after apogee (60 s after apogee when it never does):
    what `make test` replays on the board. The landing is then past the
    tape's end, so the truth has none; `make bench` (tools/bench_tapes.py)
    replays every tape whole, landing included."""
    import dataclasses

    import numpy as np

    from fswkit.plant import tape_replay as tr

    t, h = tr.smoothed_altitude(tape, tr._pad(tape, truth))
    after = (t > truth.apogee_s) & (h <= main_alt)
    cut = (float(t[after][0]) + 15.0) if after.any() else truth.apogee_s + 60.0
    if cut >= tape.end:
        return tape, truth
    k = int(np.searchsorted(tape.time, cut))
    tape = dataclasses.replace(tape, time=tape.time[:k], pressure=tape.pressure[:k], accel=tape.accel[:k])
    truth = dataclasses.replace(truth, landing_s=None, landing_alt_m_agl=None, log_end_s=float(tape.time[-1]))
    return tape, truth


def replay_and_check(name: str, hpr_firmware) -> None:
    """Every check passes, no pyro pin in boost, the drogue pin within
    -0.5/+1.0 s of the barometric apogee, the main pin within ±15 m of
    MAIN_ALT = 300 m where the tape comes down to it. The tape is replayed
    through the main's deployment (through_main); `make bench`
    (tools/bench_tapes.py) replays each whole and prints the table."""
    from fswkit.plant import tape_replay as tr

    app, layout, cfg, elf, board = hpr_firmware
    tape, truth = tr.load_tape(str(FLIGHTS / f"{name}.csv"), cfg)
    tape, truth = through_main(tape, truth, cfg.main_alt)
    o = tr.execute(tape, truth, cfg, app, elf, board, layout, None)
    text = o.report.text()
    assert o.report.checks and all(c.passed for c in o.report.checks), text
    n = o.numbers
    assert n["boost_pyro"] == 0, text
    assert -0.5 <= n["apogee_err_s"] <= 1.0, text  # drogue pin − barometric apogee
    assert cfg.main_alt == 300.0
    assert ("main_err_m" in n) == (name != "halcyon_cats"), text  # halcyon's log ends 441 m up
    if "main_err_m" in n:
        assert abs(n["main_err_m"]) <= 15.0, text  # truth altitude at the main pin − 300 m
    assert ("landing_err_s" in n) == (truth.landing_s is not None), text
