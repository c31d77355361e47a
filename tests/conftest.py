"""Shared fixtures: paths and a runner for the `fsw` command in-process
(fswkit.testing.runner, which the tools use too)."""

from __future__ import annotations

from pathlib import Path

import pytest

from fswkit.testing.runner import Ran, run_fsw

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
SHARED = ROOT.parent / "shared"

__all__ = ["ROOT", "EXAMPLES", "SHARED", "Ran", "run_fsw", "fsw"]


@pytest.fixture
def fsw():
    return run_fsw
