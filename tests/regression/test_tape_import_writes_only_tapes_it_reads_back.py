"""`fsw tape import` said it wrote a tape that `fsw tape show` then refused:
a log whose times lie closer than the tape's 10 µs (`0.100001`,
`0.100003`) were written as the same `0.1`, a pressure of 0.01 Pa as `0`,
and two times that differ by less than a float can hold once the liftoff
time is subtracted (`0` and `1e-320`, liftoff at 1 s) became one. Every
tape the import writes now reads back, with the log's rows: numbers the
usual precision would merge or zero are written exactly, and rows whose
times become equal once liftoff is subtracted are dropped and counted as
the rows whose time is not after the previous one are. (A pressure of
0.01 Pa, and log times 1e-320 s apart, are now beyond what a recorder
logs, refused at the log's cell before any tape is written:
test_tape_import_refuses_a_log_value_no_flight_records.)"""

from __future__ import annotations

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


def test_a_pressure_below_the_written_precision_is_refused_at_its_cell(tmp_path):
    rows = "".join(f"6,1,1,X,{t},2,pad,0.0{i},{p},1,1,1\n" for i, (t, p) in
                   enumerate([(0.1, "90000"), (0.2, "0.01"), (0.3, "90002")]))
    log = tmp_path / "log.csv"
    log.write_text(ALTOS + rows)
    r = run_fsw("tape", "import", "altos", str(log), "-o", str(tmp_path / "tape.csv"))
    assert r.code == 1 and f"{log}:3:" in r.err and "`0.01` is beyond 1,000 to 120,000 Pa" in r.err, r.err
    assert not (tmp_path / "tape.csv").exists()


def test_times_equal_once_liftoff_is_subtracted_are_refused_at_their_cell(tmp_path):
    head = "time,altitude,pressure,velocity,temperature,events,voltages\n"
    rows = []
    for i in range(60):
        t = i * 0.05
        h = 0.0 if t < 1.0 else (t - 1.0) * 60.0
        p = 101325 * (1 - (500 + h) / 44330.77) ** (1 / 0.190263) / 100
        rows.append(f"{'1e-320' if i == 1 else f'{t:.2f}'},0,{p:.3f},0,20, -,3.8\n")
    log = tmp_path / "log.csv"
    log.write_text(head + "".join(rows))
    r = run_fsw("tape", "import", "rrc3", str(log), "-o", str(tmp_path / "tape.csv"))
    # 0 and 1e-320, both 1 s before liftoff: no recorder logs rows 1e-320 s apart
    assert r.code == 1 and f"{log}:3:1: time (`time`): `1e-320` is " in r.err, r.err
    assert "s after the previous row's (line 2)" in r.err and "1 µs apart" in r.err
    assert not (tmp_path / "tape.csv").exists()
