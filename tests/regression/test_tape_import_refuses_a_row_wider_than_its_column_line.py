"""A log row with more cells than its column line names was read by
position all the same: a CATS export whose numbers a spreadsheet wrote
with decimal commas (`-0,02,0,5,0,0981` under
`ts,filtered_altitude_AGL,filtered_acceleration`) became a tape of
`ts` -0, altitude 2 m, acceleration 0 -- exit 0, the rows after it
dropped as late -- and a comma inside an unquoted text cell shifted every
cell after it into the wrong column. A row with a non-empty cell beyond
the columns named is now an error at that cell, in every format; empty
cells beyond them (a spreadsheet's trailing `,,,`) are still read."""

from __future__ import annotations

import pytest

from conftest import run_fsw
from fswkit.tape import TapeError
from fswkit.tape.formats import convert

CATS = "ts,filtered_altitude_AGL,filtered_acceleration\n"


def test_decimal_commas_under_a_comma_column_line_are_refused(tmp_path):
    log = tmp_path / "log.csv"
    log.write_text(CATS + "-0,02,0,5,0,0981\n0,01,1,0,98,1\n0,02,2,5,100,0\n")
    out = tmp_path / "t.csv"
    r = run_fsw("tape", "import", "cats", str(log), "-o", str(out))
    assert r.code == 1 and not out.exists(), r.err
    assert r.err.startswith(f"fsw tape import: {log}:2:9: the row has 6 cells, the column line (line 1) names 3:"), \
        r.err
    assert "`5` lies beyond its columns" in r.err and f"{log}:3:" in r.err and f"{log}:4:" in r.err


def test_trailing_empty_cells_are_read(tmp_path):
    log = tmp_path / "log.csv"
    log.write_text(CATS.rstrip("\n") + ",,\n" + "-0.02,0.5,0.0981,,\n0.0,1.0,98.1,, \n0.01,2.0,100.0,,\n")
    assert convert("cats", str(log)).rows == 3


@pytest.mark.parametrize("fmt,text,where", [
    ("rrc3", "time,altitude,pressure,velocity,temperature,events,voltages\n"
             + "".join(f"{i / 20:.2f},0,861.7,0,20,-,3.8\n" for i in range(5)) + "0.25,0,861.7,0,20,Drogue,Main,3.8\n",
     ":7:"),
    ("eggtimer", "T,Alt,Veloc\n0,0,0\n50,10,200,7\n", ":3:"),
])
def test_every_format_refuses_a_wider_row(tmp_path, fmt, text, where):
    log = tmp_path / "log.csv"
    log.write_text(text)
    with pytest.raises(TapeError) as e:
        convert(fmt, str(log))
    assert f"{log}{where}" in str(e.value) and "the column line (line 1) names" in str(e.value), str(e.value)


def test_an_altos_export_wider_than_its_column_line_is_read(tmp_path):
    # AltosCSV.java writes 9 advanced values (accel, gyro, mag) under 6 names: a TeleMega's rows
    # are 3 cells wider than its column line, after the basic columns the converter reads
    head = ("#version,serial,flight,call,time,clock,rssi,lqi,state,state_name,acceleration,pressure,altitude,"
            "height,accel_speed,baro_speed,temperature,drogue_voltage,main_voltage,battery_voltage,accel_x,"
            "accel_y,accel_z,gyro_x,gyro_y,gyro_z\n")
    rows = "".join(f"5, 6583, 3, N0CALL, {i / 10 - 0.2:8.2f}, {i:8.2f}, 0, 0,2,     pad,{0.1 * i:8.2f},"
                   f"{90000 - i:10.2f},1000.0,{i:8.2f},0,0,20.0,3.9,3.9,4.0,"
                   "0.1,0.2,9.8,0.0,0.0,0.0,0.3,0.1,0.5\n" for i in range(4))
    log = tmp_path / "altos.csv"
    log.write_text(head + rows)
    t = convert("altos", str(log))
    assert t.rows == 4 and t.pressure.tolist() == [90000.0, 89999.0, 89998.0, 89997.0]
