"""`fsw tape import eggtimer|rrc3` read a log's altitude in feet, the
recorders' default, with no way to say otherwise and no word of it: a
recorder set to metres (both can be) gave a tape whose flight was 3.28
times too low, silently. `--alt-unit ft|m` now names the unit; left out,
the import says the altitude was read in feet and how to say metres. A
format whose log states its units (AltOS, CATS, Raven) refuses the option
(status 2), and an RRC3 log with pressure of its own says it is not used."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import run_fsw
from fswkit.tape import isa_pressure, read_tape

EGG = ("T,Alt,Veloc,FAlt,FVeloc,FVeloc2,LDA,LowV,Apogee,N-O,Drogue,Main\n"
       "0,0,0,0,0,0,0,0,0,0,0,0\n50,10,200,2,40,8,0,0,0,0,0,0\n100,30,400,8,90,20,0,0,0,0,0,0\n")


def _rrc3(pressure: bool) -> str:
    head = "time,altitude," + ("pressure," if pressure else "") + "velocity,temperature,events,voltages\n"
    rows = []
    for i in range(60):
        t = i * 0.05
        h = 0.0 if t < 1.0 else (t - 1.0) * 60.0
        rows.append(f"{t:.2f},{h:.3f}," + (f"{isa_pressure(h) / 100:.3f}," if pressure else "") + "0,20.0, -,3.8\n")
    return head + "".join(rows)


@pytest.mark.parametrize("unit, metres", [("m", 1.0), ("ft", 0.3048)])
def test_the_unit_given_is_the_unit_read(tmp_path, unit, metres):
    log = tmp_path / "egg.csv"
    log.write_text(EGG)
    out = tmp_path / "t.csv"
    r = run_fsw("tape", "import", "eggtimer", str(log), "-o", str(out), "--alt-unit", unit)
    assert r.code == 0, r.err
    assert read_tape(str(out)).pressure == pytest.approx(isa_pressure(np.array([0, 10, 30]) * metres))
    assert "read in feet" not in r.err
    assert ("(m AGL)" if unit == "m" else "(ft AGL) * 0.3048") in out.read_text()


def test_an_altitude_read_in_feet_unasked_is_said(tmp_path):
    for fmt, text in (("eggtimer", EGG), ("rrc3", _rrc3(False))):
        log = tmp_path / f"{fmt}.csv"
        log.write_text(text)
        r = run_fsw("tape", "import", fmt, str(log), "-o", str(tmp_path / f"{fmt}.tape.csv"))
        assert r.code == 0, r.err
        assert "altitude read in feet" in r.err and "--alt-unit m" in r.err, r.err


def test_the_unit_where_the_log_gives_its_own(tmp_path):
    log = tmp_path / "r.csv"
    log.write_text(_rrc3(True))
    r = run_fsw("tape", "import", "rrc3", str(log), "-o", str(tmp_path / "r.tape.csv"), "--alt-unit", "m")
    assert r.code == 0 and "--alt-unit is not used: the log has pressure of its own" in r.err, r.err
    r = run_fsw("tape", "import", "rrc3", str(log), "-o", str(tmp_path / "r2.tape.csv"))
    assert r.code == 0 and "read in feet" not in r.err, r.err
    r = run_fsw("tape", "import", "altos", str(log), "-o", str(tmp_path / "a.csv"), "--alt-unit", "m")
    assert r.code == 2 and "--alt-unit" in r.err and "eggtimer" in r.err, r.err
    assert not (tmp_path / "a.csv").exists()
