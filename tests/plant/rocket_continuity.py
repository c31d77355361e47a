"""A copy of examples/rocket (its igniters' continuity inputs on A2 and A3,
volts as read) whose plant.toml has only the continuity keys a test of the
simulated igniters asks for."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

from conftest import EXAMPLES

ROCKET = EXAMPLES / "rocket"


def continuity_project(dest: Path, plant_keys: dict[str, str] | None = None) -> Path:
    """examples/rocket copied to `dest` (without its build), its plant.toml's
    continuity keys replaced by `plant_keys` ({"drogue": 'continuity_channel
    = "A2"', ...}), written at the top of those tables."""
    shutil.copytree(ROCKET, dest, ignore=shutil.ignore_patterns("build"))
    assert all(re.search(rf"^\s*i\s+{pin}\s", (dest / "rocket.aio").read_text(), re.M) for pin in ("A2", "A3"))
    plant = (dest / "plant.toml").read_text()
    plant = re.sub(r"^\s*(continuity_channel|intact_volts|open_volts)\s*=.*\n", "", plant, flags=re.M)
    for table, keys in (plant_keys or {}).items():
        plant = re.sub(rf"^\[{table}\][^\n]*\n", lambda m: m.group(0) + keys + "\n", plant, count=1, flags=re.M)
    (dest / "plant.toml").write_text(plant)
    return dest
