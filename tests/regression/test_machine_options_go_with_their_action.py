"""`fsw machine` took every option with every action and ignored those that
mean nothing to it: `upload X.sm --wait 60` (no `--activate`) committed and
returned, nothing activated, nothing said; `list --activate` and
`activate 1 --restart` did what they would have done without. Like
`fsw param`'s `-o` (which goes with `list`), each option is refused with
the actions it does not go with, before the project or a port is read."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES

STAND = str(EXAMPLES / "stand")
NEW = str(EXAMPLES / "stand" / "tank_700.sm")
PORT = "/dev/ttyNOPE"


@pytest.mark.parametrize("argv, message", [
    (["upload", NEW, "--wait", "60"], "--wait goes with `activate`, `revert` and `upload --activate`"),
    (["list", "--wait", "1"], "--wait goes with `activate`, `revert` and `upload --activate`"),
    (["list", "--activate"], "--activate goes with `upload`"),
    (["revert", "--activate"], "--activate goes with `upload`"),
    (["activate", "1", "--restart"], "--restart goes with `upload`"),
])
def test_an_option_the_action_does_not_take_is_refused(fsw, argv, message):
    r = fsw("machine", STAND, *argv, "--port", PORT)
    assert r.code == 2 and f"fsw machine: {message}" in r.err, r.err
    assert PORT not in r.err


@pytest.mark.parametrize("argv", [
    ["upload", NEW, "--activate", "--wait", "60", "--restart"],
    ["activate", "1", "--wait", "0"],
    ["revert", "--wait", "3"],
    ["list"],
])
def test_options_with_their_action_reach_the_port(fsw, argv):
    r = fsw("machine", STAND, *argv, "--port", PORT)
    assert r.code == 1 and PORT in r.err, r.err
