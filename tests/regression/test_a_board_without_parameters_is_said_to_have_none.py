"""A board flashed with a firmware without parameters (the same machine
with constants instead: the same link schema, so the hello passes)
answers the parameter commands UNKNOWN_OP. `fsw param` said "the target
refused PARAM_INFO: UNKNOWN_OP: unknown opcode", the words of the
protocol, not of the situation. Now it says the target's firmware has no
parameters and what to do, in `fsw param` and the station's page alike."""

from __future__ import annotations

import asyncio
import shutil
import time
from pathlib import Path

from conftest import run_fsw
from support.linkfw import PtyTarget, needs_cxx

pytestmark = needs_cxx()
RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"
CONSTANTS = """[local]
F32  OPEN_AT  = 800
U16  HOLD_MS  = 500
I8   TRIM     = -3
bool VENT     = true
"""


def test_fsw_param_and_the_station_say_the_firmware_has_no_parameters(tmp_path):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.params import app_parameters
    from fswkit.autocode.schema import link_plan
    from fswkit.ground.station import Station
    from fswkit.link.layout import from_app
    from fswkit.target.build import load
    from fswkit.web.source import LiveSource

    other = tmp_path / "other"
    shutil.copytree(RIG, other)
    sm = other / "tuned.sm"
    text = sm.read_text()
    start, end = text.index("[parameters]"), text.index("[Safe]")
    sm.write_text(text[:start] + CONSTANTS + "\n" + text[end:])
    out = tmp_path / "out"
    r = run_fsw("build", str(other), "--board", "native", "--out", str(out))
    assert r.code == 0, r.err
    with PtyTarget(out / "tuned", "--eeprom", str(tmp_path / "e.bin")) as t:
        time.sleep(0.2)
        r = run_fsw("param", str(RIG), "list", "--port", t.port)
        assert r.code == 1, r.out + r.err
        assert "the target's firmware has no parameters" in r.err and "build and flash it again" in r.err, r.err
        assert "UNKNOWN_OP: unknown opcode" not in r.err, r.err
        app = load(str(RIG), Diagnostics())
        ground = Station(from_app(app), str(RIG), t.port, 115200)
        ground.start()
        try:
            source = LiveSource(ground, params=app_parameters(app), tx_cap=link_plan(app).tx_cap)

            async def talk():
                deadline = time.monotonic() + 5
                while not ground.up and time.monotonic() < deadline:
                    await asyncio.sleep(0.05)
                return await source.params_now()

            now = asyncio.run(talk())
        finally:
            ground.stop()
        assert now["ok"] is False and "the target's firmware has no parameters" in now["words"], now
