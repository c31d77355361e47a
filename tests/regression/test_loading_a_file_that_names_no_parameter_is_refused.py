"""`fsw param load FILE` applies a file whole and saves it. A file that
names no parameter (only comments, an empty file, the wrong file emptied)
staged nothing, committed, and wrote the live values to the EEPROM: a
`set` the team had not meant to keep was saved by a load that loaded
nothing, and the command said "loaded 0 value(s) ... saved". Now such a
file is refused, located, before the port is opened."""

from __future__ import annotations

import time
from pathlib import Path

from conftest import run_fsw
from support.linkfw import PtyTarget, needs_cxx
from support.simfw import kept_native

pytestmark = needs_cxx()
RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"


def test_an_empty_file_loads_and_saves_nothing(tmp_path):
    exe = kept_native(RIG) / "tuned"
    f = tmp_path / "empty.toml"
    f.write_text("# field 3: nothing changed\n")
    with PtyTarget(exe, "--eeprom", str(tmp_path / "e.bin")) as t:
        time.sleep(0.2)
        assert run_fsw("param", str(RIG), "set", "OPEN_AT=650.5", "--port", t.port).code == 0
        r = run_fsw("param", str(RIG), "load", str(f), "--port", t.port)
        assert r.code == 2, r.out + r.err
        assert f"{f}: names no parameter: nothing to load" in r.err, r.err
        r = run_fsw("param", str(RIG), "list", "--port", t.port)
        assert "(defaults, unsaved changes; live CRC" in r.out, r.out  # nothing was saved
