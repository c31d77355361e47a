"""Every real-flight tape of ../shared/flights/ through examples/hpr's
machines in the reference interpreter (binary32), on the inputs the
simulated board's replay gives them (fswkit.plant.tape_interp): all
eight tapes in seconds, each held to every check of `fsw sim --tape` —
no pyro pin before burnout, the drogue pin within -0.5/+1.0 s of the
barometric apogee, the main pin within ±15 m of MAIN_ALT where the tape
comes down to it, the landing within -1/+10 s of the tape's where it
lands, none in the air where it does not. The board's replays
(test_hpr_tapes.py and tools/bench_tapes.py) agree with
these within a step or two. Skips only when the tapes' folder is absent
(a user's clone)."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES, ROOT

FLIGHTS = ROOT.parent / "shared" / "flights"
HPR = EXAMPLES / "hpr"

TAPES = sorted(p.stem for p in FLIGHTS.glob("*.csv")) if FLIGHTS.is_dir() else []


@pytest.fixture(scope="module")
def hpr_app():
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.link.layout import from_app
    from fswkit.plant import tape_replay as tr
    from fswkit.target.build import load

    diags = Diagnostics()
    app = load(str(HPR), diags)
    assert app is not None, diags.render()
    return app, tr.load_config(app, from_app(app), None)


@pytest.mark.skipif(not FLIGHTS.is_dir(), reason=f"{FLIGHTS} is absent: no real flight to replay")
def test_the_shared_folder_holds_the_eight_tapes():
    assert len(TAPES) == 8, TAPES


@pytest.mark.parametrize("name", TAPES)
def test_every_tape_meets_every_check_through_the_interpreter(name, hpr_app):
    from fswkit.plant import tape_interp as ti
    from fswkit.plant import tape_replay as tr

    app, cfg = hpr_app
    tape, truth = tr.load_tape(str(FLIGHTS / f"{name}.csv"), cfg)
    rp = ti.replay(app, cfg, tape, truth=truth)
    nums, checks, notes = tr.evaluate(rp, cfg, truth, tape)
    said = f"{name}: {nums}; " + "; ".join(f"{c.name}: {c.detail}" for c in checks) + "; " + "; ".join(notes)
    assert checks and all(c.passed for c in checks), said
    assert nums["boost_pyro"] == 0, said
    assert -0.5 <= nums["apogee_err_s"] <= 1.0, said
    assert ("main_err_m" in nums) == (name != "halcyon_cats"), said  # halcyon's log ends 441 m up
    assert ("landing_err_s" in nums) == (truth.landing_s is not None), said
    landed = next((t for t, _, s in rp.run.transitions if s == cfg.states["landed"]), None)
    assert truth.landing_s is not None or landed is None or landed > tape.end, said  # no landing in the air


def test_the_interpreter_replays_the_same_perturbed_runs_as_the_board_draws(hpr_app):
    """--perturb's seeds: the same seed gives the same perturbations, so
    the same events."""
    from fswkit.plant import tape_interp as ti
    from fswkit.plant import tape_replay as tr

    if "ndrt2020_raven" not in TAPES:
        pytest.skip("ndrt2020_raven is not among the tapes")
    app, cfg = hpr_app
    tape, truth = tr.load_tape(str(FLIGHTS / "ndrt2020_raven.csv"), cfg)
    a = ti.perturbed(app, cfg, tape, truth, 2, 7)
    b = ti.perturbed(app, cfg, tape, truth, 2, 7)
    assert [n for n, _ in a] == [n for n, _ in b]
    assert a[0][0] != a[1][0]  # two runs, two draws
