"""The core rocket: examples/rocket as issue 17's size target measured it,
without the recorder, the parameters and the pyro channels that came after
(tools/bench_firmware.py core, whose own edit of the configs this is), built
for the Uno once per test process and shared by the files that read it,
into build/sim-tests/ (kept between runs as support.simfw keeps its
builds: the generated code does not name the project's folder, so a run
that changed nothing finds the firmware up to date and links nothing)."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

from conftest import EXAMPLES, ROOT, run_fsw

_built: tuple[Path, Path] | None = None


def core_project(folder: Path) -> Path:
    """A copy of examples/rocket in `folder`, turned into the core rocket."""
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        from bench_firmware import without_later_features
    finally:
        sys.path.pop(0)
    project = folder / "rocket"
    shutil.copytree(EXAMPLES / "rocket", project, ignore=shutil.ignore_patterns("build"))
    without_later_features(str(project))
    return project


def build_core(tmp_path_factory) -> tuple[Path, Path]:
    """(the core rocket's project, its `fsw build --out` folder: rocket.elf,
    gen/), built the first time a test of this process asks. Tests read
    them and never change them."""
    from support.simfw import OUT

    global _built
    if _built is None:
        project = core_project(tmp_path_factory.mktemp("core"))
        out = OUT / "core-rocket-uno"
        r = run_fsw("build", str(project), "--out", str(out))
        assert r.code == 0, r.err
        _built = project, out
    return _built
