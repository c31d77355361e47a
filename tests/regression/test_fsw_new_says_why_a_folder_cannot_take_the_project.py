"""`fsw new` given a folder it cannot write the project into said words that
did not say why: `fsw new ""` and `fsw new .` (run in the empty folder a
newcomer just made and entered) both said `` `.` cannot name a project:
use letters, digits and `_` ``, and a symbolic link (to an empty folder, or
to nothing) `cannot write LINK: Not a directory`. Now the empty string is
refused as every option's is (`an empty string names nothing`), `.` and
`..` say that a project goes into a new folder named after it and how to
make it from the folder above, and a link says it is one; status 2 for a
name, 1 for a folder, nothing written, the link kept."""

from __future__ import annotations

import os

from conftest import run_fsw


def test_an_empty_name_names_nothing(tmp_path):
    r = run_fsw("new", "", cwd=tmp_path)
    assert r.code == 2, r.err
    assert "an empty string names nothing" in r.err and "`.`" not in r.err
    assert os.listdir(tmp_path) == []


def test_the_current_folder_says_how_to_make_the_project(tmp_path):
    rig = tmp_path / "rig"
    rig.mkdir()
    for name in (".", "./", ".."):
        r = run_fsw("new", name, cwd=rig)
        assert r.code == 2, r.err
        assert "cannot name a project: use letters" not in r.err, r.err
        assert "a new folder" in r.err, r.err
    r = run_fsw("new", ".", cwd=rig)
    assert "cd .. && fsw new rig" in r.err, r.err
    assert os.listdir(rig) == []


def test_a_symbolic_link_is_said_to_be_one(tmp_path):
    (tmp_path / "empty").mkdir()
    os.symlink("empty", tmp_path / "rig")
    os.symlink("nowhere", tmp_path / "gone")
    for name in ("rig", "gone"):
        r = run_fsw("new", name, cwd=tmp_path)
        assert r.code == 1, r.err
        assert f"{name} is a symbolic link" in r.err and "Not a directory" not in r.err, r.err
        assert os.path.islink(tmp_path / name)
    assert os.listdir(tmp_path / "empty") == []
    assert sorted(os.listdir(tmp_path)) == ["empty", "gone", "rig"]
