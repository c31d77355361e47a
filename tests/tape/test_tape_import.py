"""fswkit.tape.formats and `fsw tape import`: each recorder's log layout,
written here as a few invented rows (not copies of anyone's file), converted
and checked value by value: units, the ISA formula for pressure made from
altitude, +1 g at rest, the time base and the liftoff rule; and a located
error for every log a converter cannot read."""

from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import run_fsw
from fswkit.tape import TapeError, isa_altitude, read_tape
from fswkit.tape.formats import FORMATS, convert


def isa_p(h):  # the README's formula, written out independently of the module
    return 101325 * (1 - h / 44330.77) ** (1 / 0.190263)


def log(tmp_path, text, name="log.csv"):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


def refused(fmt, path, pad_alt=None) -> str:
    with pytest.raises(TapeError) as e:
        convert(fmt, path, pad_alt)
    return str(e.value).replace(path, "L")


# ---- AltOS ----------------------------------------------------------------------------

ALTOS = """# AltOS export written for this test
#version,serial,flight,call,time,state,state_name,acceleration,pressure,altitude,height,speed,temperature,connected
6, 4242, 7,N0CALL,    -0.20, 2,     pad,    0.00,  90000.00, 1000.0,    0.00,     NaN, 20.0, 1
6, 4242, 7,N0CALL,    -0.10, 2,     pad,   -0.98,  90001.00, 999.9,    -0.10,     NaN, 20.0, 1
6, 4242, 7,N0CALL,    -0.10, 2,     pad,   -0.98,  90001.00, 999.9,    -0.10,     NaN, 20.0, 1
6, 4242, 7,N0CALL,     0.00, 3,   boost,   98.07,  89990.00, 1000.9,    0.90,     0.0, 20.0, 1
6, 4242, 7,N0CALL,     0.05, 3,   boost,   98.07,  89990.00, 1000.9,    0.90,     0.0, 20.0, 1
6, 4242, 7,N0CALL,     0.10, 3,   boost,  -9.81,  89900.00, 1009.3,    9.30,    20.0, 20.1, 1
"""


def test_altos(tmp_path):
    t = convert("altos", log(tmp_path, ALTOS))
    # the repeated time (-0.10) and the row repeating every sensor value (0.05) are dropped
    assert t.time.tolist() == [-0.2, -0.1, 0.0, 0.1]
    assert t.pressure.tolist() == [90000.0, 90001.0, 89990.0, 89900.0]  # Pa as is
    assert t.accel == pytest.approx([1.0, 1 - 0.98 / 9.80665, 1 + 98.07 / 9.80665, 1 - 9.81 / 9.80665])
    assert t.accel[0] == 1.0  # 0 m/s^2 on the pad (AltOS removes 1 g): +1 g restored
    assert "serial 4242 flight 7" in t.flight
    assert any("1 with a time not after the previous row, 1 that repeat" in d for d in t.derived)


def test_altos_pressure_in_mbar_is_scaled(tmp_path):
    text = ALTOS.replace("90000.00", "900.00").replace("90001.00", "900.01").replace("89990.00", "899.90") \
        .replace("89900.00", "899.00")
    t = convert("altos", log(tmp_path, text))
    assert t.pressure == pytest.approx([90000.0, 90001.0, 89990.0, 89900.0])
    assert any("(hPa (mbar)) * 100" in d for d in t.derived)


def test_altos_errors(tmp_path):
    assert refused("altos", log(tmp_path, "a,b\n1,2\n")).startswith(
        "L:1:1: not a AltOS CSV export log: no line names its columns")
    bad = ALTOS.replace("89900.00", "8990x.00")
    col = bad.splitlines()[7].index("8990x") + 1
    assert refused("altos", log(tmp_path, bad)).startswith(f"L:8:{col}: pressure (`pressure`): `8990x.00` is not")
    bad = ALTOS.replace("    0.10, 3", "     abc, 3")
    col = bad.splitlines()[7].index("abc") + 1
    assert refused("altos", log(tmp_path, bad)).startswith(f"L:8:{col}: time (`time`): `abc` is not")
    units = ALTOS.replace("90000.00", "9.00").replace("90001.00", "9.01").replace("89990.00", "8.99") \
        .replace("89900.00", "8.9")
    assert "cannot tell the unit of `pressure`" in refused("altos", log(tmp_path, units))
    short = ALTOS + "6, 4242, 7,N0CALL, 0.2\n"
    assert refused("altos", log(tmp_path, short)).startswith("L:9: the row has 5 cells: no `state_name`") \
        or "L:9: the row has 5 cells" in refused("altos", log(tmp_path, short))


# ---- CATS ----------------------------------------------------------------------------

CATS = """ts,filtered_altitude_AGL,filtered_acceleration
-0.02,0.5,0.0981
-0.01,-0.5,0.0
0.0,1.0,98.1
0.01,2.0,100.0
0.02,3000.0,-9.81
0.03,2999.0,0.0
0.04,2998.0,0.0
0.05,2997.0,0.0
"""


def test_cats_filtered_export(tmp_path):
    t = convert("cats", log(tmp_path, CATS), 160.0)
    assert t.time.tolist() == [-0.02, -0.01, 0.0, 0.01, 0.02, 0.03, 0.04, 0.05]  # CATS's own liftoff: as is
    h = np.array([0.5, -0.5, 1.0, 2.0, 3000.0, 2999.0, 2998.0, 2997.0])
    assert t.pressure == pytest.approx(isa_p(160.0 + h), rel=1e-12)
    assert isa_altitude(t.pressure) - isa_altitude(isa_p(160.0)) == pytest.approx(h, abs=1e-6)
    assert t.accel[:5] == pytest.approx([1.01, 1.0, 11.0, 1 + 100 / 9.81, 0.0])
    # the final run of exact zeros (CATS after DROGUE) is not a measurement: empty
    assert np.isnan(t.accel[5:]).all()
    assert any("left empty from t = 0.03 s" in d for d in t.derived)
    assert "pad elevation 160 m ASL (given)" in t.flight


def test_cats_without_pad_alt_assumes_sea_level_and_says_so(tmp_path):
    t = convert("cats", log(tmp_path, CATS))
    assert t.pressure[0] == pytest.approx(isa_p(0.5))
    assert "0 m ASL assumed" in t.flight


def test_cats_barometer_log(tmp_path):
    text = "ts,id,T,P\n-0.01,BARO0,25.0,99619\n-0.01,BARO1,25.1,99700\n0.0,BARO0,25.0,99610\n" \
           "0.01,BARO0,25.0,99500\n0.01,BARO1,25.1,99600\n"
    t = convert("cats", log(tmp_path, text))
    assert t.time.tolist() == [-0.01, 0.0, 0.01]
    assert t.pressure.tolist() == [99619.0, 99610.0, 99500.0]  # Pa as is, first sensor only
    assert np.isnan(t.accel).all()


def test_cats_errors(tmp_path):
    assert "no line names its columns (ts with filtered_altitude_AGL" in refused("cats", log(tmp_path, ALTOS))
    bad = CATS.replace("3000.0", "3000.0.1")
    assert refused("cats", log(tmp_path, bad)).startswith(
        "L:6:6: filtered_altitude_AGL (`filtered_altitude_AGL`): `3000.0.1` is not")
    high = CATS.replace("3000.0", "13000.0")
    assert "beyond the ISA troposphere" in refused("cats", log(tmp_path, high))
    assert "--pad-alt 20000: expected a pad elevation" in refused("cats", log(tmp_path, CATS), 20000.0)


# ---- Featherweight Raven -------------------------------------------------------------------

def raven_log():
    """A FIP-export layout: an accel channel at 400 Hz for 0.3 s, an altitude
    channel at 20 Hz for 1 s (its own time column), flag columns between."""
    head = "Time-Axial Accel (Gs), Axial Accel (Gs), bILBA, Time (s), Altitude (Ft-AGL), bILBA\n"
    ta = [i * 0.0025 for i in range(121)]
    acc = [1.0 if t < 0.05 else (6.0 if t < 0.25 else -0.5) for t in ta]
    acc[10] = 2.5  # a short spike at 0.025 s: above 2 g for less than 0.1 s, not liftoff
    th = [0.01 + i * 0.05 for i in range(21)]
    alt = [0.0 if t < 0.1 else (t - 0.05) * 300.0 for t in th]
    rows = []
    for i in range(max(len(ta), len(th))):
        a = f"{ta[i]:.4f},{acc[i]:.2f},b0000" if i < len(ta) else ",,"
        h = f"{th[i]:.3f},{alt[i]:.2f},b0000" if i < len(th) else ",,"
        rows.append(f"{a},{h}\n")
    return head + "".join(rows), ta, acc, th, alt


def test_raven(tmp_path):
    text, ta, acc, th, alt = raven_log()
    t = convert("raven", log(tmp_path, text), 206.0)
    lift = 0.05  # the first sample above 2 g that stays above 2 g for 0.1 s
    assert t.time[:len(ta)] == pytest.approx(np.array(ta) - lift)
    assert t.accel[:len(ta)] == pytest.approx(acc)  # g as is
    assert np.isnan(t.accel[len(ta):]).all()
    # after the accel channel ends, rows follow the altitude clock
    assert t.time[len(ta):] == pytest.approx(np.array([x for x in th if x > ta[-1]]) - lift)
    # sample-and-hold: empty before the first altitude sample, then the last one
    assert math.isnan(t.pressure[0])  # Raven time 0 < 0.01
    i = ta.index(0.06) if 0.06 in ta else int(round(0.06 / 0.0025))
    assert t.pressure[i] == pytest.approx(isa_p(206.0 + alt[1] * 0.3048))  # held from th[1] = 0.06
    last = len(t.time) - 1
    assert t.pressure[last] == pytest.approx(isa_p(206.0 + alt[-1] * 0.3048))
    assert any("Raven time 0.05000 s" in d for d in t.derived)


def test_raven_without_accel_uses_the_baro_rule(tmp_path):
    head = "Time (s), Altitude (Ft-AGL), bILBA\n"
    rows = "".join(f"{i * 0.05:.2f},{0.0 if i < 10 else (i - 9) * 20.0:.1f},b0000\n" for i in range(40))
    t = convert("raven", log(tmp_path, head + rows))
    # pad 0 ft; 10 m (32.8 ft) exceeded at i = 11 (40 ft), the last sample within 1 m before: i = 9 (0.45 s)
    assert t.time[0] == pytest.approx(-0.45)
    assert np.isnan(t.accel).all()


def test_raven_accel_only(tmp_path):
    head = "Time-Axial Accel (Gs), Axial Accel (Gs), bILBA, Time (s), Altitude (Ft-AGL), bILBA\n"
    rows = "".join(f"{i * 0.0025:.4f},{1.0 if i < 40 else 6.0},b0000,,,\n" for i in range(200))
    t = convert("raven", log(tmp_path, head + rows))
    assert t.time[40] == pytest.approx(0.0) and np.isnan(t.pressure).all() and t.accel[-1] == 6.0


def test_an_altitude_column_without_values_is_refused(tmp_path):
    assert refused("eggtimer", log(tmp_path, "T,Alt,Veloc\n0,,0\n50,,0\n")) == "L:1:3: `Alt` holds no value"
    text = "ts,filtered_altitude_AGL,filtered_acceleration\n0,,1\n0.01,,1\n"
    assert refused("cats", log(tmp_path, text)) == "L:1:4: `filtered_altitude_AGL` holds no value"


def test_raven_errors(tmp_path):
    assert "no line names its columns" in refused("raven", log(tmp_path, CATS))
    # resting on the pad: no 2 g for 0.1 s, no climb of 10 m
    head = "Time-Axial Accel (Gs), Axial Accel (Gs), bILBA, Time (s), Altitude (Ft-AGL), bILBA\n"
    rows = "".join(f"{i * 0.0025:.4f},1.00,b0000,{i * 0.05:.3f},0.5,b0000\n" for i in range(100))
    assert refused("raven", log(tmp_path, head + rows)).startswith("L: no liftoff found")
    bad = head + rows.replace("1.00,b0000", "1,00,b0000", 1)
    assert "L:2:" in refused("raven", log(tmp_path, bad))


# ---- Eggtimer --------------------------------------------------------------------------

EGG = """Eggtimer flight summary written for this test
T,Alt,Veloc,FAlt,FVeloc,FVeloc2,LDA,LowV,Apogee,N-O,Drogue,Main
0,0,0,0,0,0,0,0,0,0,0,0
50,10,200,2,40,8,0,0,0,0,0,0
100,30,400,8,90,20,0,0,0,0,0,0
150,60,600,20,150,40,60,0,0,0,0,0
"""


def test_eggtimer(tmp_path):
    t = convert("eggtimer", log(tmp_path, EGG), 1400.0)
    assert t.time.tolist() == [0.0, 0.05, 0.1, 0.15]  # ms / 1000, 0 = the Eggtimer's flight start
    assert t.pressure == pytest.approx(isa_p(1400.0 + np.array([0, 10, 30, 60]) * 0.3048))
    assert np.isnan(t.accel).all()
    assert "pad elevation 1400 m ASL (given)" in t.flight


def test_eggtimer_errors(tmp_path):
    assert "not a Eggtimer log" in refused("eggtimer", log(tmp_path, CATS))
    assert refused("eggtimer", log(tmp_path, EGG.replace("100,30", "100,3O"))).startswith(
        "L:5:5: Alt (`Alt`): `3O` is not")


# ---- RRC3 -------------------------------------------------------------------------------

def rrc3_log(with_pressure=True):
    head = "time,altitude,pressure,velocity,temperature,events,voltages\n" if with_pressure else \
        "time,altitude,velocity,temperature,events,voltages\n"
    rows = []
    for i in range(60):
        t = i * 0.05
        h_ft = 0.0 if t < 1.0 else (t - 1.0) * 200.0
        p_hpa = isa_p(500.0 + h_ft * 0.3048) / 100
        cells = [f"{t:.2f}", f"{h_ft:.3f}"] + ([f"{p_hpa:.3f}"] if with_pressure else []) + \
            ["0", "20.0", " -" if i != 50 else " Drogue", "3.8"]
        rows.append(",".join(cells) + "\n")
    return head + "".join(rows)


def test_rrc3(tmp_path):
    t = convert("rrc3", log(tmp_path, rrc3_log()))
    # liftoff (BARO rule): the last sample within 1 m of the pad (t = 1.00 s, 0 ft) before 10 m
    assert t.time[0] == pytest.approx(-1.0) and t.time[20] == pytest.approx(0.0)
    h = np.array([0.0 if i * 0.05 < 1.0 else (i * 0.05 - 1.0) * 200.0 for i in range(60)]) * 0.3048
    assert t.pressure == pytest.approx(np.round(isa_p(500.0 + h) / 100, 3) * 100)  # hPa * 100
    assert np.isnan(t.accel).all()


def test_rrc3_altitude_only(tmp_path):
    t = convert("rrc3", log(tmp_path, rrc3_log(False)), 500.0)
    h = np.array([0.0 if i * 0.05 < 1.0 else (i * 0.05 - 1.0) * 200.0 for i in range(60)]) * 0.3048
    assert t.pressure == pytest.approx(isa_p(500.0 + np.round(h / 0.3048, 3) * 0.3048))


def test_rrc3_errors(tmp_path):
    flat = "time,altitude,pressure,velocity,temperature,events,voltages\n" + \
        "".join(f"{i * 0.05:.2f},0,861.7,0,20, -,3.8\n" for i in range(30))
    assert refused("rrc3", log(tmp_path, flat)) == "L: no liftoff found: the altitude is never 10 m above " \
                                                   "the pad for 0.5 s"
    assert "no line names its columns (time, altitude, pressure" in refused("rrc3", log(tmp_path, EGG))


# ---- shared: files the kit refuses, and the command ------------------------------------------

@pytest.mark.parametrize("fmt", sorted(FORMATS))
def test_every_format_refuses_binary_empty_and_missing_files(tmp_path, fmt):
    assert refused(fmt, log(tmp_path, "")).startswith("L: empty file")
    p = tmp_path / "bin.csv"
    p.write_bytes(b"ts,P\n\x00\x01\x02")
    assert refused(fmt, str(p)).replace(str(p), "L").startswith("L:2:1: not a text file")
    assert refused(fmt, str(tmp_path / "none.csv")).replace(str(tmp_path / "none.csv"), "L") == "L: no such file"


def test_fsw_tape_import(tmp_path):
    src = log(tmp_path, CATS)
    out = str(tmp_path / "tape.csv")
    r = run_fsw("tape", "import", "cats", src, "-o", out, "--pad-alt", "100")
    assert r.code == 0, r.err
    assert "8 rows, -0.02 to 0.05 s" in r.err
    t = read_tape(out)
    assert t.rows == 8 and t.pressure[2] == pytest.approx(isa_p(101.0), abs=0.05)
    assert t.sources[0].startswith("log.csv (imported with `fsw tape import cats`")
    before = open(out).read()
    r = run_fsw("tape", "import", "cats", src, "-o", out)
    assert r.code == 1 and "tape.csv exists: it is replaced only when asked (--force)" in r.err
    assert open(out).read() == before
    r = run_fsw("tape", "import", "cats", src, "-o", out, "--force")
    assert r.code == 0 and read_tape(out).pressure[2] == pytest.approx(isa_p(1.0), abs=0.05)
    r = run_fsw("tape", "import", "cats", src, "-o", src, "--force")
    assert r.code == 1 and "would overwrite an input" in r.err
    r = run_fsw("tape", "import", "rrc3", src, "-o", str(tmp_path / "x.csv"))
    assert r.code == 1 and r.err.startswith(f"fsw tape import: {src}:1:1: not a Missile Works RRC3")
    assert "Traceback" not in r.err and not (tmp_path / "x.csv").exists()
    r = run_fsw("tape", "import", "cats", src, "-o", str(tmp_path / "nofolder" / "x.csv"))
    assert r.code == 1 and "no such folder" in r.err
    r = run_fsw("tape", "import", "nosuch", src, "-o", out)
    assert r.code == 2
    r = run_fsw("tape", "import", "cats", src, "-o", "-")
    assert r.code == 0 and r.out.startswith("# fswkit sensor tape v1\n")
    r = run_fsw("tape", "import", "cats", src, "-o", "")
    assert r.code == 2 and "--output: an empty string names nothing" in r.err
    r = run_fsw("tape", "show", "")
    assert r.code == 2 and "an empty string names nothing" in r.err
    r = run_fsw("tape", "import", "cats", src, "-o", str(tmp_path / "n.csv"), "--pad-alt", "nan")
    assert r.code == 2 and "--pad-alt: expected a finite number of metres, found 'nan'" in r.err
    assert not (tmp_path / "n.csv").exists()
