"""A target that restarted mid-session (a reset, a reflash) begins its time
at zero again, and the page's live plot went on appending: its time column
went back, so the plot drew the new samples over the old ones, joined by a
line back to zero, and a time window ("the last 10 s") showed the whole
session before the reset mixed with the new one. The page now starts its
plot again when the target's time goes back (the station's note says the
target restarted), its time always in order."""

from __future__ import annotations

import threading

from support.browser import browser, needs_chromium, wait_for  # noqa: F401 - browser: a fixture
from support.linkstream import TANK, PtyTarget, layout_of, stream
from support.station_page import station_page


pytestmark = needs_chromium


class Resetting(PtyTarget):
    """The tank's clean link at 100 frames a second from frame 5000 (its time
    50 s), then, once `reset` is set, restarted: from frame 0 (time 0) on."""

    def __init__(self, layout):
        super().__init__()
        self.layout = layout
        self.reset = threading.Event()
        self.start()

    def _run(self) -> None:
        import os
        import select
        n = 5000
        reset = False
        while not self._stop.is_set():
            if not reset and self.reset.is_set():
                n, reset = 0, True
            try:
                os.write(self.master, b"".join(stream(self.layout, n, 5, hello_first=n in (0, 5000))))
                if select.select([self.master], [], [], 0)[0]:
                    os.read(self.master, 4096)
            except OSError:
                return
            n += 5
            self._stop.wait(0.05)


def test_the_plot_starts_again_with_the_targets_time(browser, tmp_path, monkeypatch):

    monkeypatch.setenv("FSW_RUNTIME_DIR", str(tmp_path / "run"))
    layout = layout_of(TANK)
    target = Resetting(layout)
    try:
        with station_page(browser, target, layout) as st:
            wait_for(lambda: browser.execute_script("return series.t.length && series.t[series.t.length - 1] >= 50"),
                     "the page to plot the target's time before its reset", timeout=15)
            target.reset.set()
            wait_for(lambda: browser.execute_script("return series.t.length && series.t[series.t.length - 1] < 40"),
                     "the page to plot the time after the reset", timeout=15)
            t = browser.execute_script("return series.t")
            assert all(a <= b for a, b in zip(t, t[1:])), "the plot's time went back"
            assert t[0] < 40
    finally:
        target.close()
