"""`fsw new`'s starter .aio listed the board's PWM pins as the pins for
analog outputs, the executor's timer pins among them: "PWM pins (analog
outputs): 3 5-6 9-11" on an Uno and "2-13 44-46" on a Mega 2560, though
`fsw check` refuses an analog output on 9 and 10 (Uno) or 11 and 12
(Mega): their timer paces the executor. Now the comment lists the pins an
`o` row may have, each accepted by `fsw check`, and names the timer's."""

from __future__ import annotations

import re

import pytest

from conftest import run_fsw

from fswkit.autocode.board import load_board


def listed(aio: str) -> set[int]:
    m = re.search(r"PWM pins \(analog outputs\): ([0-9 -]+)", aio)
    assert m, aio
    out = set()
    for part in m.group(1).split():
        lo, _, hi = part.partition("-")
        out |= set(range(int(lo), int(hi or lo) + 1))
    return out


@pytest.mark.parametrize("board", ["uno", "nano", "mega2560", "native"])
def test_the_listed_pwm_pins_are_those_an_analog_output_may_have(tmp_path, board):
    r = run_fsw("new", "demo", "--board", board, cwd=tmp_path)
    assert r.code == 0, r.err
    aio = (tmp_path / "demo" / "demo.aio").read_text()
    b = load_board(board)
    assert listed(aio) == set(b.pwm_pins - b.timer_pins), aio
    assert f"not {' or '.join(str(p) for p in sorted(b.timer_pins))}: their timer ({b.timer})" in aio, aio


def test_a_listed_pin_is_accepted_and_a_timer_pin_refused(tmp_path):
    assert run_fsw("new", "demo", "--board", "mega2560", cwd=tmp_path).code == 0
    project = tmp_path / "demo"
    sv = (project / "demo.sv").read_text()
    (project / "demo.sv").write_text(sv + "[Out]\nF32 drive\n")
    aio = (project / "demo.aio").read_text()
    pin = max(listed(aio))
    (project / "demo.aio").write_text(aio + f"o {pin} drive\n")
    assert run_fsw("check", "demo.app", cwd=project).code == 0
    (project / "demo.aio").write_text(aio + "o 11 drive\n")
    r = run_fsw("check", "demo.app", cwd=project)
    assert r.code == 1 and "paces the executor" in r.err, r.err
