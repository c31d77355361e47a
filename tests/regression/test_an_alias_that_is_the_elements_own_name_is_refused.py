"""`bool valveOpen @alias valveOpen` in a machine's [state_vector] was
accepted without a word: an alias is another name for the element, and
one equal to its own name names nothing new (spec: a name is used once in
a machine). It is now an error at the alias."""

from __future__ import annotations

import shutil

from conftest import EXAMPLES, run_fsw


def test_an_alias_equal_to_the_name_is_an_error_at_it(tmp_path):
    tank = tmp_path / "tank"
    shutil.copytree(EXAMPLES / "tank", tank, ignore=shutil.ignore_patterns("build"))
    sm = tank / "tank.sm"
    text = sm.read_text()
    assert "\nbool valveOpen\n" in text
    sm.write_text(text.replace("\nbool valveOpen\n", "\nbool valveOpen @alias valveOpen\n", 1))
    line = next(n for n, l in enumerate(sm.read_text().splitlines(), 1) if "@alias valveOpen" in l)
    r = run_fsw("check", str(sm))
    out = r.out + r.err
    assert r.code == 1, out
    assert f"tank.sm:{line}:23:" in out and "is the element's own name" in out, out
