"""`fsw replay --speed` takes 0 (as fast as possible) or a speed whose
waits stay representable: a speed so small the waits overflow, a negative,
infinite or NaN speed is refused with a clear message before the log is
read, never a traceback mid-replay."""

from __future__ import annotations

import pytest
from conftest import run_fsw
from linkstream import TANK, layout_of, stream

from fswkit.link.log import RX, LogWriter


@pytest.fixture(scope="module")
def log(tmp_path_factory):
    path = tmp_path_factory.mktemp("replay") / "flight.log"
    layout = layout_of(TANK)
    w = LogWriter(str(path), layout)
    for i, f in enumerate(stream(layout, 0, 60, hello_first=True)):
        w.record(RX, 1_000_000_000 + i * 1_000, f)  # 1 µs apart: 0.06 s at the slowest speed
    w.close()
    return str(path)


@pytest.mark.parametrize("speed", ["1e-300", "0.0009", "-1", "inf", "nan", "1e7", "fast"])
def test_refused(log, speed):
    r = run_fsw("replay", log, "--headless", "--speed", speed)
    assert r.code == 2 and "--speed" in r.err and "Traceback" not in r.err, r.err


@pytest.mark.parametrize("speed", ["0", "0.001", "1000", "1000000"])
def test_accepted(log, speed):
    r = run_fsw("replay", log, "--headless", "--speed", speed)
    assert r.code == 0 and "60 frames" in r.err, r.err
