"""`[reload] ram 4096` on an Uno (2,048 B of RAM): `fsw check` accepted it,
and `fsw build` then failed with 4,488 B of "other generated code and
data": the image's RAM and its slot-sized copy are static buffers, and
nothing named them. The checker now refuses a slot and an image RAM that
alone pass the board's RAM, at the setting (size + ram = the RAM is the
boundary); a build that does not fit names them by their [reload] line."""

from __future__ import annotations

import re
import shutil

import pytest

from conftest import EXAMPLES

needs_avr = pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")


def _stand(tmp_path, ram: int):
    folder = tmp_path / "stand"
    shutil.copytree(EXAMPLES / "stand", folder, ignore=shutil.ignore_patterns("build"))
    app = folder / "stand.app"
    text = app.read_text().replace("../tank/", f"{EXAMPLES}/tank/")
    app.write_text(re.sub(r"(?m)^ram +64\b", f"ram      {ram}", text))
    line = next(i for i, row in enumerate(app.read_text().splitlines(), 1) if row.startswith("ram "))
    return app, line


def test_a_slot_and_an_image_ram_past_the_boards_ram_are_refused_at_the_setting(fsw, tmp_path):
    app, line = _stand(tmp_path, 4096)
    r = fsw("check", str(app))
    assert r.code == 1
    assert f"stand.app:{line}:10:" in r.err, r.err
    assert ("the image's copy (size 384 B) and its windows and locals (ram 4,096 B) take 4,480 B: more than "
            "the uno's RAM (2,048 B); lower `ram` or `size`") in r.err


@pytest.mark.parametrize("ram, ok", [(2048 - 384, True), (2048 - 384 + 1, False)])
def test_the_boundary(fsw, tmp_path, ram, ok):
    app, _ = _stand(tmp_path, ram)
    r = fsw("check", str(app))
    assert (r.code == 0) is ok, r.err


@needs_avr
def test_a_build_that_does_not_fit_names_the_reload_buffers(fsw, tmp_path):
    app, _ = _stand(tmp_path, 1500)  # accepted (1,884 B with the slot), but not with the rest
    r = fsw("build", str(app.parent))
    assert r.code == 1, r.err
    m = re.search(r"^\s+([\d,]+) B  the machine replaced at run time: its image, windows and locals, and store, "
                  r"stand\.app:\d+ \[reload\]$", r.err, re.M)
    assert m, r.err
    assert int(m.group(1).replace(",", "")) >= 1500 + 384
    assert "other generated code and data" not in r.err.split("what uses RAM", 1)[1].split("\n\n", 1)[0]
