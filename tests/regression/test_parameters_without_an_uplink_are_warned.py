"""An application whose machines declare parameters but whose [tasks] have
no `uplink` task passed `fsw check` without a word: nothing receives the
parameter commands, so the ground can neither read nor change them, and
the firmware still boots with whatever an earlier firmware of the same
parameter table saved in the EEPROM (values no one can see over the
link). Now `fsw check` warns at the machine that declares them, as it
warns of writable elements without an uplink."""

from __future__ import annotations

import shutil
from pathlib import Path

from conftest import run_fsw

RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"


def test_parameters_without_an_uplink_task_are_warned(tmp_path):
    rig = tmp_path / "rig"
    shutil.copytree(RIG, rig)
    app = rig / "tuned.app"
    text = app.read_text().replace("up   uplink          rate=100\n", "")
    app.write_text(text.replace("[uplink]\narm\npressure\n", ""))
    r = run_fsw("check", str(app))
    assert r.code == 0, r.err
    assert ("application config warning @ " in r.err and "tuned.app:8:9:" in r.err
            and "parameters without an `uplink` task in [tasks]: the ground can neither read nor change them; the "
                "firmware boots with what an earlier firmware of the same parameter table saved in the EEPROM, else "
                "the defaults" in r.err), r.err
    assert "1 warning" in r.err


def test_with_an_uplink_no_warning():
    r = run_fsw("check", str(RIG / "tuned.app"))
    assert r.code == 0 and "0 warnings" in r.err, r.err
