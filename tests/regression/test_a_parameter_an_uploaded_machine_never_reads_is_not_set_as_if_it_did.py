"""An uploaded machine (docs/reload.md) reads the defaults of its own
parameters, never the store's: while one runs in place of the generated
machine, `fsw param set VENT_AT=600` said "set" and the page showed 600,
though the machine that ran never read it. Now, when the project's
[reload] machine declares parameters and the target runs an uploaded
image in its place (MACHINE_INFO), `fsw param set`/`load` of those
parameters and the page's set are refused, saying why and what to do
(`fsw machine PROJECT revert`); `list`, `get`, `diff` and the page say it
next to the values. Once reverted, the values reach the machine again.

The rig: examples/stand (examples/tank with a [reload] section) on the
`native` board, its vent threshold a parameter VENT_AT, and
examples/stand/tank_700.sm uploaded."""

from __future__ import annotations

import asyncio
import shutil
import time

import pytest

from conftest import EXAMPLES, run_fsw
from support.linkfw import PtyTarget, needs_cxx

pytestmark = needs_cxx()


@pytest.fixture(scope="module")
def rig(tmp_path_factory):
    root = tmp_path_factory.mktemp("rig")
    (root / "tank").mkdir()
    (root / "stand").mkdir()
    for n in ("tank.sv", "tank.aio", "tank.dio"):
        shutil.copy(EXAMPLES / "tank" / n, root / "tank" / n)
    sm = (EXAMPLES / "tank" / "tank.sm").read_text()
    sm = sm.replace("[TankVentControl]", "[parameters]\nF64 VENT_AT = 775 @min 500 @max 900 @unit psi "
                    "@when TankVentControl Idle\n\n[TankVentControl]", 1)
    sm = sm.replace("tankPressure > 775", "tankPressure > VENT_AT")
    (root / "tank" / "tank.sm").write_text(sm)
    app = (EXAMPLES / "stand" / "stand.app").read_text().replace("board uno", "board native")
    (root / "stand" / "stand.app").write_text(app)
    shutil.copy(EXAMPLES / "stand" / "tank_700.sm", root / "stand" / "tank_700.sm")
    r = run_fsw("build", str(root / "stand"), "--board", "native", "--out", str(root / "out"))
    assert r.code == 0, r.err
    return root


def test_set_is_refused_while_an_uploaded_machine_runs(rig, tmp_path):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.params import app_parameters
    from fswkit.autocode.schema import link_plan
    from fswkit.ground.station import Station
    from fswkit.link.layout import from_app
    from fswkit.target.build import load
    from fswkit.web.source import LiveSource

    project = str(rig / "stand")
    with PtyTarget(rig / "out" / "stand", "a14=770", "--eeprom", str(tmp_path / "e.bin")) as t:
        time.sleep(0.2)
        assert run_fsw("param", project, "set", "VENT_AT=760", "--port", t.port).code == 0  # the generated one runs
        r = run_fsw("machine", project, "upload", str(rig / "stand" / "tank_700.sm"), "--activate", "--port", t.port)
        assert r.code == 0 and "slot 1 runs" in r.out, r.out + r.err
        r = run_fsw("param", project, "set", "VENT_AT=600", "--port", t.port)
        assert r.code == 1, r.out + r.err
        assert ("`VENT_AT` is a parameter of machine `tank`, which runs the image uploaded in slot 1: an uploaded "
                "machine reads its own defaults, never these values") in r.err, r.err
        assert "fsw machine" in r.err and "revert" in r.err, r.err
        f = tmp_path / "p.toml"
        f.write_text("VENT_AT = 600\n")
        r = run_fsw("param", project, "load", str(f), "--port", t.port)
        assert r.code == 1 and "runs the image uploaded in slot 1" in r.err, r.out + r.err
        r = run_fsw("param", project, "list", "--port", t.port)
        assert r.code == 0 and "VENT_AT" in r.out and "760" in r.out, r.out + r.err
        assert "machine `tank` runs the image uploaded in slot 1" in r.err, r.err
        # the station's page: the same refusal, and the note beside the values
        app = load(project, Diagnostics())
        ground = Station(from_app(app), project, t.port, 115200)
        ground.start()
        try:
            source = LiveSource(ground, params=app_parameters(app), tx_cap=link_plan(app).tx_cap, reload_machine="tank")

            async def talk():
                deadline = time.monotonic() + 5
                while not ground.up and time.monotonic() < deadline:
                    await asyncio.sleep(0.05)
                return await source.params_now(), await source.params_set("test", {"VENT_AT": "600"})

            now, entry = asyncio.run(talk())
        finally:
            ground.stop()
        assert now["ok"] is True and "runs the image uploaded in slot 1" in now["note"], now
        assert entry["ok"] is False and "runs the image uploaded in slot 1" in entry["words"], entry
        # reverted: the generated machine reads the store again
        r = run_fsw("machine", project, "revert", "--port", t.port)
        assert r.code == 0, r.out + r.err
        r = run_fsw("param", project, "set", "VENT_AT=600", "--port", t.port)
        assert r.code == 0, r.out + r.err
        r = run_fsw("param", project, "get", "VENT_AT", "--port", t.port)
        assert r.out.strip() == "VENT_AT = 600" and "uploaded" not in r.err, r.out + r.err
