"""A command the target never answered was told as refused: the page's
history said `set valveOpen = true — refused: no acknowledgement`, though
a refusal is the target's answer and a missing one says nothing of
whether it was applied (the command may have been, its acknowledgement
lost). And a command given while the port was gone (a cable pulled) was
archived and listed as sent with no acknowledgement, though nothing went
on the wire. Now the station's words (its history, its archive, the
client's error) tell the three apart — applied, refused and why, no
acknowledgement (lost, or applied with its answer lost), not sent (the
port is not open) — and the page lists each as that, an unanswered one
not as refused."""

from __future__ import annotations

import sqlite3

import pytest
from support.browser import browser, needs_chromium, press, wait_for  # noqa: F401 - browser: a fixture
from support.linkstream import TANK, PtyStream, PtyTarget, health, hello, layout_of
from support.station_page import station_page

from fswkit.ground.archive import Archive
from fswkit.ground.station import Station
from fswkit.link import wire
from fswkit.link.client import LinkTimeout

LOST = "no acknowledgement of `hello` after 2 tries: lost, or applied and its acknowledgement lost"
NOT_SENT = "not sent: the port is not open (it went away)"


def test_the_station_tells_a_lost_command_from_one_never_sent(tmp_path, monkeypatch):
    monkeypatch.setenv("FSW_RUNTIME_DIR", str(tmp_path / "run"))
    layout = layout_of(TANK)
    path = tmp_path / "ground.sqlite"
    entries = []
    target = PtyStream(layout, hello_first=True)  # reads and drops what the ground sends: no acknowledgement
    st = Station(layout, "tank", target.port, 115200, archive=Archive(str(path)), serve=False)
    st.commands(entries.append)
    st.start()
    try:
        with pytest.raises(LinkTimeout) as lost:
            st.command("test", wire.OP_HELLO, b"", tries=2, timeout=0.2, text="hello, unanswered")
        assert str(lost.value) == LOST
        target.close()  # the port goes away
        wait_for(lambda: not st.up, "the station to see the port gone")
        with pytest.raises(OSError) as gone:
            st.command("test", wire.OP_HELLO, b"", tries=2, timeout=0.2, text="hello, port gone")
        assert str(gone.value) == NOT_SENT
    finally:
        st.stop()
    mine = [e for e in entries if e["who"] == "test"]
    assert [(e["text"], e["ok"], e["status"], e["words"]) for e in mine] == [
        ("hello, unanswered", False, None, LOST), ("hello, port gone", False, None, NOT_SENT)]
    con = sqlite3.connect(path)
    rows = con.execute("SELECT text, status, words FROM commands WHERE who = 'test' ORDER BY id").fetchall()
    assert rows == [("hello, unanswered", None, LOST), ("hello, port gone", None, NOT_SENT)]


class DeafTarget(PtyTarget):
    """A target on a pty that sends a health frame every 50 ms (a hello every tenth),
    and reads and drops whatever the ground sends: no acknowledgement ever
    comes."""

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
                os.write(self.master, (hello if n % 10 == 0 else health)(self.layout, n, 10 * n))
                if select.select([self.master], [], [], 0)[0]:
                    os.read(self.master, 4096)
            except OSError:
                return
            n += 1
            self._stop.wait(0.05)


@needs_chromium
def test_the_page_lists_an_unanswered_command_as_unanswered_not_refused(browser, tmp_path, monkeypatch):
    from selenium.webdriver.common.by import By

    monkeypatch.setenv("FSW_RUNTIME_DIR", str(tmp_path / "run"))
    layout = layout_of(TANK)
    target = DeafTarget(layout)
    with station_page(browser, target, layout) as st:
        text = lambda i: browser.find_element(By.ID, i).text  # noqa: E731

        def send(value: str):
            box = browser.find_element(By.ID, "cmd-valveOpen")
            box.clear()
            box.send_keys(value)
            press(browser, "send-valveOpen")
            wait_for(lambda: browser.find_element(By.ID, "confirm").get_attribute("open") is not None, "the dialog", page=browser)
            press(browser, "confirm-yes")
            return wait_for(lambda: [li for li in browser.find_elements(By.CSS_SELECTOR, "#history li")
                                     if f"set valveOpen = {value}" in li.text], "the command in the history",
                            timeout=15)[0]

        wait_for(lambda: text("link-status") == "live", "the link to show live", page=browser)
        item = send("true")
        assert "refused" not in item.text, item.text
        assert "after 3 tries: lost, or applied and its acknowledgement lost" in item.text
        assert item.get_attribute("class") == "lost"
        target.close()
        wait_for(lambda: not st.up, "the station to see the port gone", page=browser)
        item = send("false")
        assert "refused" not in item.text, item.text
        assert NOT_SENT in item.text, item.text
        assert item.get_attribute("class") == "lost"
