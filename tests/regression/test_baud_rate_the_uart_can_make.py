"""`baud 9600.5` passed and silently became 115200; `baud 5000000`
underflowed the UART's divisor (about 488 baud on silicon). A rate is
accepted only when it is a whole number the board's UART makes within
±2.5 %, computed from the board's clock, double-speed mode and the divisor
the runtime programs (UBRR = (F_CPU / 4 / baud - 1) / 2, 12 bits)."""

from __future__ import annotations

import pytest

SV = """\
[Flight]
U64 time
U32 state
"""

SM = """\
[state_vector]
U64 time @alias G
U32 state @alias S

[Idle]
"""

APP = """\
[application]
board {board}
baud {baud}

[configs]
state_vector rig.sv
machine rig.sm

[tasks]
control  machine rig
down     telemetry

[telemetry]
Flight rate=10
"""


def check(fsw, tmp_path, baud: str, board: str = "uno"):
    for name, text in (("rig.sv", SV), ("rig.sm", SM), ("rig.app", APP.format(baud=baud, board=board))):
        (tmp_path / name).write_text(text)
    return fsw("check", str(tmp_path / "rig.app")), tmp_path / "rig.app"


def uart_rate(f_cpu: int, baud: int) -> float:
    """What the runtime's console_begin programs, as the silicon makes it."""
    ubrr = (f_cpu // 4 // baud - 1) // 2
    return f_cpu / (8 * (ubrr + 1))


@pytest.mark.parametrize("baud", [9600, 19200, 38400, 57600, 115200, 250000, 500000, 1000000, 2000000])
def test_rates_the_uart_makes_are_accepted(fsw, tmp_path, baud):
    assert abs(uart_rate(16_000_000, baud) / baud - 1) <= 0.025
    r, _ = check(fsw, tmp_path, str(baud))
    assert r.code == 0, r.err


@pytest.mark.parametrize("baud, message", [
    ("9600.5", "`baud` must be a whole number of bits per second, found `9600.5` "
               "(for 9600 the uno's UART makes 9,615 baud, +0.16 %)"),
    ("5000000", "`baud 5000000` is faster than the uno's UART can run (16 MHz, double speed): "
                "the fastest it makes is 2,000,000 baud, -60.00 %"),
    ("300", "`baud 300` is slower than the uno's UART can run (16 MHz, double speed, a 12-bit divisor): "
            "the slowest it makes is 488 baud, +62.76 %"),
    ("230400", "`baud 230400`: the uno's UART makes 222,222 baud (16 MHz, double speed, UBRR 8), -3.55 %, "
               "more than the ±2.5 % a serial link allows"),
    ("460800", "`baud 460800`: the uno's UART makes 500,000 baud (16 MHz, double speed, UBRR 3), +8.51 %, "
              "more than the ±2.5 % a serial link allows"),
])
def test_rates_the_uart_cannot_make_are_refused(fsw, tmp_path, baud, message):
    r, p = check(fsw, tmp_path, baud)
    assert r.code != 0
    assert f"application config error @ {p}:3:6:" in r.err, r.err
    assert message in r.err, r.err
    assert "Traceback" not in r.err


def test_the_error_is_the_boards_own(fsw, tmp_path):
    # the host build has no UART to divide a clock for: any whole rate
    r, _ = check(fsw, tmp_path, "230400", board="native")
    assert r.code == 0, r.err
    r, _ = check(fsw, tmp_path, "230400.5", board="native")
    assert r.code != 0 and "`baud` must be a whole number of bits per second" in r.err, r.err


def test_the_default_rate_is_checked_too(fsw, tmp_path, monkeypatch):
    # a board clocked at 8 MHz makes 111,111 baud of the default 115200
    import dataclasses

    from fswkit.autocode import app as A

    real = A.load_board
    monkeypatch.setattr(A, "load_board", lambda name: dataclasses.replace(real(name), f_cpu=8_000_000))
    r, p = check(fsw, tmp_path, "57600")
    assert r.code == 0, r.err
    (p).write_text(p.read_text().replace("baud 57600\n", ""))
    r = fsw("check", str(p))
    assert r.code != 0
    assert f"application config error @ {p}:2:7:" in r.err, r.err
    assert ("`baud 115200`: the uno's UART makes 111,111 baud (8 MHz, double speed, UBRR 8), -3.55 %, more than "
            "the ±2.5 % a serial link allows; `baud` is not set, so it is the default") in r.err, r.err
