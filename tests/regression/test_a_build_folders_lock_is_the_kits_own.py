"""A build folder is the kit's when it holds the `.lock` a build left
there, and a build took any `.lock` for one: a folder of the user's with
another tool's `.lock` in it got the build's objects and its `build.log`
replaced the user's; and a `.lock` that is a symbolic link was followed
and truncated, emptying the file it named (in a `--out` folder, or in the
project's own build folder). Now only a regular file holding nothing or a
process id marks a build folder, and the lock is never taken through a
link: the build is refused, saying why, and the file is left as it was.
A build folder whose `.lock` the user removed is refused as any folder of
files is (nothing there is known to be the kit's), and now says how to
make it a build folder again."""

from __future__ import annotations

import os
import shutil

import pytest
from conftest import EXAMPLES, run_fsw

TANK = EXAMPLES / "tank"


def test_another_tools_lock_does_not_make_a_build_folder(tmp_path):
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / ".lock").write_text("held by my sync tool\n")
    (mine / "build.log").write_text("my notes\n")
    r = run_fsw("build", str(TANK), "--out", str(mine))
    assert r.code != 0 and f"{mine} holds files a build of fswkit did not write (.lock, build.log)" in r.err, r.err
    assert (mine / "build.log").read_text() == "my notes\n"
    assert sorted(p.name for p in mine.iterdir()) == [".lock", "build.log"]


def test_a_lock_that_links_elsewhere_is_never_followed(tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    out = tmp_path / "out"
    out.mkdir()
    os.symlink(victim, out / ".lock")
    r = run_fsw("build", str(TANK), "--out", str(out))
    assert r.code != 0 and "Traceback" not in r.err, r.err
    assert victim.read_text() == "precious\n"


def test_the_projects_own_build_folder_with_a_linked_lock(tmp_path):
    project = tmp_path / "tank"
    shutil.copytree(TANK, project, ignore=shutil.ignore_patterns("build"))
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    (project / "build" / "uno").mkdir(parents=True)
    os.symlink(victim, project / "build" / "uno" / ".lock")
    r = run_fsw("build", str(project))
    assert r.code != 0, r.err
    assert (f"cannot lock the build folder {project / 'build' / 'uno'}: {project / 'build' / 'uno' / '.lock'} is a "
            "symbolic link (move it away)") in r.err, r.err
    assert "Traceback" not in r.err
    assert victim.read_text() == "precious\n"


@pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")
def test_a_kit_lock_still_marks_the_kits_folder(tmp_path):
    out = tmp_path / "out"
    assert run_fsw("build", str(TANK), "--out", str(out)).code == 0
    assert (out / ".lock").read_text().strip().isdigit()
    r = run_fsw("build", str(TANK), "--out", str(out))
    assert r.code == 0, r.err


@pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")
def test_a_build_folder_whose_lock_was_removed(tmp_path):
    out = tmp_path / "out"
    assert run_fsw("build", str(TANK), "--out", str(out)).code == 0
    (out / ".lock").unlink()
    r = run_fsw("build", str(TANK), "--out", str(out))
    assert r.code != 0 and "Traceback" not in r.err, r.err
    assert (f"its build.log is a build's, but its .lock is gone: if you know the folder holds nothing of yours, "
            f"`touch {out / '.lock'}` makes it a build folder again") in r.err, r.err
    (out / ".lock").touch()
    assert run_fsw("build", str(TANK), "--out", str(out)).code == 0
