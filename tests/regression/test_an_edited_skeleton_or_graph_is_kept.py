"""`fsw skeleton tank.sm -o tank.ss` is made to be edited in place (its
TODOs are the user's to fill), yet running it again replaced the edited
script without a word: the file still began with the skeleton's head line,
and that line was all `-o` looked at. `fsw graph -o` likewise replaced a
diagram the user had styled by hand. Each output's head line now ends with
a digest of the text the command wrote; `-o` replaces the file without
`--force` only while its text still has that digest (nobody edited it)."""

from __future__ import annotations

import shutil

import pytest
from conftest import EXAMPLES, run_fsw


@pytest.fixture
def tank(tmp_path):
    for name in ("tank.sm", "tank.sv"):
        shutil.copy(EXAMPLES / "tank" / name, tmp_path / name)
    return tmp_path


def _edit(text: str) -> str:
    """What a user does to the output: a line changed below the head."""
    lines = text.split("\n")
    lines[-2] += "  # checked by hand"
    return "\n".join(lines)


OUTPUTS = [("skeleton", ()), ("graph", ()), ("graph", ("--format", "mermaid"))]


@pytest.mark.parametrize("command,args", OUTPUTS)
def test_an_edited_output_is_not_replaced_unasked(tank, command, args):
    out = tank / "out.txt"
    assert run_fsw(command, str(tank / "tank.sm"), *args, "-o", str(out)).code == 0
    mine = _edit(out.read_text())
    out.write_text(mine)
    r = run_fsw(command, str(tank / "tank.sm"), *args, "-o", str(out))
    assert r.code == 1, r.err
    assert f"{out} was edited since `fsw {command}` wrote it" in r.err and "--force" in r.err, r.err
    assert "Traceback" not in r.err
    assert out.read_text() == mine
    r = run_fsw(command, str(tank / "tank.sm"), *args, "-o", str(out), "--force")
    assert r.code == 0, r.err
    assert out.read_text() != mine
    # and once written again, unedited, it is the command's to replace
    assert run_fsw(command, str(tank / "tank.sm"), *args, "-o", str(out)).code == 0


@pytest.mark.parametrize("command,args", OUTPUTS)
def test_the_digest_is_of_the_whole_text(tank, command, args):
    """A change anywhere (the head line's own words, a blank line added at
    the end) makes the file the user's; the output on standard output is
    the same text, digest and all."""
    out = tank / "out.txt"
    assert run_fsw(command, str(tank / "tank.sm"), *args, "-o", str(out)).code == 0
    first = out.read_text()
    r = run_fsw(command, str(tank / "tank.sm"), *args)
    assert r.code == 0 and r.out == first
    assert "(digest " in first.split("\n", 3)[0] + first.split("\n", 3)[1]
    for edited in (first + "\n", first.replace("state machine", "State machine", 1).replace(
            "State-script skeleton", "state-script skeleton", 1)):
        assert edited != first
        out.write_text(edited)
        assert run_fsw(command, str(tank / "tank.sm"), *args, "-o", str(out)).code == 1
        assert out.read_text() == edited


def test_an_output_with_no_digest_is_kept(tank):
    """A skeleton from a kit that wrote no digest, or one the user pasted the
    head line into: nothing says it is unedited, so it is kept."""
    out = tank / "tank.ss"
    assert run_fsw("skeleton", str(tank / "tank.sm"), "-o", str(out)).code == 0
    head, rest = out.read_text().split("\n", 1)
    old = head[:head.rindex(" (digest ")] + "\n" + rest
    out.write_text(old)
    r = run_fsw("skeleton", str(tank / "tank.sm"), "-o", str(out))
    assert r.code == 1 and "--force" in r.err, r.err
    assert out.read_text() == old
