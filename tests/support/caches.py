"""A test's own kit cache, with the runtime's native objects already in it;
and those objects for a test's own native program.

Tests that need an empty cache to watch what a compile leaves behind (its
temporary folder, its runner) need not watch the runtime compile as well:
the runtime's objects (about 2.5 s of CPU from nothing) are compiled once
into the run's cache, and copied from there into the test's. A test that
compiles a program of its own against the runtime links them from there
(`native_runtime`), as a native build does."""

from __future__ import annotations

import os
import shutil

from fswkit.autocode.numeric import F64MODE
from fswkit.run import native


def seeded(folder, real=F64MODE) -> str:
    """`folder` as a kit cache (FSW_CACHE_DIR) holding the runtime's objects
    for `real` from the run's own cache; returns it. Call it before the
    test points FSW_CACHE_DIR at `folder`."""
    objs = native.runtime_objects(real)  # the run's cache: compiled there once
    entry = os.path.dirname(objs[0])
    shutil.copytree(entry, os.path.join(folder, "native", os.path.basename(entry)))
    return str(folder)


def native_runtime() -> list[str]:
    """The runtime's objects as a native build links them (`fsw build
    --board native`, fswkit.target.libcache.native_objects: binary64, the
    kit's flags), compiled once into the run's cache: a test that compiles
    its own program against the runtime compiles only that program."""
    return native.runtime_objects(F64MODE)
