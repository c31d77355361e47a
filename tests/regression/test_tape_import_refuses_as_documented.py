"""What `fsw tape import` and the tape reader refused, they refused in their
own words rather than the documented ones: `--pad-alt nan` (or 20000) was
exit 1, not the 2 of a wrong command line; an existing output was `X: the
file exists: it is not replaced unless asked`, not the kit's `X exists: it
is replaced only when asked (--force)` that docs/cli.md quotes; a log that
is not UTF-8, or empty, was called a tape (`a tape is UTF-8 text`, `a tape
starts with the line # fswkit sensor tape v1`). And a cell Python's
float() takes but no CSV means as a number (`1_000`, Arabic-Indic digits)
was read as one, in a log and in a tape. A time written `NaN` was said to
be empty."""

from __future__ import annotations

import pytest

from conftest import run_fsw

from fswkit.tape import TapeError, read_tape

CATS = "ts,filtered_altitude_AGL,filtered_acceleration\n-0.1,0,0\n0,0.5,30\n0.1,3,30\n"


@pytest.fixture
def log(tmp_path):
    p = tmp_path / "log.csv"
    p.write_text(CATS)
    return p


@pytest.mark.parametrize("value", ["nan", "inf", "20000", "-600", "abc"])
def test_a_pad_altitude_out_of_range_is_a_command_line_error(tmp_path, log, value):
    r = run_fsw("tape", "import", "cats", str(log), "-o", str(tmp_path / "t.csv"), f"--pad-alt={value}")
    assert r.code == 2, r.err
    assert "--pad-alt" in r.err and "Traceback" not in r.err
    assert not (tmp_path / "t.csv").exists()


def test_an_existing_output_is_refused_in_the_kits_words(tmp_path, log):
    out = tmp_path / "t.csv"
    out.write_text("my notes\n")
    r = run_fsw("tape", "import", "cats", str(log), "-o", str(out))
    assert r.code == 1
    assert r.err == f"fsw tape import: {out} exists: it is replaced only when asked (--force)\n"
    assert out.read_text() == "my notes\n"


def test_a_log_that_is_not_utf8_or_empty_is_called_a_log(tmp_path, log):
    log.write_bytes(CATS.replace("0.5", "0.\xe95").encode("latin-1"))
    r = run_fsw("tape", "import", "cats", str(log), "-o", str(tmp_path / "t.csv"))
    assert r.code == 1
    assert r.err.startswith(f"fsw tape import: {log}:3:5: not a text file (binary data here): the log is read "
                            "as UTF-8 text"), r.err
    log.write_bytes(b"")
    r = run_fsw("tape", "import", "cats", str(log), "-o", str(tmp_path / "t.csv"))
    assert r.err == f"fsw tape import: {log}: empty file: a recorder's log holds a column line and rows " \
                    "(docs/tapes.md, Converters)\n"


@pytest.mark.parametrize("cell", ["1_000", "\u0661\u0662", "\uff11"])
def test_a_log_cell_python_takes_but_csv_does_not_is_not_a_number(tmp_path, log, cell):
    log.write_text(CATS.replace("0,0.5,30", f"0,{cell},30"))
    r = run_fsw("tape", "import", "cats", str(log), "-o", str(tmp_path / "t.csv"))
    assert r.code == 1, r.err
    assert f"{log}:3:3: filtered_altitude_AGL (`filtered_altitude_AGL`): `{cell}` is not" in r.err, r.err


@pytest.mark.parametrize("cell", ["1_000", "\u0661\u0662", "\uff11"])
def test_a_tape_cell_python_takes_but_csv_does_not_is_not_a_number(tmp_path, cell):
    p = tmp_path / "t.csv"
    p.write_text(f"# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n0,90000,1\n1,{cell},1\n")
    with pytest.raises(TapeError) as e:
        read_tape(str(p))
    assert str(e.value) == f"{p}:4:3: pressure_pa: `{cell}` is not a number (leave the cell empty for " \
                           "\"not available\")"


def test_a_nan_time_is_not_called_empty(tmp_path, log):
    log.write_text(CATS.replace("0,0.5,30", "NaN,0.5,30"))
    r = run_fsw("tape", "import", "cats", str(log), "-o", str(tmp_path / "t.csv"))
    assert r.code == 1
    assert r.err == f"fsw tape import: {log}:3:1: ts (`ts`): `NaN` is not a finite number\n", r.err
