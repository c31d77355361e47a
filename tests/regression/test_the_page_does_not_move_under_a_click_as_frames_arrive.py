"""The web station's page built its link and task tables when the first
health frame arrived (13 rows for the parameter rig, 264 px) and each
machine's transition list grew a line a transition: the Parameters panel
below them moved down under the operator's pointer about half a second
after the page opened. A click aimed at a parameter's Set button then
landed beside it, and nothing happened (seen as a browser test that timed
out waiting for the confirmation). Now the tables have every row the
layout names from the start, a dash in each value, and a transition list
has its height from the start: the first frames fill cells in place."""

from __future__ import annotations

from support.browser import browser, needs_chromium, press, wait_for  # noqa: F401 - browser: a fixture
from support.linkfw import needs_cxx
from support.param_page import tuned_page

WATCHED = ("parameters", "param-refresh", "param-table", "commands")


def _tops(page) -> dict:
    return page.execute_script(
        "return Object.fromEntries(arguments[0].map(i => [i, document.getElementById(i).getBoundingClientRect().top"
        " + window.scrollY]))", list(WATCHED))


@needs_cxx()
@needs_chromium
def test_the_first_frames_fill_the_page_in_place(browser, tmp_path):
    from selenium.webdriver.common.by import By

    go = tmp_path / "go"
    with tuned_page(browser, tmp_path, until=go):
        cell = lambda css: browser.find_element(By.CSS_SELECTOR, css).text  # noqa: E731
        wait_for(lambda: cell("#task-m .task-mode_name") == "—", "the task rows before any frame", page=browser)
        assert cell("#link-table").splitlines()[:3] == ["reset cause —", "cycles —", "late starts —"], cell("#link-table")
        before = _tops(browser)
        go.touch()  # the target starts: hello, samples, a transition, health frames
        wait_for(lambda: cell("#task-m .task-mode_name") == "enabled", "the first health frame", page=browser)
        wait_for(lambda: cell("#transitions-state li"), "the first transition", page=browser)
        press(browser, "param-refresh")
        wait_for(lambda: cell("#pval-HOLD_MS") == "500 ms", "the parameters", page=browser)
        assert _tops(browser) == before
        assert cell("#link-table").splitlines()[:2] != ["reset cause —", "cycles —"], cell("#link-table")
