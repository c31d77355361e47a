"""`fsw new café` was told `use letters, digits and `_`, starting with a
letter`: é is a letter, and `_rig`, which does not start with a letter, is
accepted. `fsw gen --sketch café` likewise said `use letters, digits, `_`,
`-` and `.``. Both now say ASCII letters, and `fsw new` that a name may
start with `_`; every name the message allows is accepted."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES, run_fsw


@pytest.mark.parametrize("name", ["café", "my rig", "9lives", "Ωmega"])
def test_the_message_says_ascii_letters(tmp_path, name):
    r = run_fsw("new", str(tmp_path / name))
    assert r.code == 2, r.err
    assert "ASCII letters (A-Z, a-z), digits and `_`, not starting with a digit" in r.err, r.err


def test_a_name_starting_with_an_underscore_is_taken(tmp_path):
    r = run_fsw("new", str(tmp_path / "_rig"))
    assert r.code == 0, r.err
    assert (tmp_path / "_rig" / "_rig.app").is_file()


def test_the_sketch_message_says_ascii_letters(tmp_path):
    r = run_fsw("gen", str(EXAMPLES / "tank"), "--sketch", str(tmp_path / "café"))
    assert r.code == 2, r.err
    assert "ASCII letters (A-Z, a-z), digits, `_`, `-` and `.`" in r.err, r.err
    assert not (tmp_path / "café").exists()
