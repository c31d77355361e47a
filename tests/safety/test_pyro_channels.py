"""Pyro channels declared in the application config (docs/safety.md): the
examples declare theirs and pass the proof, `fsw check --pyro-report`
prints what can fire each (the rocket's report, word for word), and the
pulse's limits hold at their boundaries."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from conftest import EXAMPLES, ROOT, run_fsw
from fswkit.autocode.app import load_app
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.pyrocheck import pyro_report

GOLDEN = ROOT / "tests" / "autocode" / "golden" / "app"

ROCKET_REPORT = """rocket.app: 2 pyro channels

pyro channel drogue (rocket.app:60)
  output:      pin 5 (rocket.dio:4), pulse 1 s
  arming:      armSwitch (pin 2, rocket.dio:3) reading true
  continuity:  drogueSense (pin A2, rocket.aio:10) at least 1
  machine:     mission; armed states Armed; fire states Apogee
  unarmed:     Safe, Abort (reached without an armed state: none sets it true)
  arming transitions (each requires armSwitch):
    Safe -> Armed  mission.sm:74
  states that can fire it:
    Apogee  .entry  mission.sm:102  drogue = true
      arming path: Safe -> Armed -> Boost -> Coast -> Apogee
  transitions that can fire it:
    Coast -> Apogee  mission.sm:97  (enters Apogee)
    Coast -> Apogee  mission.sm:98  (enters Apogee)

pyro channel main (rocket.app:61)
  output:      pin 6 (rocket.dio:5), pulse 1 s
  arming:      armSwitch (pin 2, rocket.dio:3) reading true
  continuity:  mainSense (pin A3, rocket.aio:11) at least 1
  machine:     mission; armed states Armed; fire states Main
  unarmed:     Safe, Abort (reached without an armed state: none sets it true)
  arming transitions (each requires armSwitch):
    Safe -> Armed  mission.sm:74
  states that can fire it:
    Main  .entry  mission.sm:120  main = true
      arming path: Safe -> Armed -> Boost -> Coast -> Apogee -> Drogue -> Main
  transitions that can fire it:
    Drogue -> Main  mission.sm:115  (enters Main)
    Drogue -> Main  mission.sm:116  (enters Main)
"""


def app_of(path: Path):
    diags = Diagnostics()
    app = load_app(str(path), diags)
    assert app is not None and not diags.errors and not diags.warnings, diags.render()
    return app


@pytest.mark.parametrize("project", ["rocket", "hpr"])
def test_the_examples_declare_their_charges_and_pass(project):
    app = app_of(EXAMPLES / project / f"{project}.app")
    assert [(c.element.name, c.output.pin, [a.element.name for a in c.arm]) for c in app.pyro] == [
        ("drogue", "5", ["armSwitch"]), ("main", "6", ["armSwitch"])]
    mission = app.machines[app.pyro[0].machine]
    assert mission.name == "mission"
    assert [[mission.states[i - 1].name for i in c.fire] for c in app.pyro] == [["Apogee"], ["Main"]]


def test_the_rockets_report():
    assert pyro_report(app_of(EXAMPLES / "rocket" / "rocket.app")) == ROCKET_REPORT


def test_the_report_is_the_same_every_time():
    app = app_of(EXAMPLES / "hpr" / "hpr.app")
    assert pyro_report(app) == pyro_report(app_of(EXAMPLES / "hpr" / "hpr.app"))


def test_fsw_check_prints_the_report():
    r = run_fsw("check", "--pyro-report", str(EXAMPLES / "rocket"))
    assert r.code == 0, r.err
    assert r.out == ROCKET_REPORT
    assert r.err.endswith(", 0 errors, 0 warnings\n")


def test_no_report_where_the_proof_failed():
    r = run_fsw("check", "--pyro-report", "pyro_fires_unarmed.app", cwd=GOLDEN)
    assert r.code == 1 and r.out == ""
    assert "Safe -> Boost -> Apogee" in r.err


def test_the_report_needs_an_application():
    r = run_fsw("check", "--pyro-report", str(EXAMPLES / "rocket" / "mission.sm"))
    assert r.code == 2 and r.out == ""
    assert r.err == "fsw check: --pyro-report needs an application config (.app), or a folder holding one\n"


def test_an_application_without_pyro_channels_says_so():
    r = run_fsw("check", "--pyro-report", "valid.app", cwd=GOLDEN)
    assert (r.code, r.out) == (0, "valid.app: no pyro channels ([pyro] declares them: docs/safety.md)\n")


# ---- the pulse's limits, in pairs -----------------------------------------------------

def project(tmp_path: Path, drogue_pulse: str, outputs_rate: int = 100) -> Path:
    for name in ("pyro.sv", "pyro.sm", "pyro.aio", "pyro.dio", "pyro_valid.app"):
        shutil.copy(GOLDEN / name, tmp_path / name)
    app = tmp_path / "pyro_valid.app"
    text = app.read_text().replace("min=0.5 pulse=1 ", f"min=0.5 pulse={drogue_pulse} ")
    text = text.replace("act outputs rate=100", f"act outputs rate={outputs_rate}").replace("pulse=0.5", "pulse=1")
    app.write_text(text)
    return app


@pytest.mark.parametrize("pulse, rate, ok", [
    ("10", 100, True), ("10.001", 100, False),
    ("0.01", 100, True), ("0.0099", 100, False),
    ("0.1", 10, True), ("0.09", 10, False),  # a period of the outputs task at least
    ("0", 100, False), ("1e-3", 100, False),
])
def test_pulse_limits(tmp_path, pulse, rate, ok):
    r = run_fsw("check", str(project(tmp_path, pulse, rate)))
    assert (r.code == 0) is ok, r.err
    if not ok:
        assert "pulse" in r.err and r.err.count(" error @ ") == 1, r.err


def test_a_parameter_the_ground_may_change_is_no_constant(tmp_path):
    """`drogue = TEST_FIRE` in Safe, with a bool parameter false by default:
    the ground can set the parameter, so the assignment can fire unarmed."""
    app = project(tmp_path, "1")
    sm = tmp_path / "pyro.sm"
    text = sm.read_text().replace("U32 PULSE = 1000\n", "U32 PULSE = 1000\n\n[parameters]\nbool TEST_FIRE = false\n")
    sm.write_text(text.replace("[Safe]\n.entry\n    drogue = false", "[Safe]\n.entry\n    drogue = TEST_FIRE"))
    r = run_fsw("check", str(app))
    assert r.code == 1
    assert ("can fire here, in state `Safe`, which is not one of its fire states (Apogee) and is reached without "
            "passing through an armed state (Armed): Safe\n") in r.err
    assert r.err.count(" error @ ") == 1


def test_the_same_assignment_of_a_constant_false_is_accepted(tmp_path):
    app = project(tmp_path, "1")
    sm = tmp_path / "pyro.sm"
    text = sm.read_text().replace("U32 PULSE = 1000\n", "U32 PULSE = 1000\nbool TEST_FIRE = false @read_only\n")
    sm.write_text(text.replace("[Safe]\n.entry\n    drogue = false", "[Safe]\n.entry\n    drogue = TEST_FIRE"))
    r = run_fsw("check", str(app))
    assert r.code == 0, r.err


def test_two_machines_writing_a_pyro_element_are_refused_once(tmp_path):
    """The one-writer rule and the pyro check would both refuse it: the
    error is the pyro check's, with its reason, and only once."""
    r = run_fsw("check", "pyro_second_machine.app", cwd=GOLDEN)
    assert r.code == 1 and r.err.count(" error @ ") == 1
    assert "a second writer could fire the charge" in r.err
