"""`bool valveOpen @alias valveOpen` in a machine's [state_vector] was
accepted without a word: an alias is another name for the element, and
one equal to its own name names nothing new (spec: a name is used once in
a machine). It is now an error at the alias."""

from __future__ import annotations

from conftest import run_fsw
from support.configs import edit, tank_configs


def test_an_alias_equal_to_the_name_is_an_error_at_it(tmp_path):
    sm = tank_configs(tmp_path) / "tank.sm"
    edit(sm, "\nbool valveOpen\n", "\nbool valveOpen @alias valveOpen\n")
    line = next(n for n, l in enumerate(sm.read_text().splitlines(), 1) if "@alias valveOpen" in l)
    r = run_fsw("check", str(sm))
    out = r.out + r.err
    assert r.code == 1, out
    assert f"tank.sm:{line}:23:" in out and "is the element's own name" in out, out
