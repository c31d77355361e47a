"""The web station's page read the target's parameters when it loaded and
after a value set in the page, and never again: a value set or a file
loaded from a terminal (`fsw param`, through the same station), a save, or
a restart of the target left the page showing values and a store state
the board no longer had, with nothing to say so. Now the page reads them
again when an acknowledged SET, COMMIT or SAVE goes by on the link, or
when the store state that every hello and health frame carries changes."""

from __future__ import annotations

import time

from conftest import run_fsw
from support.browser import browser, needs_chromium, wait_for  # noqa: F401 - browser: a fixture
from support.linkfw import needs_cxx
from support.param_page import RIG, tuned_page

pytestmark = [needs_cxx(), needs_chromium]


def test_a_terminals_set_and_save_show_in_the_page(browser, tmp_path):
    from selenium.webdriver.common.by import By

    with tuned_page(browser, tmp_path) as target:
        text = lambda i: browser.find_element(By.ID, i).text  # noqa: E731
        wait_for(lambda: text("pval-OPEN_AT") == "800 psi", "the parameters", page=browser)
        assert text("param-state") == "defaults"
        # another client, through the station: the page was not asked
        r = run_fsw("param", str(RIG), "set", "OPEN_AT=650.5", "--port", target.port)
        assert r.code == 0, r.out + r.err
        wait_for(lambda: text("pval-OPEN_AT") == "650.5 psi", "the value set from the terminal", page=browser)
        wait_for(lambda: "unsaved changes" in text("param-state"), "the unsaved changes", page=browser)
        r = run_fsw("param", str(RIG), "set", "TRIM=7", "--port", target.port)
        assert r.code == 0, r.err  # the store state stays the same: the SET's acknowledgement tells
        wait_for(lambda: text("pval-TRIM") == "7", "the second value", page=browser)
        r = run_fsw("param", str(RIG), "save", "--port", target.port)
        assert r.code == 0, r.err
        wait_for(lambda: text("param-state") == "bank A, sequence 1", "the saved bank", page=browser)
        time.sleep(0.5)
        assert text("param-err") == ""


def test_a_value_being_typed_survives_a_read_again(browser, tmp_path):
    """Reading the parameters again made the table's rows again, their
    inputs empty: a value being typed when another client's change arrived
    was gone. The rows of the same table are kept, only their values
    written again."""
    from selenium.webdriver.common.by import By

    with tuned_page(browser, tmp_path) as target:
        text = lambda i: browser.find_element(By.ID, i).text  # noqa: E731
        wait_for(lambda: text("pval-OPEN_AT") == "800 psi", "the parameters", page=browser)
        browser.find_element(By.ID, "pset-HOLD_MS").send_keys("700")
        r = run_fsw("param", str(RIG), "set", "OPEN_AT=650.5", "--port", target.port)
        assert r.code == 0, r.out + r.err
        wait_for(lambda: text("pval-OPEN_AT") == "650.5 psi", "the value set from the terminal", page=browser)
        assert browser.find_element(By.ID, "pset-HOLD_MS").get_attribute("value") == "700"
