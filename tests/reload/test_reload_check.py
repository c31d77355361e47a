"""[reload] messages no golden case holds (tests/autocode/golden/app/reload_*.app
hold the rest), the EEPROM the slots share with the parameters and the
flight recorder, and what a [reload] adds to the generated code."""

from __future__ import annotations

import dataclasses
import re
import shutil
from pathlib import Path

from conftest import EXAMPLES

from fswkit.autocode.appcheck import check_app
from fswkit.autocode.appsyntax import parse_app
from fswkit.autocode.board import load_board
from fswkit.autocode.diagnostics import APP, Diagnostics, read_source

GOLDEN = Path(__file__).resolve().parents[1] / "autocode" / "golden" / "app"


def _rig(tmp: Path, reload: str) -> Path:
    for name in ("rig.sv", "rig.sm", "rig.aio", "rig.dio"):
        shutil.copy(GOLDEN / name, tmp / name)
    text = (GOLDEN / "valid.app").read_text()
    app = tmp / "rig.app"
    app.write_text(text + "\n[reload]\n" + reload)
    return app


def _errors(app: Path, board=load_board) -> list[tuple[int, str]]:
    diags = Diagnostics()
    src = read_source(str(app), diags, APP)
    check_app(parse_app(src, diags), diags, None, board)
    return [(d.line, d.message) for d in diags.errors]


def test_activate_without_states_is_refused(tmp_path):
    assert _errors(_rig(tmp_path, "machine rig\nactivate\n")) == [(36, "`activate` takes states of machine `rig`")]


def test_a_signed_number_is_one_value_out_of_range(tmp_path):
    """`size -5` is a number out of range, not two values."""
    msg = "`size` takes the bytes of a slot (an image and its state mask): a whole number from 32 to 4096"
    assert _errors(_rig(tmp_path, "machine rig\nsize -5\n")) == [(36, msg)]
    assert _errors(_rig(tmp_path, "machine rig\nsize +128\n")) == [(36, msg)]


def test_a_machine_no_image_could_replace_is_refused(tmp_path):
    """An uploaded machine keeps the generated machine's states at their
    numbers; an image holds at most 255 states: a machine of 256 could never
    be replaced, and the section is refused (255 is the boundary)."""
    head = (GOLDEN / "rig.sm").read_text()
    for n, ok in ((255, True), (256, False)):
        app = _rig(tmp_path, "machine rig\n")
        (tmp_path / "rig.sm").write_text(head + "".join(f"\n[X{i}]\n" for i in range(n - _states(head))))
        errs = _errors(app)
        assert (errs == []) is ok, errs
    assert errs == [(35, "machine `rig` has 256 states: an uploaded machine keeps them at their numbers and an image "
                         "holds at most 255, so no machine could ever replace it")]


def _states(sm_text: str) -> int:
    return sum(1 for line in sm_text.splitlines() if re.fullmatch(r"\[[A-Za-z_]\w*\]", line.strip())
               and line.strip() not in ("[state_vector]", "[local]", "[parameters]"))


def test_a_board_without_eeprom_is_told_so(tmp_path):
    errs = _errors(_rig(tmp_path, "machine rig\n"), lambda name: dataclasses.replace(load_board(name), eeprom=0))
    assert errs == [(35, "the uno has no EEPROM to keep uploaded machines in")]


def test_the_slots_share_the_eeprom_with_the_parameters_and_the_recorder(tmp_path):
    """The rocket keeps 6 parameters (2 banks of 9 + 24 B) and its record in
    the Uno's 1,024 B: slots of 440 B leave the recorder less than two records;
    of 300 B, the recorder's area starts after them."""
    from fswkit.autocode.recorder import plan
    from fswkit.target.build import load

    folder = tmp_path / "rocket"
    shutil.copytree(EXAMPLES / "rocket", folder, ignore=shutil.ignore_patterns("build"))
    app_path = folder / "rocket.app"
    base = app_path.read_text()
    app_path.write_text(base + "\n[reload]\nmachine mission\nsize 440\nactivate Safe\n")
    diags = Diagnostics()
    assert load(str(folder), diags) is None
    [err] = [d for d in diags.errors]
    assert re.fullmatch(r"the two slots take 898 B \(2 x \(9 \+ 440\)\), the parameters' banks 66 B, the recorder at "
                        r"least 2 records of 64 B: more than the uno's 1,024 B of EEPROM; lower `size`", err.message), \
        err.message
    app_path.write_text(base + "\n[reload]\nmachine mission\nsize 300\nactivate Safe\n")
    diags = Diagnostics()
    app = load(str(folder), diags)
    assert app is not None, diags.render()
    assert plan(app).base == 66 + 2 * (9 + 300)  # the parameters' banks, then the two slots


def test_the_generated_code_runs_the_machine_through_the_store():
    """The reloadable machine's task steps fsw::reload_step; its machine
    gets leave(); the slots follow the parameters in the EEPROM; another
    machine's code is as without [reload]."""
    from fswkit.autocode.emit.app import emit_app
    from fswkit.target.build import load

    app = load(str(EXAMPLES / "stand"), Diagnostics())
    files = emit_app(app)
    cpp = files["app.gen.cpp"]
    assert "return fsw::reload_step(reload);" in cpp and "tank::step();" not in cpp.split("task_control")[1][:200]
    assert "fsw::reload_begin(reload, &kReloadConfig);" in cpp and "fsw::reload_poll(reload);" in cpp
    assert "kReloadAllow[1] FSW_FLASH = {0x05};  // TankVentControl Idle" in cpp
    assert "384, 64, 0, 1};" in cpp  # size, ram, EEPROM base (no parameters), mask bytes
    assert "&reload, fsw::link_reload_apply, fsw::link_reload_ack, link_rx, 0, 0};" in cpp  # its buffer: pipelined
    # (its locals passed as its state functions take them: through a pointer in step(), docs/codegen.md)
    assert "void leave();" in files["tank.gen.h"] and "case S_TankVentControl: s1_exit(loc); break;" in files["tank.gen.cpp"]
    plain = emit_app(load(str(EXAMPLES / "tank"), Diagnostics()))
    assert "leave" not in plain["tank.gen.h"] and "reload" not in plain["app.gen.cpp"]
    assert ", 0, 0, 0};" in plain["app.gen.cpp"]  # the link's reload fields, empty


def test_an_upload_the_board_could_not_run_is_refused_on_the_ground(capsys):
    """Before any port is opened: a machine needing more RAM than [reload]
    ram, and one with none of the states [reload] activate names (once
    running it could never be replaced)."""
    from fswkit.cli.machine import image_for
    from fswkit.target.build import load

    app = load(str(EXAMPLES / "stand"), Diagnostics())
    new = str(EXAMPLES / "stand" / "tank_700.sm")
    assert image_for(app, new, Diagnostics()) is not None
    small = dataclasses.replace(app, reload=dataclasses.replace(app.reload, ram=16))
    assert image_for(small, new, Diagnostics()) is None
    assert "needs 20 B for its windows and locals: more than the 16 B [reload] ram" in capsys.readouterr().err
    stuck = dataclasses.replace(app, reload=dataclasses.replace(app.reload, activate=("Nowhere",)))
    assert image_for(stuck, new, Diagnostics()) is None
    assert "has none of the states in which [reload] lets another machine take over (Nowhere)" in \
        capsys.readouterr().err
