"""`fsw machine activate|revert --wait S` took `nan`, `inf` and negative
numbers and went on to open the port: with a NaN, the wait for the board to
switch (`now() > end`) never ends. They are refused before the port is
opened, as `--baud` is."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES


@pytest.mark.parametrize("wait, message", [("nan", "expected a finite number, found 'nan'"),
                                           ("-5", "expected a number >= 0, found -5"),
                                           ("inf", "expected a finite number, found 'inf'"),
                                           ("1e999", "expected a finite number of seconds, found 1e999")])
def test_a_wait_that_would_never_end_is_refused(fsw, wait, message):
    r = fsw("machine", str(EXAMPLES / "stand"), "revert", "--wait", wait, "--port", "/dev/ttyNOPE")
    assert r.code == 2 and f"argument --wait: {message}" in r.err, r.err
    assert "ttyNOPE" not in r.err  # never got as far as the port


def test_a_finite_wait_reaches_the_port(fsw):
    r = fsw("machine", str(EXAMPLES / "stand"), "revert", "--wait", "2.5", "--port", "/dev/ttyNOPE")
    assert r.code != 0 and "ttyNOPE" in r.err, r.err
