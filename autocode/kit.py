"""Where the kit's own files are: the firmware runtime, the board
definitions and the build makefiles. This is the one place that knows; every
other module asks it.

In a source checkout (and an editable install) they sit at the top of the
tree, beside `autocode/`."""

from __future__ import annotations

import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RUNTIME = os.path.join(ROOT, "firmware", "src")
BOARDS = os.path.join(ROOT, "boards")
BUILD_MK = os.path.join(ROOT, "mk", "build.mk")
