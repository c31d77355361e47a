"""`fsw tape import altos LOG --pad-alt 1400` took the pad altitude and did
nothing with it, without a word: a log with pressure (AltOS, an RRC3's
`pressure`, a CATS barometer log) gives the tape its own pressure, and the
pad altitude is only for pressure made from an altitude. The import says
so, and the tape is the same as without the option."""

from __future__ import annotations

from conftest import run_fsw

ALTOS = ("#version,serial,flight,call,time,state,state_name,acceleration,pressure,altitude,height,speed\n"
         "6,1,1,X,-0.1,2,pad,0,90000,1,1,1\n6,1,1,X,0.0,3,boost,50,89990,2,2,2\n")
CATS = "ts,filtered_altitude_AGL,filtered_acceleration\n-0.1,0,0\n0,0.5,30\n0.1,3,30\n"


def test_pad_alt_on_a_log_with_pressure_is_said_unused(tmp_path):
    log = tmp_path / "log.csv"
    log.write_text(ALTOS)
    plain, given = tmp_path / "a.csv", tmp_path / "b.csv"
    assert run_fsw("tape", "import", "altos", str(log), "-o", str(plain)).code == 0
    r = run_fsw("tape", "import", "altos", str(log), "-o", str(given), "--pad-alt", "1400")
    assert r.code == 0, r.err
    assert "fsw tape import: --pad-alt is not used: the log has pressure of its own" in r.err, r.err
    assert given.read_text().replace("b.csv", "a.csv") == plain.read_text().replace("b.csv", "a.csv")


def test_pad_alt_used_is_not_said_unused(tmp_path):
    log = tmp_path / "log.csv"
    log.write_text(CATS)
    r = run_fsw("tape", "import", "cats", str(log), "-o", str(tmp_path / "t.csv"), "--pad-alt", "1400")
    assert r.code == 0, r.err
    assert "not used" not in r.err
