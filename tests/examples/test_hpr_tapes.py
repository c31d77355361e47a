"""Real flights through examples/hpr, the CATS tapes but the longest (and any tape of a recorder not named): see tests/support/hpr_tapes.py."""

from __future__ import annotations

import pytest

from support.hpr_tapes import MARKS, build_hpr, replay_and_check, tapes

pytestmark = MARKS + [pytest.mark.costly(11)]


@pytest.fixture(scope="module")
def hpr_firmware():
    return build_hpr()


@pytest.mark.parametrize("name", tapes("cats"))
def test_every_tape_replays_through_hpr_with_every_check_passing(name, hpr_firmware):
    replay_and_check(name, hpr_firmware)

