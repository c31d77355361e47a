"""The parameter rig (tests/param/tuned), built natively and run on a pty,
behind a ground station whose web page a test's browser has open."""

from __future__ import annotations

import contextlib
from pathlib import Path

RIG = Path(__file__).resolve().parents[1] / "param" / "tuned"


@contextlib.contextmanager
def tuned_page(browser, tmp_path: Path, until: Path | None = None):
    """The rig's target (its EEPROM in tmp_path), its station and the page
    open in `browser`: yields the target (its `port`). With `until`, the
    target starts only once that file exists: the page is open on a silent
    port until then."""
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.params import app_parameters
    from fswkit.autocode.schema import link_plan
    from fswkit.ground.station import Station
    from fswkit.link.layout import from_app
    from fswkit.target.build import load
    from fswkit.web.app import create_app
    from fswkit.web.source import LiveSource

    from support.browser import served
    from support.linkfw import PtyTarget
    from support.simfw import kept_native

    app = load(str(RIG), Diagnostics())
    run = (kept_native(RIG) / "tuned", "--eeprom", str(tmp_path / "e.bin"))
    if until is not None:
        run = ("/bin/sh", "-c", 'while [ ! -e "$0" ]; do sleep 0.02; done; exec "$@"', str(until), *map(str, run))
    with PtyTarget(*run) as target:
        ground = Station(from_app(app), str(RIG), target.port, 115200)
        ground.start()
        try:
            source = LiveSource(ground, params=app_parameters(app), tx_cap=link_plan(app).tx_cap)
            with served(create_app(source)) as url:
                browser.get(url)
                yield target
        finally:
            ground.stop()
