"""Where no $XDG_RUNTIME_DIR is set, the holder records of serial ports and
the ground station's socket live in `/tmp/fswkit-UID`, and the kit took
that folder as it found it: another user of the machine who made it first
(world-writable, or theirs) could plant a record naming their own socket,
and `fsw cmd`, `fsw param` and `fsw monitor` would then send the commands
to them. The folder (and FSW_RUNTIME_DIR's) is now used only when it is a
folder of this user's, not a link, that no one else can write; otherwise
the command says so and exits non-zero."""

from __future__ import annotations

import os

import pytest
from conftest import EXAMPLES, run_fsw

TANK = EXAMPLES / "tank"
WORDS = "not a folder of this user's that only this user can write"


def _monitor():
    return run_fsw("monitor", str(TANK), "--port", "/dev/null", "--headless", "--duration", "1")


def test_a_folder_others_can_write_is_refused(tmp_path, monkeypatch):
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o777)
    monkeypatch.setenv("FSW_RUNTIME_DIR", str(shared))
    r = _monitor()
    assert r.code != 0
    assert f"{shared}: {WORDS}" in r.err, r.err
    assert "Traceback" not in r.err
    assert list(shared.iterdir()) == []  # no record written there


def test_a_link_is_refused(tmp_path, monkeypatch):
    private = tmp_path / "private"
    private.mkdir(mode=0o700)
    link = tmp_path / "link"
    link.symlink_to(private)
    monkeypatch.setenv("FSW_RUNTIME_DIR", str(link))
    r = _monitor()
    assert r.code != 0 and f"{link}: {WORDS}" in r.err, r.err


@pytest.mark.skipif(os.geteuid() != 0, reason="giving a folder to another user takes root")
def test_another_users_folder_is_refused(tmp_path, monkeypatch):
    theirs = tmp_path / "theirs"
    theirs.mkdir(mode=0o700)
    os.chown(theirs, 65534, 65534)
    monkeypatch.setenv("FSW_RUNTIME_DIR", str(theirs))
    r = _monitor()
    assert r.code != 0 and f"{theirs}: {WORDS}" in r.err, r.err


def test_a_private_folder_is_used(tmp_path, monkeypatch):
    private = tmp_path / "private"
    monkeypatch.setenv("FSW_RUNTIME_DIR", str(private))
    r = _monitor()
    assert WORDS not in r.err
    assert "/dev/null" in r.err  # it went on to the port (which is no serial port)
    assert private.is_dir() and (private.stat().st_mode & 0o777) == 0o700
