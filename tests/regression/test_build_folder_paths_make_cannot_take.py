"""A project in a folder whose path holds a space (`~/My Rocket/`) failed
to build with Make's own words (`/tmp/a: Is a directory`), reported as an
internal error; an application file named with one did the same. Make
splits file names on spaces and gives `:`, `$`, `%` and `#` meanings of
its own: the build runs in its folder with names relative to it, and the
firmware's file name keeps only the characters Make takes."""

from __future__ import annotations

import shutil

import pytest

from conftest import EXAMPLES


@pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")
def test_a_project_in_a_folder_named_with_spaces_and_make_syntax_builds(fsw, tmp_path):
    project = tmp_path / "My Rocket: 50% #2 $HOME"
    shutil.copytree(EXAMPLES / "tank", project, ignore=shutil.ignore_patterns("build"))
    (project / "tank.app").rename(project / "tank rig $(x).app")
    out = project / "build" / "uno"
    r = fsw("build", str(project))
    assert r.code == 0, r.err
    elf, hexfile = out / "tank_rig___x_.elf", out / "tank_rig___x_.hex"
    assert f"  {elf}\n  {hexfile}\n" in r.out
    assert hexfile.read_text().startswith(":")
