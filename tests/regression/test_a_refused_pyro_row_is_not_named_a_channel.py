"""A `[pyro]` row refused for its element (here `abortCmd`, which no `o`
row of a .dio table drives) still counted as a pyro channel for the
[uplink] check: besides the row's own error, `fsw check` said at the
[uplink] row that `abortCmd` "is pyro channel `abortCmd` (line 60): the
ground cannot write it", a second error about a channel that does not
exist. Now only an element a pyro row names *and* a .dio table drives is
refused in [uplink]; the row's own error says what is wrong."""

from __future__ import annotations

import shutil

from conftest import EXAMPLES


def test_the_uplink_row_is_not_blamed(fsw, tmp_path):
    shutil.copytree(EXAMPLES / "rocket", tmp_path / "rocket")
    app = tmp_path / "rocket" / "rocket.app"
    text = app.read_text()
    old = "drogue    arm=armSwitch  continuity=drogueSense"
    assert old in text
    app.write_text(text.replace(old, "abortCmd  arm=armSwitch  continuity=drogueSense", 1))
    r = fsw("check", str(app))
    assert r.code == 1, r.err
    assert "`abortCmd` is not a digital output" in r.err
    assert "is pyro channel `abortCmd`" not in r.err
    assert "1 error," in r.err.splitlines()[-1], r.err
