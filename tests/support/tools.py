"""A script of tools/ (a benchmark) loaded as a module, for the tests that
build what it builds: tools/ is not a package."""

from __future__ import annotations

import importlib.util
from pathlib import Path

TOOLS = Path(__file__).resolve().parents[2] / "tools"


def tool(name: str):
    """tools/NAME.py, loaded afresh."""
    spec = importlib.util.spec_from_file_location(name, TOOLS / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def rocket_with_reload(out: str, baud: int):
    """examples/rocket with [reload] of its mission machine, as
    tools/bench_reload.py makes it for a simulated ATmega2560 at `baud`
    (its configs written into `out`), and the mission machine's image: (the
    application, the build, the image, its state mask). Built as the tool
    builds it (`built`), into build/sim-tests/ (kept between runs as
    support.simfw keeps its builds: the generated code does not name the
    project's folder, so a run that changed nothing links nothing)."""
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.cli.machine import image_for
    from support.simfw import OUT

    R = tool("bench_reload")
    R.OUT = out
    folder = R.rocket_variant(f"rocket-{baud}", baud)
    R.OUT = str(OUT / "reload")  # where R.built builds: OUT/rocket-BAUD
    app, built = R.built(folder)
    d = Diagnostics()
    got = image_for(app, str(TOOLS.parent / "examples" / "rocket" / "mission.sm"), d)
    assert got is not None, d.render()
    image, mask, _m = got
    return app, built, image, mask
