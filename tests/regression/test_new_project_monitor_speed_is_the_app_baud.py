"""The platformio.ini `fsw new` writes sets `monitor_speed` to the baud of
the application it writes beside it (`pio device monitor` then reads the
board at the link's rate), not a fixed 115200 that stays behind when the
scaffold's baud changes."""

from __future__ import annotations

import configparser

import pytest

from fswkit.autocode.app import load_app
from fswkit.autocode.diagnostics import Diagnostics


def _written(fsw, folder, board):
    assert fsw("new", str(folder), "--board", board).code == 0
    diags = Diagnostics()
    app = load_app(str(folder / f"{folder.name}.app"), diags)
    assert app is not None, diags.render()
    ini = configparser.ConfigParser(interpolation=None, inline_comment_prefixes=(";",))
    ini.read(folder / "platformio.ini")
    return app, ini


@pytest.mark.parametrize("board", ["uno", "mega2560", "native"])
def test_monitor_speed_is_the_applications_baud(fsw, tmp_path, board):
    app, ini = _written(fsw, tmp_path / "rocket", board)
    assert ini["env"]["monitor_speed"] == str(app.baud)


def test_monitor_speed_follows_the_scaffolds_baud(fsw, tmp_path, monkeypatch):
    import fswkit.new.project as project

    monkeypatch.setattr(project, "BAUD", 57600)
    app, ini = _written(fsw, tmp_path / "rocket", "uno")
    assert app.baud == 57600
    assert ini["env"]["monitor_speed"] == "57600"
