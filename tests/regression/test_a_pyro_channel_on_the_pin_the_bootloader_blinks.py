"""The Arduino bootloaders flash the L LED on pin 13 at every reset, before
the firmware runs (Optiboot on the Uno, the Nano's and the Mega 2560's
bootloaders too): examples/hpr with its drogue moved to pin 13 (and the
LED off it) passed `fsw check`, and every reset, a brown-out in flight
included, would have driven the drogue's firing transistor high with no
gate to stop it: the proof and the gate begin with the firmware. The
check now refuses a pyro channel on a pin the board file lists in
`pins.boot_driven`, at the channel's row."""

from __future__ import annotations

import shutil

import pytest

from conftest import EXAMPLES
from fswkit.autocode.board import load_board


def hpr(tmp_path, board: str):
    shutil.copytree(EXAMPLES / "hpr", tmp_path / "hpr")
    dio = tmp_path / "hpr" / "hpr.dio"
    text = dio.read_text()
    for old, new in (("o      5    drogue", "o      13   drogue"), ("o      13   led", "o      7    led")):
        assert old in text
        text = text.replace(old, new)
    dio.write_text(text)
    app = tmp_path / "hpr" / "hpr.app"
    app.write_text(app.read_text().replace("board uno", f"board {board}"))
    return app


@pytest.mark.parametrize("board", ["uno", "nano", "mega2560"])
def test_a_pyro_channel_on_pin_13_is_refused(fsw, tmp_path, board):
    r = fsw("check", str(hpr(tmp_path, board)))
    assert r.code == 1, r.out
    assert "hpr.app:58:1:" in r.err
    assert (f"pyro channel `drogue` is on pin 13 (hpr.dio:4), which the {board}'s bootloader drives high at every "
            "reset, before the firmware and its gate run") in r.err
    assert "Traceback" not in r.err


def test_the_led_on_pin_13_is_still_fine(fsw):
    r = fsw("check", str(EXAMPLES / "hpr" / "hpr.app"))  # its LED is on 13
    assert r.code == 0, r.err


def test_the_boards_say_which_pins_their_bootloader_drives():
    for name in ("uno", "nano", "mega2560"):
        assert set(load_board(name).boot_driven) == {13}
    assert load_board("native").boot_driven == {}
