"""A log with one pressure not above 0 Pa (a sensor's glitch row), or one so
large that in hPa times 100 it is no number, stopped `fsw tape import`
with a message naming the tape it was to write, with no line:
`tape.csv: pressure_pa holds a value not above 0 Pa`, and numpy's
RuntimeWarnings on standard error. Now it is the log's cell, located
`LOG:LINE:COL`, like any other cell the converter cannot take."""

from __future__ import annotations

from conftest import run_fsw

ALTOS = "#version,serial,flight,call,time,state,state_name,acceleration,pressure,altitude,height,speed\n"
ROWS = [(-0.2, "90000"), (-0.1, "90001"), (0.0, "89990"), (0.1, "89900"), (0.2, "89800")]


def altos(bad_row: int, value: str) -> tuple[str, int]:
    lines = [ALTOS]
    for i, (t, p) in enumerate(ROWS):
        lines.append(f"6,1,1,X,{t},2,pad,0.0{i},{value if i == bad_row else p},1,1,1\n")
    text = "".join(lines)
    line = text.splitlines()[bad_row + 1]
    col = len(",".join(line.split(",")[:8])) + 2
    return text, col


def refused(tmp_path, fmt, text):
    log = tmp_path / "log.csv"
    log.write_text(text)
    out = tmp_path / "tape.csv"
    r = run_fsw("tape", "import", fmt, str(log), "-o", str(out))
    assert r.code == 1, r.err
    assert "Traceback" not in r.err and "Warning" not in r.err, r.err
    assert not out.exists()
    return r.err.replace(str(log), "LOG")


def test_a_pressure_not_above_zero_is_located_in_the_log(tmp_path):
    for value in ("-3", "0"):
        text, col = altos(3, value)
        err = refused(tmp_path, "altos", text)
        assert err.startswith(f"fsw tape import: LOG:5:{col}: pressure (`pressure`): `{value}` is not above 0 Pa"), err
        assert "tape.csv" not in err


def test_a_pressure_too_large_once_scaled_is_located_in_the_log(tmp_path):
    text, col = altos(2, "9e307")  # the log in hPa (its median): 9e307 * 100 is beyond binary64
    hpa = text.replace("90000", "900.00").replace("90001", "900.01").replace("89900", "899.00") \
        .replace("89800", "898.00")
    err = refused(tmp_path, "altos", hpa)
    assert err.startswith(f"fsw tape import: LOG:4:{col}: pressure (`pressure`): `9e307`"), err
    assert "hPa" in err


def test_a_cats_barometer_pressure_not_above_zero_is_located(tmp_path):
    text = "ts,id,T,P\n-0.01,BARO0,25.0,99619\n0.0,BARO0,25.0,-1\n0.01,BARO0,25.0,99500\n"
    err = refused(tmp_path, "cats", text)
    assert err.startswith("fsw tape import: LOG:3:16: P (`P`): `-1` is not above 0 Pa"), err
