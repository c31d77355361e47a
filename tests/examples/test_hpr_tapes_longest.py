"""Real flights through examples/hpr, the longest replay (lince, 406 s through the main): see
tests/support/hpr_tapes.py."""

from __future__ import annotations

import pytest

from support.hpr_tapes import MARKS, build_hpr, replay_and_check, tapes

pytestmark = MARKS + [pytest.mark.costly(7)]


@pytest.fixture(scope="module")
def hpr_firmware():
    return build_hpr()


@pytest.mark.parametrize("name", tapes("longest"))
def test_every_tape_replays_through_hpr_with_every_check_passing(name, hpr_firmware):
    replay_and_check(name, hpr_firmware)
