"""`fsw sim --link PATH` never removes what is at PATH: a file, a folder, a
symbolic link of someone else's or one to a pseudo-terminal still open is
refused with a clear message and left as it was; only a stale link a
simulated board left behind (to a pty that is gone) is replaced. The
simulated board's harness itself replaces only a symbolic link, and
removes only its own on leaving."""

from __future__ import annotations

import os
import pty
import subprocess

import pytest
from conftest import run_fsw

from fswkit.sim.board import harness, link_problem


def _refused(tmp_path, path, check):
    r = run_fsw("sim", str(tmp_path / "fw.elf"), "--board", "uno", "--link", str(path))
    assert r.code == 2 and f"--link {path}" in r.err and "Traceback" not in r.err, r.err
    check()


def test_a_file_is_never_removed(tmp_path):
    f = tmp_path / "notes.txt"
    f.write_text("my notes\n")
    _refused(tmp_path, f, lambda: f.read_text() == "my notes\n" or pytest.fail("the file changed"))


def test_a_folder_or_foreign_link_is_refused(tmp_path):
    d = tmp_path / "dir"
    d.mkdir()
    _refused(tmp_path, d, lambda: d.is_dir() or pytest.fail("the folder went"))
    target = tmp_path / "data.csv"
    target.write_text("1,2\n")
    link = tmp_path / "port"
    link.symlink_to(target)
    _refused(tmp_path, link, lambda: os.readlink(link) == str(target) or pytest.fail("the link changed"))


def test_an_empty_link_path_is_refused_not_ignored(tmp_path):
    assert link_problem("") is not None
    r = run_fsw("sim", str(tmp_path / "fw.elf"), "--board", "uno", "--link", "")
    assert r.code == 2 and "--link: an empty string" in r.err, r.err


def test_a_link_to_an_open_pty_is_refused(tmp_path):
    master, slave = pty.openpty()
    try:
        link = tmp_path / "port"
        link.symlink_to(os.ttyname(slave))
        _refused(tmp_path, link, lambda: link.is_symlink() or pytest.fail("the link went"))
    finally:
        os.close(master)
        os.close(slave)


def test_a_stale_board_link_is_accepted(tmp_path):
    link = tmp_path / "port"
    link.symlink_to("/dev/pts/987654")
    assert link_problem(str(link)) is None
    assert link_problem(str(tmp_path / "new")) is None
    assert "no such folder" in link_problem(str(tmp_path / "no" / "port"))


@pytest.fixture(scope="module")
def tiny_elf(tmp_path_factory):
    d = tmp_path_factory.mktemp("elf")
    src = d / "idle.c"
    src.write_text("int main(void) { for (;;) {} }\n")
    elf = d / "idle.elf"
    subprocess.run(["avr-gcc", "-mmcu=atmega328p", "-Os", str(src), "-o", str(elf)], check=True)
    return str(elf)


def _harness(elf, link):
    p = subprocess.run([harness(), "-c", "-m", "atmega328p", "-f", "16000000", "-u", "pty", "-l", str(link), elf],
                       input="", capture_output=True, text=True, timeout=30)
    return p


def test_the_harness_never_removes_a_file(tmp_path, tiny_elf):
    f = tmp_path / "notes.txt"
    f.write_text("my notes\n")
    p = _harness(tiny_elf, f)
    assert f.read_text() == "my notes\n" and not f.is_symlink(), p.stderr
    assert "cannot link" in p.stderr


def test_the_harness_replaces_a_stale_link_and_removes_its_own(tmp_path, tiny_elf):
    link = tmp_path / "port"
    link.symlink_to("/dev/pts/987654")
    p = _harness(tiny_elf, link)
    assert "port=/dev/pts/" in p.stdout, (p.stdout, p.stderr)
    assert not os.path.lexists(link), p.stderr  # its own link, removed on leaving
