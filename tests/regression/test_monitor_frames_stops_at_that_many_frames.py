"""`fsw monitor --frames N` is to stop after N frames (docs/cli.md), but it
looked at the count only after each read of the port, and the count took
in frames it never showed: `--frames 5 --headless` printed as many lines
as the reads happened to bring (a dozen, at the stream's pace). It now
stops at the Nth frame it decoded and showed: N lines (the summary counts
every frame read, as before). A frame of the handshake
(the hello) counts; the monitor never stops before the hello has matched."""

from __future__ import annotations

import pytest
from conftest import run_fsw
from support.linkstream import PtyStream, layout_of, tank_copy


@pytest.fixture(scope="module")
def quiet(tmp_path_factory):
    """The tank without its uplink: the monitor waits for the hello and reads."""
    return tank_copy(tmp_path_factory.mktemp("frames") / "tank", uplink=False)


@pytest.mark.parametrize("n", [1, 5, 37])
def test_headless_monitor_prints_exactly_n_frames(quiet, n):
    with PtyStream(layout_of(quiet), hello_first=True) as target:
        r = run_fsw("monitor", str(quiet), "--port", target.port, "--headless", "--frames", str(n))
    assert r.code == 0, r.err
    lines = r.out.splitlines()
    assert len(lines) == n, r.out
    assert lines[0].startswith("seq=") and " hello " in lines[0]
    assert "link: " in r.err  # the summary counts every frame read, shown or not
