"""A project with a `[budget]` was refused for the native host build: the
native board's memory sizes are 0 ("not limited"), and the budget check
read them as a limit of 0 B, so `fsw build examples/rocket --board native`
failed although the same project builds for its Uno. A board whose memory
is not limited holds no budget to a limit."""

from __future__ import annotations

import shutil

from conftest import EXAMPLES
from fswkit.autocode.app import load_app
from fswkit.autocode.diagnostics import Diagnostics


def test_a_budgeted_project_loads_for_the_native_board():
    diags = Diagnostics()
    app = load_app(str(EXAMPLES / "rocket" / "rocket.app"), diags, board_override="native")
    assert diags.error_count == 0, diags
    assert app is not None and app.board.name == "native"
    assert (app.flash_budget, app.ram_budget) == (25600, 1920)


def test_a_budget_over_an_avr_board_is_still_refused(tmp_path):
    project = tmp_path / "rocket"
    shutil.copytree(EXAMPLES / "rocket", project, ignore=shutil.ignore_patterns("build"))
    app_file = project / "rocket.app"
    text = app_file.read_text()
    app_file.write_text(text.replace("flash 25600", "flash 40000"))
    line = next(i for i, row in enumerate(text.splitlines(), 1) if row.startswith("flash 25600"))
    diags = Diagnostics()
    assert load_app(str(app_file), diags) is None
    assert [(d.line, d.message) for d in diags.errors] == [
        (line, "a flash budget of 40,000 B is more than the uno has (32,256 B)")]
