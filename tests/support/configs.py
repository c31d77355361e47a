"""The tank example's configs copied for a test to edit, and the edit."""

from __future__ import annotations

from pathlib import Path

TANK = Path(__file__).resolve().parents[2] / "examples" / "tank"


def tank_configs(tmp: Path) -> Path:
    """tmp with the tank's configs (no build, no other scripts): tmp."""
    for name in ("tank.sv", "tank.sm", "tank.ss", "tank.app", "tank.aio", "tank.dio"):
        (tmp / name).write_bytes((TANK / name).read_bytes())
    return tmp


def edit(path: Path, old: str, new: str) -> None:
    """Replaces the first `old` in the file with `new`; `old` must be there."""
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))


def example_copy(name: str, tmp: Path) -> Path:
    """A copy of examples/NAME in tmp/NAME without its build folder: the copy."""
    import shutil

    dst = tmp / name
    shutil.copytree(TANK.parent / name, dst, ignore=shutil.ignore_patterns("build"))
    return dst
