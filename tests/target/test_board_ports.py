"""The board files' pin -> port map (`arduino.ports`), which generated code
uses to drive digital channels through their port registers, against the
Arduino variant the firmware is built with: a wrong entry would drive
another pin than the channel names, silently."""

from __future__ import annotations

import os
import shutil

import pytest

from fswkit.autocode.board import board_from_dict, board_names, load_board

ARDUINO = "/usr/share/arduino/hardware/arduino/avr"
AVR_BOARDS = [n for n in board_names() if load_board(n).is_avr]


@pytest.mark.skipif(shutil.which("avr-gcc") is None or not os.path.isdir(ARDUINO),
                    reason="gcc-avr or the Arduino core is not installed")
@pytest.mark.parametrize("name", AVR_BOARDS)
def test_ports_match_the_variants_pin_table(name):
    from fswkit.sim.board import pin_map

    board = load_board(name)
    assert board.ports == pin_map(board).digital


@pytest.mark.parametrize("name", AVR_BOARDS)
def test_every_digital_pin_has_a_port(name):
    board = load_board(name)
    assert set(board.digital_pins) <= set(board.ports)


def test_a_malformed_port_is_refused():
    d = load_board("uno").raw
    bad = {**d, "arduino": {**d["arduino"], "ports": ["D0", "D9"]}}
    with pytest.raises(ValueError, match=r"arduino.ports\[1\] = 'D9'"):
        board_from_dict("uno", bad)
