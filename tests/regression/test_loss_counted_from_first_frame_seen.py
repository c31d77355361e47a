"""A ground that attaches to a link mid-stream counts frames lost only from
the first frame it saw: the first frame's 8-bit sequence number is not the
target's whole frame counter. Live (the session the monitor uses), in the
log it writes, and in log2csv and replay of that log."""

from __future__ import annotations

import pytest
from conftest import run_fsw
from support.linkstream import TANK, layout_of, stream

from fswkit.link.log import RX, LogWriter
from fswkit.link.session import Session


@pytest.fixture(scope="module")
def layout():
    return layout_of(TANK)


# the counts a ground reported on clean links, each a first frame met mid-stream
@pytest.mark.parametrize("first", [1, 256 + 7, 768 + 30, 5120 + 200, 30464 + 99, 2**32 - 600])
def test_clean_link_joined_mid_stream_loses_nothing(layout, first):
    s = Session(layout)
    for f in stream(layout, first, 600):
        s.feed(f)
    assert s.stats.lost == 0 and s.stats.gaps == 0 and s.stats.restarts == 0
    assert s.stats.frames == 600


def test_loss_after_the_first_frame_is_still_counted(layout):
    first = 5120 + 11
    gone = {first + 3, first + 4, first + 5} | set(range(first + 100, first + 400))  # a short gap, a long one
    s = Session(layout)
    for f in stream(layout, first, 600, skip=gone):
        s.feed(f)
    assert s.stats.lost == len(gone) and s.stats.restarts == 0


def test_log_tools_count_from_the_first_frame(layout, tmp_path):
    log = tmp_path / "joined.log"
    w = LogWriter(str(log), layout, port="test")
    for i, f in enumerate(stream(layout, 30464 + 99, 500)):
        w.record(RX, 1_000_000_000 + i * 10_000_000, f)
    w.close()
    for argv in (("log2csv", str(log), "-o", str(tmp_path / "out.csv")),
                 ("replay", str(log), "--headless", "--speed", "0")):
        r = run_fsw(*argv)
        assert r.code == 0, r.err
        assert "500 frames" in r.err and " 0 lost in 0 gaps" in r.err, (argv, r.err)
