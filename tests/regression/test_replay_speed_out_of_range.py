"""`fsw replay --speed` takes 0 (as fast as possible) or a speed whose
waits stay representable: a speed so small the waits overflow, a negative,
infinite or NaN speed is refused with a clear message before the log is
read, never a traceback mid-replay."""

from __future__ import annotations

import pytest
from conftest import run_fsw
from support.linkstream import TANK, write_log


@pytest.fixture(scope="module")
def log(tmp_path_factory):
    # 1 µs apart: 0.06 s at the slowest speed
    return str(write_log(tmp_path_factory.mktemp("replay") / "flight.log", 60, step_ns=1_000))


@pytest.mark.parametrize("speed", ["1e-300", "0.0009", "-1", "inf", "nan", "1e7", "fast"])
def test_refused(log, speed):
    r = run_fsw("replay", log, "--headless", "--speed", speed)
    assert r.code == 2 and "--speed" in r.err and "Traceback" not in r.err, r.err


@pytest.mark.parametrize("speed", ["0", "0.001", "1000", "1000000"])
def test_accepted(log, speed):
    r = run_fsw("replay", log, "--headless", "--speed", speed)
    assert r.code == 0 and "60 frames" in r.err, r.err


# other numbers of the command line, held to what their use can take: refused by the parser
# (status 2, the option named), never an OverflowError from the serial port or the skeleton
@pytest.mark.parametrize("argv", [
    ("skeleton", str(TANK / "tank.sm"), "--delta-t", str(2**64)),
    ("monitor", str(TANK), "--port", "/dev/no-such-port", "--baud", "99999999999999999999"),
    ("cmd", "ping", "-p", str(TANK), "--port", "/dev/no-such-port", "--baud", "99999999999999999999"),
    ("monitor", str(TANK), "--port", "/dev/no-such-port", "--baud", "10000001"),
], ids=["delta-t", "monitor-baud", "cmd-baud", "baud-above-10M"])
def test_numbers_beyond_their_use_are_refused(argv):
    r = run_fsw(*argv)
    assert r.code == 2 and argv[-2] in r.err and "internal error" not in r.err, r.err


def test_largest_delta_t_is_accepted():
    r = run_fsw("skeleton", str(TANK / "tank.sm"), "--delta-t", str(2**64 - 1))
    assert r.code == 0 and f"delta_t {2**64 - 1}" in r.out, r.err
