"""`fsw check examples/stand` failed: `tank_700.sm`, the machine the stand's
crew uploads, sits beside `stand.app`, whose state vector is
`../tank/tank.sv`, and the search for a machine's state vector looked only
for `.sv` files in its folder (`no state vector config (.sv) found beside
tank_700.sm`); `fsw compile` of it needed `--sv`. A machine with no state
vector of its own beside it now takes the one the folder's application
config names, the one `fsw machine upload` compiles it against."""

from __future__ import annotations

import shutil

from conftest import EXAMPLES

STAND = EXAMPLES / "stand"


def test_the_stand_project_checks_clean(fsw):
    r = fsw("check", str(STAND))
    assert r.code == 0, r.err
    assert "fsw check: 2 files, 0 errors" in r.err


def test_the_machine_to_upload_compiles_to_the_image_fsw_machine_sends(fsw, tmp_path):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.cli.machine import image_for
    from fswkit.target.build import load

    out = tmp_path / "tank_700.fsm"
    r = fsw("compile", str(STAND / "tank_700.sm"), "--board", "uno", "-o", str(out))
    assert r.code == 0, r.err
    app = load(str(STAND), Diagnostics())
    assert out.read_bytes() == image_for(app, str(STAND / "tank_700.sm"), Diagnostics())[0]


def test_two_applications_in_the_folder_decide_nothing(fsw, tmp_path):
    folder = tmp_path / "stand"
    shutil.copytree(STAND, folder, ignore=shutil.ignore_patterns("build"))
    for name in ("stand.app", "other.app"):
        (folder / name).write_text((STAND / "stand.app").read_text().replace("../tank/", f"{EXAMPLES}/tank/"))
    r = fsw("compile", str(folder / "tank_700.sm"), "-o", str(tmp_path / "x.fsm"))
    assert r.code == 2 and "no state vector config (.sv) found beside" in r.err, r.err
