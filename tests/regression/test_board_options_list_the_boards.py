"""`--board` took a board's name, and no help said which names there are:
`fsw new --help` said "the board it runs on (default uno)", and a newcomer
learnt the others only from the error of a wrong one. Every command's
`--board` help now lists the kit's boards (boards/*.toml)."""

from __future__ import annotations

import pytest

from conftest import ROOT, run_fsw

BOARDS = sorted(p.stem for p in (ROOT / "boards").glob("*.toml"))


@pytest.mark.parametrize("command", ["new", "build", "gen", "sim", "flash", "test", "compile"])
def test_the_board_option_lists_every_board(command):
    assert len(BOARDS) >= 3
    r = run_fsw(command, "--help")
    assert r.code == 0, r.err
    said = " ".join(r.out.split())  # argparse wraps the help
    assert "boards: " + ", ".join(BOARDS) in said, said
