"""A folder at a fixed place, made afresh and held while a test module
uses it: another test run of the same tree waits for it. Tests that build
at one place from run to run (so that a compiler cache or the kit's own
cache finds the same paths) use it instead of a new temporary folder."""

from __future__ import annotations

import contextlib
import fcntl
import shutil
from pathlib import Path


@contextlib.contextmanager
def fresh_folder(place: Path):
    """`place`, emptied and made again, held (an exclusive lock on
    `place`.lock beside it, which the system drops when its holder exits)
    until the block ends."""
    place.parent.mkdir(parents=True, exist_ok=True)
    with open(f"{place}.lock", "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        shutil.rmtree(place, ignore_errors=True)
        place.mkdir()
        yield place
