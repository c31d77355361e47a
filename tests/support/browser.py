"""Debian's Chromium, headless, driven by Selenium through chromedriver
(installed by `make setup`), for the web ground station's tests; and a free
TCP port for the station to serve on, and an app served there in a thread."""

from __future__ import annotations

import contextlib
import os
import socket
import threading
import time

import pytest

CHROMIUM, DRIVER = "/usr/bin/chromium", "/usr/bin/chromedriver"
needs_chromium = pytest.mark.skipif(not (os.path.exists(CHROMIUM) and os.path.exists(DRIVER)),
                                    reason="Debian's chromium and chromium-driver are needed (make setup)")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def chromium():
    """A headless Chromium, 1400×1000 (the docs' screenshots' size); quit it after use."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = CHROMIUM
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
              "--disable-background-networking", "--disable-component-update", "--disable-sync",
              "--disable-dev-shm-usage", "--window-size=1400,1000"):
        opts.add_argument(a)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})  # for page_state
    return webdriver.Chrome(service=Service(DRIVER), options=opts)


def wait_for(fn, what: str, timeout: float = 10.0, page=None):
    """What `fn()` gives once it is truthy (an exception counts as not yet),
    polled every 0.1 s; AssertionError after `timeout` seconds, with what
    the page in the browser `page` showed and logged then when it is given."""
    deadline = time.monotonic() + timeout
    while True:
        try:
            v = fn()
        except Exception:  # the page is still building what fn looks for
            v = None
        if v:
            return v
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}" + (page_state(page) if page else ""))
        time.sleep(0.1)


def press(page, element_id: str):
    """Clicks the element `element_id` of the page in the browser `page`,
    scrolled to the middle of the window first (the page's panels keep
    their size as frames arrive: test_the_page_does_not_move_under_a_click_
    as_frames_arrive)."""
    from selenium.webdriver.common.by import By

    el = page.find_element(By.ID, element_id)
    page.execute_script("arguments[0].scrollIntoView({block: 'center'})", el)
    el.click()


def page_state(page) -> str:
    """What a failing test's page showed and logged: its open dialogs, its
    error lines and the browser console's messages."""
    try:
        shown = page.execute_script(
            "return Array.from(document.querySelectorAll('dialog[open], .err'), "
            "e => (e.id || e.tagName) + ': ' + e.textContent.trim()).filter(t => !t.endsWith(': ')).join('\\n')")
        logs = "\n".join(m.get("message", "") for m in page.get_log("browser"))
    except Exception as e:  # noqa: BLE001 - the page itself may be what failed
        return f"\n(the page could not be read: {e})"
    return f"\nthe page showed:\n{shown or '(no dialog, no error)'}\nthe console:\n{logs or '(nothing)'}"


@pytest.fixture(scope="module")
def browser():
    """A headless Chromium for a test module (import this fixture into it)."""
    drv = chromium()
    yield drv
    drv.quit()


@contextlib.contextmanager
def served(app):
    """The app on a free localhost port, in a thread: its URL."""
    import uvicorn

    http = free_port()
    server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=http, log_level="warning",
                                           ws="websockets-sansio"))
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + 10
    while not server.started:
        assert time.monotonic() < deadline, "the server did not start"
        time.sleep(0.02)
    try:
        yield f"http://127.0.0.1:{http}/"
    finally:
        server.should_exit = True
        thread.join(5)
