"""A parameter has a unit (`@unit ms`), and a value typed in another unit
is the mistake a team makes at the pad (`HOLD_MS=0.5` meant as seconds).
The unit was shown by `fsw param list` only: `set HOLD_MS=2s` was refused
as "`2s` is not a whole number", without the unit it wants; a set said
`set HOLD_MS = 700` without one; the page asked "Set parameter HOLD_MS =
700 on the target" without one. Now a number with a unit after it is
told to be given alone, in the parameter's unit; `set` says the unit of
each value it set; the page's confirmation says it too."""

from __future__ import annotations

import time

from conftest import run_fsw
from support.browser import browser, needs_chromium, press, wait_for  # noqa: F401 - browser: a fixture
from support.linkfw import PtyTarget, needs_cxx
from support.param_page import RIG, tuned_page
from support.simfw import kept_native


def test_a_number_with_a_unit_is_told_the_parameters_unit(tmp_path):
    r = run_fsw("param", str(RIG), "set", "HOLD_MS=2s", "--port", str(tmp_path / "none"))
    assert r.code == 2, r.out + r.err
    assert "`HOLD_MS` is U16: `2s` is not a whole number: give the number alone, in ms (its unit)" in r.err, r.err
    r = run_fsw("param", str(RIG), "set", "OPEN_AT=650 psi", "--port", str(tmp_path / "none"))
    assert "`OPEN_AT` is F32: `650 psi` is not a number: give the number alone, in psi (its unit)" in r.err, r.err
    r = run_fsw("param", str(RIG), "set", "TRIM=3m", "--port", str(tmp_path / "none"))
    assert "`TRIM` is I8: `3m` is not a whole number: give the number alone (`TRIM` has no unit)" in r.err, r.err


@needs_cxx()
def test_set_says_the_units_of_what_it_set(tmp_path):
    exe = kept_native(RIG) / "tuned"
    with PtyTarget(exe, "--eeprom", str(tmp_path / "e.bin")) as t:
        time.sleep(0.2)
        r = run_fsw("param", str(RIG), "set", "HOLD_MS=700", "OPEN_AT=650.5", "TRIM=2", "--port", t.port)
        assert r.code == 0, r.err
        assert "set HOLD_MS = 700 ms, OPEN_AT = 650.5 psi, TRIM = 2 (live" in r.out, r.out


@needs_cxx()
@needs_chromium
def test_the_pages_confirmation_says_the_unit(browser, tmp_path):
    from selenium.webdriver.common.by import By

    with tuned_page(browser, tmp_path):
        text = lambda i: browser.find_element(By.ID, i).text  # noqa: E731
        wait_for(lambda: text("pval-HOLD_MS") == "500 ms", "the parameters", page=browser)
        browser.find_element(By.ID, "pset-HOLD_MS").send_keys("700")
        press(browser, "psend-HOLD_MS")
        wait_for(lambda: browser.find_element(By.ID, "confirm").get_attribute("open") is not None, "the dialog", page=browser)
        assert text("confirm-text") == "Set parameter HOLD_MS = 700 ms on the target (live, until saved)?"
        press(browser, "confirm-no")
