"""`fsw tape import` converted any finite number of a log: an AltOS
acceleration of 1e308 m/s^2 became an accel_g of 1e+307, a CATS `ts` of
1e308 a tape "-0.02 to 100000000...000.00 s" long, an Eggtimer `T` of
1e20 ms a flight of 1e17 s, an RRC3 pressure of 1e300 hPa a tape row of
1e+302 Pa, a clock that jumped by hours a tape with a 9,000 s row, rows
1e-300 s apart a flight of no length; each was written, exit status 0,
for `fsw tape truth` and `fsw sim --tape` to make silently wrong numbers
of. Now every column a converter reads has the range of the tape column it
makes (docs/tapes.md, "Ranges"), and a cell beyond it is an error at the
log's line and column, naming the column, the value, the range and what
to do; no tape is written. A long log with one such row at its end names
that row's line."""

from __future__ import annotations

import pytest

from conftest import run_fsw

ALTOS_HEAD = "#version,serial,flight,call,time,state,state_name,acceleration,pressure,altitude,height,speed\n"


def altos(n=8, at=None, dt=0.1) -> str:
    rows = []
    for i in range(n):
        t, a, p = f"{i * dt - 0.2:.2f}", f"{0.5 * (i % 100):.2f}", f"{90000 - i % 100}"
        t, a, p = (at or {}).get(i, (t, a, p))
        rows.append(f"6,1,1,X,{t},2,pad,{a},{p},{i},{i},{i}\n")
    return ALTOS_HEAD + "".join(rows)


CATS_HEAD = "ts,filtered_altitude_AGL,filtered_acceleration\n"


def cats(at=None) -> str:
    rows = []
    for i in range(8):
        t, h, a = f"{i / 100 - 0.02:.2f}", f"{i * 10.0:.1f}", "9.81"
        t, h, a = (at or {}).get(i, (t, h, a))
        rows.append(f"{t},{h},{a}\n")
    return CATS_HEAD + "".join(rows)


def refused(tmp_path, fmt, text, line, said, span):
    log = tmp_path / "log.csv"
    log.write_text(text)
    out = tmp_path / "tape.csv"
    r = run_fsw("tape", "import", fmt, str(log), "-o", str(out))
    assert r.code == 1, r.err
    err = r.err.replace(str(log), "LOG")
    assert f"fsw tape import: LOG:{line}:" in err and said in err and span in err, err
    assert "Traceback" not in err and "Warning" not in err, err
    assert not out.exists()
    return err


def test_altos_values_beyond_their_ranges(tmp_path):
    t, a, p = "0.30", "0.50", "89990"
    refused(tmp_path, "altos", altos(at={5: (t, "1e308", p)}), 7, "acceleration (`acceleration`): `1e308`",
            "-250 to 250 g")
    refused(tmp_path, "altos", altos(at={5: (t, "-3000", p)}), 7, "`-3000`", "-250 to 250 g")
    refused(tmp_path, "altos", altos(at={5: (t, a, "1e7")}), 7, "pressure (`pressure`): `1e7`",
            "1,000 to 120,000 Pa")
    refused(tmp_path, "altos", altos(at={5: (t, a, "5")}), 7, "`5`", "1,000 to 120,000 Pa")
    refused(tmp_path, "altos", altos(at={7: ("1e308", a, p)}), 9, "time (`time`): `1e308`", "-3,600 to 3,600 s")
    refused(tmp_path, "altos", altos(at={0: ("-1e308", a, p)}), 2, "time (`time`): `-1e308`", "-3,600 to 3,600 s")
    err = refused(tmp_path, "altos", altos(at={5: ("3000", a, p), 6: ("3000.1", a, p), 7: ("3000.2", a, p)}), 7,
                  "time (`time`): `3000` is 2,999.8 s after the previous row's (line 6)", "60 s apart")
    refused(tmp_path, "altos", altos(at={5: ("0.2000000001", a, p)}), 7, "time (`time`): `0.2000000001`",
            "1 µs apart")


def test_a_long_log_with_one_bad_row_at_its_end_names_its_line(tmp_path):
    n = 50_000
    text = altos(n, at={n - 1: ("1e308", "0.5", "89000")}, dt=0.01)
    refused(tmp_path, "altos", text, n + 1, "`1e308`", "-3,600 to 3,600 s")


def test_cats_values_beyond_their_ranges(tmp_path):
    refused(tmp_path, "cats", cats(at={7: ("1e308", "70.0", "9.81")}), 9, "ts (`ts`): `1e308`", "-3,600 to 3,600 s")
    refused(tmp_path, "cats", cats(at={4: ("0.02", "40.0", "1e300")}), 6,
            "filtered_acceleration (`filtered_acceleration`): `1e300`", "-250 to 250 g")
    baro = "ts,id,T,P\n-0.01,B,25.0,99619\n0.0,B,25.0,99600\n0.01,B,25.0,1e10\n"
    refused(tmp_path, "cats", baro, 4, "P (`P`): `1e10`", "1,000 to 120,000 Pa")


def test_eggtimer_times_beyond_their_range(tmp_path):
    egg = ("T,Alt,Veloc,FAlt,FVeloc,FVeloc2,LDA,LowV,Apogee,N-O,Drogue,Main\n0,0,0,0,0,0,0,0,0,0,0,0\n"
           "50,10,200,2,40,8,0,0,0,0,0,0\n1e20,30,400,8,90,20,0,0,0,0,0,0\n")
    refused(tmp_path, "eggtimer", egg, 4, "T (`T`): `1e20`", "-3,600 to 3,600 s")


def rrc3(at=None) -> str:
    rows = []
    for i in range(60):
        t = i * 0.05
        h = 0.0 if t < 1.0 else (t - 1.0) * 200.0
        p = 101325 * (1 - (500 + h * 0.3048) / 44330.77) ** (1 / 0.190263) / 100
        cells = [f"{t:.2f}", f"{h:.3f}", f"{p:.3f}", "0", "20.0", " -", "3.8"]
        for k, v in (at or {}).get(i, {}).items():
            cells[k] = v
        rows.append(",".join(cells) + "\n")
    return "time,altitude,pressure,velocity,temperature,events,voltages\n" + "".join(rows)


def test_rrc3_values_beyond_their_ranges(tmp_path):
    # a recorder's clock, not yet counted from liftoff: a time far from the others is a jump
    refused(tmp_path, "rrc3", rrc3(at={59: {0: "1e308"}}), 61, "time (`time`): `1e308` is 1e+308 s after", "60 s apart")
    refused(tmp_path, "rrc3", rrc3(at={30: {2: "1e300"}}), 32, "pressure (`pressure`): `1e300`",
            "1,000 to 120,000 Pa")
    # a row 2 h before the next: the jump, at the row after it
    refused(tmp_path, "rrc3", rrc3(at={0: {0: "-7200"}}), 3, "time (`time`): `0.05` is 7,200.05 s after the "
            "previous row's (line 2)", "60 s apart")
    # a row its clock drops (not after the one before), 4,000 s before liftoff: beyond the range all the same
    refused(tmp_path, "rrc3", rrc3(at={30: {0: "-4000"}}), 32, "time (`time`): `-4000` makes time_s -400",
            "-3,600 to 3,600 s")


def test_raven_values_beyond_their_ranges(tmp_path):
    head = "Time-Axial Accel (Gs), Axial Accel (Gs), bILBA, Time (s), Altitude (Ft-AGL), bILBA\n"
    ta = [i * 0.0025 for i in range(121)]
    acc = [f"{1.0 if t < 0.05 else (6.0 if t < 0.25 else -0.5):.2f}" for t in ta]
    acc[100] = "1e308"
    th = [0.01 + i * 0.05 for i in range(21)]
    alt = [0.0 if t < 0.1 else (t - 0.05) * 300.0 for t in th]
    rows = [(f"{ta[i]:.4f},{acc[i]},b0000" if i < len(ta) else ",,") + "," +
            (f"{th[i]:.3f},{alt[i]:.2f},b0000" if i < len(th) else ",,") + "\n" for i in range(len(ta))]
    refused(tmp_path, "raven", head + "".join(rows), 102, "Axial Accel (`Axial Accel (Gs)`): `1e308`",
            "-250 to 250 g")
    rows[20] = rows[20].replace(f"{th[20]:.3f},", "1e308,")
    acc[100] = "-0.50"
    refused(tmp_path, "raven", head + "".join(rows).replace("1e308,b0000", "-0.50,b0000"), 22,
            "Altitude time (`Time (s)`): `1e308` is 1e+308 s after", "60 s apart")
    rows[20] = rows[20].replace("1e308,", "-4000,", 1)  # a row its clock drops, beyond the range all the same
    refused(tmp_path, "raven", head + "".join(rows).replace("1e308,b0000", "-0.50,b0000"), 22,
            "Altitude time (`Time (s)`): `-4000` makes time_s -400", "-3,600 to 3,600 s")


@pytest.mark.parametrize("fmt", ["altos", "cats"])
def test_values_at_the_ends_of_the_ranges_are_imported(tmp_path, fmt):
    text = altos(at={5: ("0.30", f"{248 * 9.80665:.4f}", "1001")}) if fmt == "altos" else \
        cats(at={4: ("0.02", "40.0", f"{-251 * 9.81 + 0.5:.3f}")})
    log = tmp_path / "log.csv"
    log.write_text(text)
    r = run_fsw("tape", "import", fmt, str(log), "-o", str(tmp_path / "tape.csv"))
    assert r.code == 0, r.err
