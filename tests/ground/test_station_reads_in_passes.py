"""The station reads a busy link in passes of whole frames: each pass costs
the decoder, the archive and every client their work, and the thread and
the page's event loop a wake-up each, so a link full of frames is handed
on at most once every PASS_S (the frames that came meanwhile together),
where it was handed on as it trickled in. Nothing is lost or held back
for it: every frame reaches the listener, the archive has every byte and
every frame, and a frame is handed on about PASS_S after its last byte at
the most. The target is a pty fed at the link's real rate (115,200 baud:
about 11.5 bytes a millisecond), as the simulated board feeds it."""

from __future__ import annotations

import os
import sqlite3
import statistics
import time

from fswkit.ground.archive import Archive
from fswkit.ground.station import FRAME_WAIT_S, PASS_S, Station
from support.linkstream import TANK, PtyTarget, layout_of, stream

RATE = 11_520  # bytes a second on a 115,200-baud link


class PacedTarget(PtyTarget):
    """The tank's downlink written at the link's rate, a millisecond's bytes
    at a time, once started; `ends[seq]` is when each frame's last byte was
    written."""

    def __init__(self, frames: list[tuple[int, bytes]]):
        super().__init__()
        self.frames = frames
        self.ends: dict[int, float] = {}

    def _run(self) -> None:
        data = b"".join(f for _, f in self.frames)
        bounds, at = [], 0
        for seq, f in self.frames:
            at += len(f)
            bounds.append((at, seq))
        t0, sent, k = time.monotonic(), 0, 0
        while sent < len(data) and not self._stop.is_set():
            due = min(len(data), int((time.monotonic() - t0) * RATE))
            if due > sent:
                sent += os.write(self.master, data[sent:due])
                now = time.monotonic()
                while k < len(bounds) and bounds[k][0] <= sent:
                    self.ends[bounds[k][1]] = now
                    k += 1
            time.sleep(0.001)


def test_a_full_link_is_handed_on_in_passes_with_every_frame(tmp_path, monkeypatch):
    monkeypatch.setenv("FSW_RUNTIME_DIR", str(tmp_path / "run"))
    layout = layout_of(TANK)
    first = 1000
    frames = list(enumerate(stream(layout, first, 1500, hello_first=True), first))
    passes: list[tuple[float, list]] = []
    path = tmp_path / "ground.sqlite"
    with PacedTarget(frames) as target:
        st = Station(layout, str(TANK), target.port, 115200, archive=Archive(str(path)), serve=False)
        st.listen(lambda evs: passes.append((time.monotonic(), [ev.seq for ev in evs])))
        st.start()
        target.start()  # once the station reads: its first frame is a hello
        try:
            deadline = time.monotonic() + 30
            while len(target.ends) < len(frames) and time.monotonic() < deadline:
                time.sleep(0.1)
            time.sleep(0.3)
        finally:
            st.stop()
        ends = dict(target.ends)
    assert len(ends) == len(frames), "the target could not write its frames"
    seen = [s for _, seqs in passes for s in seqs]
    assert seen == [s for s, _ in frames]  # every frame, once, in order

    busy = [t for t, seqs in passes if seqs]
    gaps = [b - a for a, b in zip(busy, busy[1:])]
    # one pass per PASS_S at the most: the listener sees them so, give or take how long a pass took to
    # reach it (a busy machine's scheduler), where frames went on as they trickled in, ms apart
    # (a pass that reached it late makes the next gap short: 95 % of them, not every one)
    assert sorted(gaps)[len(gaps) // 20] >= PASS_S / 2, f"passes {sorted(gaps)[len(gaps) // 20] * 1000:.1f} ms apart"
    assert statistics.median(gaps) >= PASS_S * 0.95, f"passes {statistics.median(gaps) * 1000:.1f} ms apart"
    span = ends[frames[-1][0]] - ends[frames[0][0]]
    assert len(busy) <= span / PASS_S + 3

    delay = [t - ends[s] for t, seqs in passes for s in seqs]
    # a frame waits for the pass after its last byte: about PASS_S at the most, less on the whole
    assert statistics.median(delay) <= PASS_S, f"median {statistics.median(delay) * 1000:.1f} ms"
    # and its tail within a few passes: on a quiet machine PASS_S + FRAME_WAIT_S, but where the suite runs
    # four workers on two cores the station's thread wakes up to 0.1 s late now and then (the scheduler,
    # not the station); the median above holds a frame to the first pass after its last byte, and one held
    # back until a buffer fills or a batch is due waits longer than this
    assert sorted(delay)[int(len(delay) * 0.9)] <= PASS_S + FRAME_WAIT_S + 0.2, \
        f"90 % within {sorted(delay)[int(len(delay) * 0.9)] * 1000:.1f} ms"

    con = sqlite3.connect(path)  # the archive: every byte, every frame
    (nbytes,) = con.execute("SELECT sum(length(data)) FROM chunks WHERE dir = 0").fetchone()
    assert nbytes == sum(len(f) for _, f in frames)
    assert [s for (s,) in con.execute("SELECT seq FROM frames ORDER BY id")] == [s for s, _ in frames]
    assert con.execute("SELECT count(*) FROM samples s JOIN frames f ON f.id = s.frame "
                       "WHERE f.kind = 'sample'").fetchone()[0] == \
        con.execute("SELECT count(*) FROM frames WHERE kind = 'sample'").fetchone()[0]
    con.close()
