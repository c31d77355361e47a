"""`fsw tape import` said it wrote a tape that `fsw tape show` then refused:
a log whose times lie closer than the tape's 10 µs (`0.100001`,
`0.100003`) were written as the same `0.1`, a pressure of 0.01 Pa as `0`,
and two times that differ by less than a float can hold once the liftoff
time is subtracted (`0` and `1e-320`, liftoff at 1 s) became one. Every
tape the import writes now reads back, with the log's rows: numbers the
usual precision would merge or zero are written exactly, and rows whose
times become equal once liftoff is subtracted are dropped and counted as
the rows whose time is not after the previous one are."""

from __future__ import annotations

import math

from conftest import run_fsw

from fswkit.tape import read_tape


def imported(tmp_path, fmt, text):
    log = tmp_path / "log.csv"
    log.write_text(text)
    out = tmp_path / "tape.csv"
    r = run_fsw("tape", "import", fmt, str(log), "-o", str(out))
    assert r.code == 0, r.err
    assert "Traceback" not in r.err
    return read_tape(str(out)), run_fsw("tape", "show", str(out))


CATS = "ts,filtered_altitude_AGL,filtered_acceleration\n"


def test_times_closer_than_ten_microseconds_stay_apart(tmp_path):
    tape, show = imported(tmp_path, "cats", CATS + "0.100001,1.0,9.81\n0.100003,2.0,9.81\n0.2,3.0,9.81\n")
    assert show.code == 0, show.err
    assert tape.time.tolist() == [0.100001, 0.100003, 0.2]


def test_a_time_rounded_up_does_not_pass_the_next_one(tmp_path):
    # 0.100006 written with 5 decimals is 0.10001, after the next row's 0.100008
    tape, show = imported(tmp_path, "cats", CATS + "0.100006,1.0,9.81\n0.100008,2.0,9.81\n0.2,3.0,9.81\n")
    assert show.code == 0, show.err
    assert tape.time.tolist() == [0.100006, 0.100008, 0.2]


ALTOS = "#version,serial,flight,call,time,state,state_name,acceleration,pressure,altitude,height,speed\n"


def test_a_pressure_below_the_written_precision_is_not_written_as_zero(tmp_path):
    rows = "".join(f"6,1,1,X,{t},2,pad,0.0{i},{p},1,1,1\n" for i, (t, p) in
                   enumerate([(0.1, "90000"), (0.2, "0.01"), (0.3, "90002")]))
    tape, show = imported(tmp_path, "altos", ALTOS + rows)
    assert show.code == 0, show.err
    assert tape.pressure.tolist() == [90000.0, 0.01, 90002.0]


def test_times_equal_once_liftoff_is_subtracted_are_dropped_and_counted(tmp_path):
    head = "time,altitude,pressure,velocity,temperature,events,voltages\n"
    rows = []
    for i in range(60):
        t = i * 0.05
        h = 0.0 if t < 1.0 else (t - 1.0) * 60.0
        p = 101325 * (1 - (500 + h) / 44330.77) ** (1 / 0.190263) / 100
        rows.append(f"{'1e-320' if i == 1 else f'{t:.2f}'},0,{p:.3f},0,20, -,3.8\n")
    tape, show = imported(tmp_path, "rrc3", head + "".join(rows))
    assert show.code == 0, show.err
    assert tape.rows == 59  # 0 and 1e-320, both 1 s before liftoff, are one time: the second is dropped
    assert tape.time[0] == -1.0 and math.isclose(tape.time[1], -0.9)
    assert any("1 with a time not after the previous row" in d for d in tape.derived)
