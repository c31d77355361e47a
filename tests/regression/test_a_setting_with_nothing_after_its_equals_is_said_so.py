"""A `key=value` setting of an .app row written with nothing after its
`=` (`arm=  continuity=drogueSense ...`, a value deleted while editing)
took the next setting's key for its value: `fsw check` said `unknown
element `continuity`` at the next word and `unexpected `=`` after it, two
errors that named neither the setting at fault nor what was missing. A
value must follow its `=` with no blank between; a setting without one is
one error at it: `arm=` has no value. So for a pyro row and for a task's
options alike."""

from __future__ import annotations

import shutil

import pytest

from conftest import EXAMPLES, run_fsw


@pytest.mark.parametrize("old, new, key", [
    ("drogue    arm=armSwitch  continuity", "drogue    arm=  continuity", "arm"),
    ("sense    inputs            rate=100", "sense    inputs            rate= ", "rate"),
    ("nav      machine nav       rate=100", "nav      machine nav       rate=\trate=100", "rate"),
])
def test_a_setting_without_a_value_is_one_error_at_it(tmp_path, old, new, key):
    proj = tmp_path / "rocket"
    shutil.copytree(EXAMPLES / "rocket", proj, ignore=shutil.ignore_patterns("build"))
    app = proj / "rocket.app"
    text = app.read_text()
    assert old in text
    app.write_text(text.replace(old, new, 1))
    line = next(n for n, l in enumerate(app.read_text().splitlines(), 1) if l.startswith(new.split()[0] + " "))
    r = run_fsw("check", str(proj))
    assert r.code == 1, r.out + r.err
    out = r.out + r.err
    assert out.count(" error @ ") == 1, out
    assert f"rocket.app:{line}:" in out and f"`{key}=` has no value" in out, out
    assert "unknown element" not in out
