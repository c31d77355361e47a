"""A parameter's name reaches C++ behind the prefix `P_`, and names a
system header defines as a macro with that prefix get a `0` after it
(autocode/cnames.py `enumerator`). The machine's header declared a
parameter `tmpdir` as `P_0tmpdir`, but the application's parameter table
(app.gen.cpp) wrote `P_tmpdir`, which glibc's stdio.h defines as "/tmp":
the native build failed with "an internal error" for a configuration
`fsw check` accepts. Now the table names the enumerator the header
declares, and the firmware builds and runs with it."""

from __future__ import annotations

import shutil
import time
from pathlib import Path

from conftest import run_fsw
from support.linkfw import PtyTarget, needs_cxx

pytestmark = needs_cxx()
RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"


def test_a_parameter_named_tmpdir_builds_and_is_listed(tmp_path):
    rig = tmp_path / "rig"
    shutil.copytree(RIG, rig)
    sm = rig / "tuned.sm"
    sm.write_text(sm.read_text().replace("HOLD_MS", "tmpdir"))
    assert run_fsw("check", str(rig / "tuned.app")).code == 0
    out = tmp_path / "out"
    r = run_fsw("build", str(rig), "--board", "native", "--out", str(out))
    assert r.code == 0, r.err
    assert "P_0tmpdir" in (out / "gen" / "app.gen.cpp").read_text()
    with PtyTarget(out / "tuned", "--eeprom", str(tmp_path / "e.bin")) as t:
        time.sleep(0.2)
        r = run_fsw("param", str(rig), "get", "tmpdir", "--port", t.port)
        assert r.code == 0, r.err
        assert r.out.strip() == "tmpdir = 500"
