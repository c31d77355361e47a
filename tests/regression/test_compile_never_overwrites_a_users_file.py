"""`fsw compile -o FILE` and `--layout FILE` replaced whatever FILE was: a
slip of the keyboard (`-o tank_700.sm`, `--layout stand.app`, a notes file)
put a binary image or a layout over a config the user wrote, and said
"196 bytes" as if all was well. An image replaces an image and a layout a
layout (compiling again into the same files is the usual loop); any other
file the user has is replaced only with `--force`, and a refusal writes
neither file."""

from __future__ import annotations

import shutil

import pytest

from conftest import EXAMPLES

TANK = EXAMPLES / "tank"


@pytest.fixture
def folder(tmp_path):
    for name in ("tank.sm", "tank.sv"):
        shutil.copy(TANK / name, tmp_path / name)
    shutil.copy(EXAMPLES / "stand" / "tank_700.sm", tmp_path / "tank_700.sm")
    (tmp_path / "notes.txt").write_text("valve opens at 775\n")
    return tmp_path


@pytest.mark.parametrize("victim", ["tank_700.sm", "notes.txt"])
def test_an_image_never_replaces_a_file_that_is_not_one(folder, fsw, victim):
    before = (folder / victim).read_bytes()
    r = fsw("compile", str(folder / "tank.sm"), "-o", str(folder / victim))
    assert r.code == 1, r.err
    assert f"{folder / victim}: the file exists and is not a bytecode image" in r.err and "--force" in r.err
    assert (folder / victim).read_bytes() == before
    r = fsw("compile", str(folder / "tank.sm"), "-o", str(folder / victim), "--force")
    assert r.code == 0, r.err
    assert (folder / victim).read_bytes()[:4] == b"FSMB"


def test_a_layout_never_replaces_a_file_that_is_not_one_and_then_no_image_is_written(folder, fsw):
    before = (folder / "tank_700.sm").read_bytes()
    r = fsw("compile", str(folder / "tank.sm"), "-o", str(folder / "t.fsm"), "--layout", str(folder / "tank_700.sm"))
    assert r.code == 1, r.err
    assert f"{folder / 'tank_700.sm'}: the file exists and is not a layout" in r.err
    assert (folder / "tank_700.sm").read_bytes() == before and not (folder / "t.fsm").exists()


def test_an_image_and_a_layout_replace_their_own_kind(folder, fsw):
    """The edit-compile loop: the same two paths again, after the machine
    changed; an empty file holds nothing to lose."""
    (folder / "empty.fsm").write_bytes(b"")
    for _ in range(2):
        r = fsw("compile", str(folder / "tank.sm"), "-o", str(folder / "t.fsm"), "--layout", str(folder / "t.layout"))
        assert r.code == 0, r.err
        r = fsw("compile", str(folder / "tank.sm"), "-o", str(folder / "empty.fsm"))
        assert r.code == 0, r.err
    assert (folder / "t.fsm").read_bytes() == (folder / "empty.fsm").read_bytes()
    assert "fswsm-layout 1" in (folder / "t.layout").read_text()


def test_a_symbolic_link_to_a_users_file_is_refused_too(folder, fsw):
    (folder / "out.fsm").symlink_to(folder / "notes.txt")
    r = fsw("compile", str(folder / "tank.sm"), "-o", str(folder / "out.fsm"))
    assert r.code == 1 and "is not a bytecode image" in r.err, r.err
    assert (folder / "notes.txt").read_text() == "valve opens at 775\n"
