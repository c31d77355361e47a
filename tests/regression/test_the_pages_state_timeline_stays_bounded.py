"""The page's state timeline kept every state change of the session and
drew them all again at each change and at each of the link's ticks (twice
a second): a machine that changes state often over a long session (a vent
valve's controller cycling through a hot fire) made the page ever slower,
until it stopped answering. The timeline now keeps each machine's latest
TIMELINE_KEPT changes (the band and the list), and the page keeps up."""

from __future__ import annotations


from support.browser import browser, needs_chromium, wait_for  # noqa: F401 - browser: a fixture
from support.linkstream import TANK, PtyTarget, layout_of, stream
from support.station_page import station_page


pytestmark = needs_chromium
KEPT = 500  # ground.js's TIMELINE_KEPT


class Flapping(PtyTarget):
    """The tank's clean link at 200 frames a second, its state element
    changing at every sample frame."""

    def __init__(self, layout):
        super().__init__()
        self.layout = layout
        self.start()

    def _run(self) -> None:
        import os
        import select

        n = 5000
        while not self._stop.is_set():
            try:
                os.write(self.master, b"".join(stream(self.layout, n, 10, hello_first=n == 5000)))
                if select.select([self.master], [], [], 0)[0]:
                    os.read(self.master, 4096)
            except OSError:
                return
            n += 10
            self._stop.wait(0.05)


def test_a_machine_that_changes_state_often_keeps_the_page_answering(browser, tmp_path, monkeypatch):
    from selenium.webdriver.common.by import By

    monkeypatch.setenv("FSW_RUNTIME_DIR", str(tmp_path / "run"))
    layout = layout_of(TANK)
    target = Flapping(layout)
    browser.set_script_timeout(10)
    try:
        with station_page(browser, target, layout) as st:
            count = "return document.querySelectorAll('#transitions-state li').length"
            wait_for(lambda: browser.execute_script(count) >= KEPT, f"{KEPT} state changes listed", timeout=40, page=browser)
            seen = browser.execute_script("return window.fswSeqs.length")
            wait_for(lambda: browser.execute_script("return window.fswSeqs.length") > seen + 500,
                     "the page to go on taking frames", timeout=15)
            assert browser.execute_script(count) <= KEPT
            assert browser.execute_script("return document.querySelectorAll('#band-state .seg').length") <= KEPT + 1
            assert browser.find_element(By.ID, "link-status").text == "live"
    finally:
        target.close()
