"""A `[log]` without its `store` line, on a board whose definition has no
EEPROM (a board a team added, docs/boards.md), was `fsw: internal error:
KeyError: 'store'` out of `fsw check`: the checker took the missing line's
default, `eeprom`, and went to point at the line to say the board has
none. The missing `store` is now said where the section starts, alone,
with status 1; `store eeprom` on such a board is said at the word."""

from __future__ import annotations

import shutil

import fswkit.autocode.board as board_mod
from conftest import ROOT, run_fsw

RIG = ROOT / "tests" / "recorder" / "logged"


def _project(tmp_path, monkeypatch, log: str):
    boards = tmp_path / "boards"
    boards.mkdir()
    uno = (ROOT / "boards" / "uno.toml").read_text()
    assert "\neeprom = 1024\n" in uno
    (boards / "noeeprom.toml").write_text(uno.replace("\neeprom = 1024\n", "\neeprom = 0\n")
                                          .replace('name = "uno"', 'name = "noeeprom"'))
    monkeypatch.setattr(board_mod, "BOARDS_DIR", str(boards))
    proj = tmp_path / "p"
    shutil.copytree(RIG, proj)
    app = (proj / "logged.app").read_text().replace("board uno", "board noeeprom")
    (proj / "logged.app").write_text(app[:app.index("[log]")] + log)
    return proj / "logged.app"


def test_a_missing_store_is_said_not_a_traceback(tmp_path, monkeypatch):
    app = _project(tmp_path, monkeypatch, "[log]\nmachine logged\ntrigger Run\nrate 50\nelement level\n")
    r = run_fsw("check", str(app))
    assert r.code == 1 and "internal error" not in r.err, r.out + r.err
    assert "logged.app:26:1" in r.out + r.err and "[log] needs `store`" in r.out + r.err


def test_store_eeprom_on_it_is_said_at_the_word(tmp_path, monkeypatch):
    app = _project(tmp_path, monkeypatch, "[log]\nstore eeprom\nmachine logged\ntrigger Run\nrate 50\nelement level\n")
    r = run_fsw("check", str(app))
    assert r.code == 1 and "logged.app:26:7" in r.out + r.err and "has no EEPROM" in r.out + r.err, r.out + r.err
