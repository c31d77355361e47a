"""A [configs] path was lexed as tokens: `machine ./tank.sm` was refused
with "unexpected character `.`" and the file then read was `/tank.sm` at the
root of the disk, the path rebuilt from the token after the `.`; `../`
(a state vector shared with a sibling project), file names in other
alphabets or with `$` did the same. A path is the text after the kind, as
written, to a comment or the end of the line, relative to the .app."""

from __future__ import annotations

import shutil

import pytest

from conftest import EXAMPLES


@pytest.fixture
def tank(tmp_path):
    project = tmp_path / "rig"
    shutil.copytree(EXAMPLES / "tank", project, ignore=shutil.ignore_patterns("build", "*.ss"))
    return project


def _configs(project, sv: str, sm: str) -> None:
    app = project / "tank.app"
    text = app.read_text().replace("state_vector tank.sv", f"state_vector {sv}")
    app.write_text(text.replace("machine      tank.sm", f"machine      {sm}"))


@pytest.mark.parametrize("sv_at, sv, sm_at, sm", [
    ("tank.sv", "./tank.sv", "tank.sm", "./tank.sm"),
    ("../common/tank.sv", "../common/tank.sv", "sub dir/tank.sm", "sub dir/tank.sm  # the machine"),
    ("общий.sv", "общий.sv", "$rig/tank.sm", "$rig/tank.sm"),
])
def test_relative_paths_spaces_and_other_alphabets_are_read_as_written(fsw, tank, sv_at, sv, sm_at, sm):
    for src, dst in (("tank.sv", sv_at), ("tank.sm", sm_at)):
        if dst != src:
            (tank / dst).parent.mkdir(parents=True, exist_ok=True)
            shutil.move(str(tank / src), str(tank / dst))
    _configs(tank, sv, sm)
    r = fsw("check", str(tank / "tank.app"))
    assert r.code == 0, r.err
    assert "0 errors" in r.out + r.err


def test_a_missing_path_is_reported_as_written_and_nothing_else_is_read(fsw, tank):
    _configs(tank, "tank.sv", "./nowhere/tank.sm")
    r = fsw("check", str(tank / "tank.app"))
    assert r.code == 1
    assert "unexpected character" not in r.err
    assert "nowhere/tank.sm" in r.err and "@ /tank.sm" not in r.err
    assert "cannot read file" in r.err
