"""`fsw plot -e x x` drew x in two panels and counted its points twice; an
element named many times made a figure as tall as matplotlib refuses,
after minutes of drawing. Each element is one panel, however often named."""

from __future__ import annotations

from conftest import run_fsw
from support.linkstream import write_log


def test_an_element_named_twice_is_one_panel(tmp_path):
    log = write_log(tmp_path / "x.log", 100)
    once = run_fsw("plot", str(log), "-e", "tankPressure", "-o", str(tmp_path / "a.png"))
    assert once.code == 0, once.err
    many = run_fsw("plot", str(log), "-e", *["tankPressure"] * 400, "-o", str(tmp_path / "b.png"))
    assert many.code == 0, many.err
    said = once.err.split("a.png: ", 1)[1]
    assert said.startswith("96 points, ") and many.err.split("b.png: ", 1)[1] == said, (once.err, many.err)
