"""An altitude cell beyond the ISA troposphere the tapes use was an error
at the log's column line, not at the cell, and said the column's highest
altitude whatever was wrong: a single glitch row of -5,000 m in a CATS
export that climbed to 3,000 m was `LOG:1:4: ... reaches 3000 m ASL ...:
beyond the ISA troposphere the tapes use (0 to 11 km)` (3,000 m is within
it, and the limit below was -1 km). Now each such cell is an error at its
own `LOG:LINE:COL`, saying its value and the altitude it makes, for every
converter that makes pressure from an altitude (cats, eggtimer, rrc3,
raven)."""

from __future__ import annotations

from conftest import run_fsw


def refused(tmp_path, fmt, text, *more):
    log = tmp_path / "log.csv"
    log.write_text(text)
    out = tmp_path / "tape.csv"
    r = run_fsw("tape", "import", fmt, str(log), "-o", str(out), *more)
    assert r.code == 1, r.err
    assert "Traceback" not in r.err, r.err
    assert not out.exists()
    return r.err.replace(str(log), "LOG")


CATS = ("ts,filtered_altitude_AGL,filtered_acceleration\n-0.02,0.5,0.0981\n-0.01,-0.5,0.0\n0.0,1.0,98.1\n"
        "0.01,{bad},100.0\n0.02,3000.0,-9.81\n0.03,2999.0,0.0\n")


def test_a_cats_altitude_far_below_the_pad_is_located_at_its_cell(tmp_path):
    err = refused(tmp_path, "cats", CATS.format(bad="-5000"))
    assert err.startswith("fsw tape import: LOG:5:6: filtered_altitude_AGL (`filtered_altitude_AGL`): `-5000` is "
                          "-5000 m ASL (read as m AGL, the pad at 0 m ASL): beyond the ISA troposphere the tapes use "
                          "(-1 to 11 km)"), err
    assert "3000" not in err


def test_a_cats_altitude_far_above_is_located_at_its_cell(tmp_path):
    err = refused(tmp_path, "cats", CATS.format(bad="50000"), "--pad-alt", "100")
    assert err.startswith("fsw tape import: LOG:5:6: filtered_altitude_AGL (`filtered_altitude_AGL`): `50000` is "
                          "50100 m ASL (read as m AGL, the pad at 100 m ASL)"), err


def test_an_eggtimer_altitude_in_the_wrong_unit_is_located_at_each_cell(tmp_path):
    text = "T,Alt,Veloc\n0,0,0\n50,10,0\n100,40000,0\n150,40001,0\n"
    err = refused(tmp_path, "eggtimer", text)
    lines = err.splitlines()
    assert lines[0].startswith("fsw tape import: LOG:4:5: Alt (`Alt`): `40000` is 12192 m ASL (read as ft AGL"), err
    assert lines[1].startswith("fsw tape import: LOG:5:5: Alt (`Alt`): `40001` is"), err


def test_an_rrc3_altitude_is_located_at_its_cell(tmp_path):
    rows = "".join(f"{i * 0.05:.2f},{0.0 if i < 10 else (i - 9) * 20.0:.1f},0,20,,9\n" for i in range(40))
    text = "time,altitude,velocity,temperature,events,voltages\n" + rows.replace("\n0.50,20.0,", "\n0.50,-9000,")
    err = refused(tmp_path, "rrc3", text, "--alt-unit", "m")
    assert err.startswith("fsw tape import: LOG:12:6: altitude (`altitude`): `-9000` is -9000 m ASL"), err


def test_a_raven_altitude_is_located_at_its_cell(tmp_path):
    head = "Time-Axial Accel (Gs), Axial Accel (Gs), bILBA, Time (s), Altitude (Ft-AGL), bILBA\n"
    rows = [f"{i * 0.0025:.4f},{1.0 if i < 40 else 6.0},b0000,{i * 0.05:.3f},{0.0 if i < 10 else i * 30.0},b0000\n"
            for i in range(100)]
    rows[50] = rows[50].replace(",1500.0,", ",99999,")
    err = refused(tmp_path, "raven", head + "".join(rows))
    assert err.startswith("fsw tape import: LOG:52:"), err
    assert "Altitude (Ft-AGL) (`Altitude (Ft-AGL)`): `99999` is 30480 m ASL (read as ft AGL" in err, err


def test_an_altitude_within_it_is_imported(tmp_path):
    log = tmp_path / "log.csv"
    log.write_text(CATS.format(bad="2.0"))
    r = run_fsw("tape", "import", "cats", str(log), "-o", str(tmp_path / "tape.csv"))
    assert r.code == 0, r.err
