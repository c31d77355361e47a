"""The web station (`fsw ground`) lists and sets a target's parameters by
the project's table. The link's schema (the hello) does not cover the
parameters, so a board reflashed with another parameter table (here the
tests/param/tuned rig with HOLD_MS's range changed, and one with the
parameters in another order) passes the hello check; `fsw param` then
refuses on the table hash, but the station read the board's values
through the project's table (names, types and ranges that are not the
board's) and sent its SETs by the project's ids, setting a parameter the
user never named. Now the station, as `fsw param`, compares the target's
table hash and count with the project's first, and refuses to show or set
values with the same words."""

from __future__ import annotations

import asyncio
import shutil
import time
from pathlib import Path

import pytest

from conftest import run_fsw
from support.linkfw import PtyTarget, needs_cxx

pytestmark = needs_cxx()
RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"


def _variant(tmp_path, edit) -> Path:
    rig = tmp_path / "other"
    shutil.copytree(RIG, rig)
    sm = rig / "tuned.sm"
    sm.write_text(edit(sm.read_text()))
    out = tmp_path / "out"
    r = run_fsw("build", str(rig), "--board", "native", "--out", str(out))
    assert r.code == 0, r.err
    return out / "tuned"


def _swap(text: str) -> str:  # TRIM before HOLD_MS: ids 1 and 2 change places
    lines = text.splitlines(keepends=True)
    i = next(n for n, line in enumerate(lines) if line.startswith("U16  HOLD_MS"))
    lines[i], lines[i + 1] = lines[i + 1], lines[i]
    return "".join(lines)


@pytest.mark.parametrize("edit", [lambda t: t.replace("@max 60000", "@max 50000"), _swap],
                         ids=["another-range", "another-order"])
def test_the_station_refuses_a_board_of_another_parameter_table(tmp_path, edit):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.params import app_parameters
    from fswkit.autocode.schema import link_plan
    from fswkit.ground.station import Station
    from fswkit.link.layout import from_app
    from fswkit.target.build import load
    from fswkit.web.source import LiveSource

    exe = _variant(tmp_path, edit)
    app = load(str(RIG), Diagnostics())
    with PtyTarget(exe, "--eeprom", str(tmp_path / "e.bin")) as target:
        time.sleep(0.2)
        ground = Station(from_app(app), str(RIG), target.port, 115200)
        ground.start()
        try:
            source = LiveSource(ground, params=app_parameters(app), tx_cap=link_plan(app).tx_cap)

            async def talk():
                await source.start()
                try:
                    deadline = time.monotonic() + 5
                    while not ground.up and time.monotonic() < deadline:  # the hello came: the schema is the same
                        await asyncio.sleep(0.05)
                    assert ground.up, ground.note
                    return await source.params_now(), await source.params_set("test", {"TRIM": "7"})
                finally:
                    await source.stop()

            now, entry = asyncio.run(talk())
        finally:
            ground.stop()
        assert now["ok"] is False and "params" not in now, now
        assert "parameter table" in now["words"] and "build and flash it again" in now["words"], now
        assert entry["ok"] is False and "parameter table" in entry["words"], entry
        # nothing was set: the board's values are its defaults still (read by the board's own table)
        r = run_fsw("param", str(tmp_path / "other"), "list", "--port", target.port)
        assert r.code == 0, r.err
        assert "(defaults; live CRC" in r.out and "unsaved" not in r.out, r.out
