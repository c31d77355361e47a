"""[log] messages no golden case holds (tests/autocode/golden/app/log_*.app
hold the rest): a board without EEPROM (none in boards/ is one), and more
elements than a record's field table takes."""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

from conftest import run_fsw

from fswkit.autocode.appcheck import check_app
from fswkit.autocode.appsyntax import parse_app
from fswkit.autocode.board import load_board
from fswkit.autocode.diagnostics import APP, Diagnostics, read_source

RIG = Path(__file__).resolve().parent / "logged"


def test_a_board_without_eeprom_is_told_so():
    diags = Diagnostics()
    src = read_source(str(RIG / "logged.app"), diags, APP)
    tree = parse_app(src, diags)
    check_app(tree, diags, None, lambda name: dataclasses.replace(load_board(name), eeprom=0))
    assert [(d.line, d.message) for d in diags.errors] == [(26, "the uno has no EEPROM")]  # at `store eeprom`


def test_at_most_32_elements_are_logged(tmp_path):
    project = tmp_path / "many"
    shutil.copytree(RIG, project)
    sv = (project / "logged.sv").read_text() + "".join(f"F32 x{i}\n" for i in range(33))
    (project / "logged.sv").write_text(sv)
    app = (project / "logged.app").read_text()
    app = app.replace("element state\n", "element state\n" + "".join(f"element x{i}\n" for i in range(30)))
    (project / "logged.app").write_text(app)
    r = run_fsw("check", str(project / "logged.app"))
    assert r.code == 1 and "at most 32 elements are logged" in r.err, r.err
    line = app.splitlines().index("element x29") + 1  # the 33rd `element` row
    assert f"logged.app:{line}:1:" in r.err


def test_a_sample_of_more_than_253_bytes_is_refused(tmp_path):
    project = tmp_path / "wide"
    shutil.copytree(RIG, project)
    sv = (project / "logged.sv").read_text() + "".join(f"F64 w{i}\n" for i in range(32))
    (project / "logged.sv").write_text(sv)
    app = (project / "logged.app").read_text().replace("record  64", "record  255")
    i = app.index("element level")
    app = app[:i] + "".join(f"element w{k}\n" for k in range(32))
    (project / "logged.app").write_text(app)
    r = run_fsw("check", str(project / "logged.app"))
    assert r.code == 1 and "the logged elements take 256 bytes a sample: at most 253" in r.err, r.err


def test_a_recorded_value_agrees_with_telemetry_within_half_a_step_and_binary32s_rounding():
    from fswkit.recorder.check import agrees

    # seed 20 of the rocket: 306.1499938964844 x 10 is 3061.5 in binary32, a count of 3062
    assert agrees(306.2, 306.1499938964844, 0.05 + 1e-6)
    assert agrees(306.1, 306.14, 0.05 + 1e-6)
    assert not agrees(306.3, 306.1499938964844, 0.05 + 1e-6)  # a whole step out
    assert not agrees(306.21, 306.15, 0.05 + 1e-6)
    assert agrees(7.0, 7.0, 0.0) and not agrees(7.0, 7.000001, 0.0)  # held and raw values: equal
