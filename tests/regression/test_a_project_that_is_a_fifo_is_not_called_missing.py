"""`fsw build ff.app` with ff.app a FIFO, or `fsw build /dev/null`, said
`no such file or folder` of a file that is there: every command that takes
a PROJECT (build, flash, gen, sim...) now says what it is and that it is
not read."""

from __future__ import annotations

import os

import pytest

from conftest import run_fsw


@pytest.mark.parametrize("command", ["build", "gen"])
def test_a_fifo_named_as_the_project_is_said_to_be_one(tmp_path, command):
    fifo = tmp_path / "tank.app"
    os.mkfifo(fifo)
    r = run_fsw(command, str(fifo))
    assert r.code == 2, r.err
    assert r.err == f"fsw {command}: {fifo}: not a regular file (a FIFO): name the project's folder or its .app file\n"


def test_a_device_named_as_the_project_is_said_to_be_one():
    r = run_fsw("build", "/dev/null")
    assert r.code == 2
    assert r.err == "fsw build: /dev/null: not a regular file (a device): name the project's folder or its .app file\n"


def test_a_missing_project_is_still_missing(tmp_path):
    r = run_fsw("build", str(tmp_path / "none"))
    assert r.code == 2 and r.err == f"fsw build: {tmp_path / 'none'}: no such file or folder\n"
