"""Where the kit's own files are: the firmware runtime, the board
definitions and the build makefiles. This is the one place that knows; every
other module asks it.

In a source checkout (and an editable install) they sit at the top of the
tree, beside `autocode/`. An installed kit (`pip install .`) carries them
inside the package in the same layout, beside `fswkit/autocode/`
(pyproject.toml's package-data): fswkit/firmware/src, fswkit/boards,
fswkit/mk/build.mk, the runtime's Arduino library files and the PlatformIO
hook (fswkit/integrations/platformio) that a platformio.ini written by
`fsw new` names. Either way they are found from this file, never from
the working folder, and nothing is written beside them: builds go to the
project's folder (or --out), compiled helpers to the user's cache
(FSW_CACHE_DIR, else $XDG_CACHE_HOME/fswkit or ~/.cache/fswkit)."""

from __future__ import annotations

import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RUNTIME = os.path.join(ROOT, "firmware", "src")
BOARDS = os.path.join(ROOT, "boards")
BUILD_MK = os.path.join(ROOT, "mk", "build.mk")


def board_names() -> list[str]:
    """The boards the kit knows: the names of its boards/*.toml."""
    try:
        return sorted(n[:-5] for n in os.listdir(BOARDS) if n.endswith(".toml"))
    except OSError:
        return []
