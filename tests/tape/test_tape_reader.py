"""fswkit.tape.tape: the sensor tape v1 reader, its located errors, the
writer's refusal to overwrite, and the truth file reader."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

from conftest import run_fsw
from fswkit.outputs import OutputError
from fswkit.tape import Tape, TapeError, isa_altitude, isa_pressure, parse_tape, read_tape, read_truth, write_tape
from fswkit.tape import tape as tape_mod

GOOD = """# fswkit sensor tape v1
# source: example/log@0000:flight.csv (MIT)
# flight: Test, 2026-01-01, recorder Nothing, pad 100 m ASL
# derived: written by hand for this test
# note: a note
time_s,pressure_pa,accel_g
-0.2,100000,1
-0.1,100001.5,
0,,5.25
0.1,99990,-0.5
"""


def write(tmp_path, text, name="t.csv"):
    p = tmp_path / name
    p.write_bytes(text.encode() if isinstance(text, str) else text)
    return str(p)


def errors(tmp_path, text) -> list[str]:
    path = write(tmp_path, text)
    with pytest.raises(TapeError) as e:
        read_tape(path)
    return [m.replace(path, "T") for m in e.value.messages]


def test_isa_formula_and_inverse():
    assert isa_altitude(101325.0) == pytest.approx(0.0)
    # the README's formula, written out
    assert isa_altitude(86338.1) == pytest.approx(44330.77 * (1 - (86338.1 / 101325) ** 0.190263))
    assert isa_pressure(1394.0) == pytest.approx(101325 * (1 - 1394.0 / 44330.77) ** (1 / 0.190263))
    h = np.array([-100.0, 0.0, 1500.0, 6000.0])
    assert np.allclose(isa_altitude(isa_pressure(h)), h, atol=1e-6)


def test_reads_a_tape_with_empty_cells_as_nan(tmp_path):
    t = read_tape(write(tmp_path, GOOD))
    assert t.rows == 4 and t.start == -0.2 and t.end == 0.1
    assert t.time.tolist() == [-0.2, -0.1, 0.0, 0.1]
    assert t.pressure[1] == 100001.5 and math.isnan(t.pressure[2])
    assert math.isnan(t.accel[1]) and t.accel[2] == 5.25
    assert t.sources == ("example/log@0000:flight.csv (MIT)",)
    assert t.flight.startswith("Test, 2026-01-01")
    assert t.derived == ("written by hand for this test",) and t.notes == ("a note",)
    assert t.columns_available() == ("pressure_pa", "accel_g")
    assert t.pad_pressure() == pytest.approx(100000.75)
    assert t.rate_hz() == pytest.approx(10.0)


def test_crlf_and_byte_order_mark_are_taken(tmp_path):
    t = read_tape(write(tmp_path, b"\xef\xbb\xbf" + GOOD.replace("\n", "\r\n").encode()))
    assert t.rows == 4


@pytest.mark.parametrize("text, expected", [
    ("", "T: empty file"),
    ("time_s,pressure_pa,accel_g\n0,1,1\n", "T:1:1: not a fswkit sensor tape"),
    ("# fswkit sensor tape v1\ntime,pressure,accel\n0,1,1\n", "T:2:1: expected the column line"),
    ("# fswkit sensor tape v1\n# source: x\n", "T:2:1: the header ends without the column line"),
    ("# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n", "T:2:27: no data rows"),
    ("# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n0,1x,1\n", "T:3:3: pressure_pa: `1x` is not a number"),
    ("# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n0,100,nan\n", "T:3:7: accel_g: `nan` is not a finite"),
    ("# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n0,inf,1\n", "T:3:3: pressure_pa: `inf` is not a finite"),
    ("# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n0,1,1\n0,1,1\n", "T:4:1: time_s 0 is not after"),
    ("# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n1,1,1\n0.5,1,1\n", "T:4:1: time_s 0.5 is not after"),
    ("# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n,1,1\n", "T:3:1: time_s is empty"),
    ("# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n0,1\n", "T:3:1: expected 3 cells"),
    ("# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n0,1,1\n# late\n", "T:4:1: a `#` line among"),
    ("# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n0,-5,1\n", "T:3:3: pressure_pa -5 is not above 0"),
    (b"# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n0,1\x00,1\n", "T:3:4: not a text file"),
    (b"\x89PNG\r\n\x1a\n\x00\x00", "T:1:1: not a text file"),
    (b"# fswkit sensor tape v1\n\xff\xfe", "T:2:1: not a text file"),
])
def test_every_malformed_input_is_a_located_error(tmp_path, text, expected):
    msgs = errors(tmp_path, text)
    assert any(m.startswith(expected) for m in msgs), msgs


def test_errors_are_collected_and_capped(tmp_path):
    rows = "".join(f"{i},x,1\n" for i in range(50))
    path = write(tmp_path, "# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n" + rows)
    with pytest.raises(TapeError) as e:
        read_tape(path)
    assert len(e.value.messages) == tape_mod.MAX_ERRORS and e.value.hidden == 30
    assert "30 more not shown" in str(e.value)


def test_huge_file_and_fifo_are_refused_without_reading(tmp_path, monkeypatch):
    path = write(tmp_path, GOOD)
    monkeypatch.setattr(tape_mod, "MAX_TAPE", 100)
    with pytest.raises(TapeError, match="file too large"):
        read_tape(path)
    fifo = str(tmp_path / "fifo.csv")
    os.mkfifo(fifo)
    with pytest.raises(TapeError, match="not a regular file"):
        read_tape(fifo)
    with pytest.raises(TapeError, match="no such file"):
        read_tape(str(tmp_path / "none.csv"))


def test_write_round_trips_and_never_overwrites_unasked(tmp_path):
    t = read_tape(write(tmp_path, GOOD))
    out = str(tmp_path / "out.csv")
    write_tape(out, t)
    back = read_tape(out)
    assert np.array_equal(back.time, t.time)
    assert np.allclose(back.pressure, t.pressure, equal_nan=True)
    assert np.allclose(back.accel, t.accel, equal_nan=True)
    assert back.sources == t.sources and back.derived == t.derived and back.notes == t.notes
    before = open(out).read()
    with pytest.raises(OutputError, match="exists.*--force"):
        write_tape(out, t)
    assert open(out).read() == before
    assert not [f for f in os.listdir(tmp_path) if f.endswith(".part")]
    write_tape(out, t, force=True)
    with pytest.raises(OutputError, match="input"):
        write_tape(out, t, force=True, inputs=(out,))


def test_writer_refuses_arrays_no_file_could_hold(tmp_path):
    bad = Tape("x.csv", np.array([0.0, 0.0]), np.array([1.0, 1.0]), np.array([1.0, 1.0]))
    with pytest.raises(TapeError, match="not after"):
        write_tape(str(tmp_path / "x.csv"), bad)
    assert not os.path.exists(tmp_path / "x.csv")


def test_parse_from_text():
    assert parse_tape(GOOD, "mem").rows == 4


TRUTH = """# a truth file
name = "t"
recorder = "Nothing"
liftoff_s = 0.0
apogee_s = 12.5  # a comment
apogee_m_agl = 800
recorder_apogee_event_s = 12.7
recorder_apogee_event_minus_baro_apogee_s = 0.2
something_new = "kept"
"""


def test_truth_keys_typed_optional_and_unknown_kept(tmp_path):
    tr = read_truth(write(tmp_path, TRUTH, "t.truth.toml"))
    assert tr.name == "t" and tr.recorder == "Nothing"
    assert tr.apogee_s == 12.5 and tr.apogee_m_agl == 800.0 and tr.landing_s is None
    assert tr.recorder_events["recorder_apogee_event_s"] == 12.7
    assert tr.extra == {"something_new": "kept"}
    assert [k for k, _ in tr.events()] == ["liftoff_s", "apogee_s", "recorder_apogee_event_s"]


@pytest.mark.parametrize("text, expected", [
    ('recorder = "x"\n', "T:1:1: a truth file needs `name"),
    ('name = "t"\napogee_s = "soon"\n', "T:2:1: `apogee_s` must be a finite number"),
    ('name = "t"\napogee_s = nan\n', "T:2:1: `apogee_s` must be a finite number"),
    ('name = "t"\napogee_s = = 1\n', "T:2:12: "),
])
def test_truth_errors_are_located(tmp_path, text, expected):
    path = write(tmp_path, text, "t.truth.toml")
    with pytest.raises(TapeError) as e:
        read_truth(path)
    assert str(e.value).replace(path, "T").startswith(expected), str(e.value)


def test_fsw_tape_show(tmp_path):
    path = write(tmp_path, GOOD)
    write(tmp_path, TRUTH, "t.truth.toml")
    r = run_fsw("tape", "show", path)
    assert r.code == 0, r.err
    assert "rows:    4, time -0.200 to 0.100 s" in r.out
    assert "apogee_s" in r.out and "recorder_apogee_event_s" in r.out and "_minus_" not in r.out
    bad = write(tmp_path, "# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n0,x,1\n", "b.csv")
    r = run_fsw("tape", "show", bad)
    assert r.code == 1 and f"{bad}:3:3: pressure_pa" in r.err and "Traceback" not in r.err
