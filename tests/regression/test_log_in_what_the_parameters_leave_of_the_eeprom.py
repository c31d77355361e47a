"""The flight recorder keeps its records in the EEPROM after the
parameters' banks, and the firmware needs room for two records there
(fsw_log.h `log_config_ok`). examples/rocket with enough parameters that
the banks took 994 of the Uno's 1,024 B passed `fsw check`, and `fsw build`
then failed with "internal error: the generated code did not build ...
a defect of fswkit" (a static assertion on the recorder's tables); with
`[reload]` the check asked for one record's room, not two. `fsw check` now
says where the EEPROM went, at the `record` (or `store`) line."""

from __future__ import annotations

import shutil

from conftest import EXAMPLES


def rocket(tmp_path, params: int, app_extra: str = ""):
    shutil.copytree(EXAMPLES / "rocket", tmp_path / "rocket")
    sm = tmp_path / "rocket" / "mission.sm"
    text = sm.read_text()
    assert "[parameters]\n" in text
    sm.write_text(text.replace("[parameters]\n", "[parameters]\n" + "".join(
        f"U64 EXTRA{i} = 1 @min 0 @max 2\n" for i in range(params))))
    app = tmp_path / "rocket" / "rocket.app"
    app.write_text(app.read_text() + app_extra)
    return app


def test_banks_that_leave_no_two_records_are_refused_at_the_record(fsw, tmp_path):
    # 6 parameters of 4 B and 58 of 8 B: 2 x (9 + 488) = 994 B; 30 B left
    r = fsw("check", str(rocket(tmp_path, 58)))
    assert r.code == 1, r.out
    assert "rocket.app:40:9:" in r.err
    assert "the parameters' banks take 994 B of the uno's 1,024 B of EEPROM, which leaves 30 B" in r.err
    assert "room for 0 records of 64 B, and the recorder needs 2 at least" in r.err
    assert "Traceback" not in r.err


def test_room_for_one_record_is_refused(fsw, tmp_path):
    # 2 x (9 + 24 + 8 n) <= 1024 - 64 and > 1024 - 128: n = 53 leaves 1024 - 914 = 110 B
    r = fsw("check", str(rocket(tmp_path, 53)))
    assert r.code == 1, r.out
    assert "leaves 110 B: room for 1 record of 64 B" in r.err


def test_room_for_two_records_is_accepted_and_builds_two_slots(fsw, tmp_path):
    from fswkit.autocode.app import load_app
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.recorder import plan

    app = rocket(tmp_path, 49)  # 2 x (9 + 24 + 392) = 850 B: 174 B left, two records
    r = fsw("check", str(app))
    assert r.code == 0, r.err
    p = plan(load_app(str(app), Diagnostics()))
    assert (p.base, p.slots) == (850, 2)


RELOAD = """
[reload]
machine  nav
size     {size}
"""


def test_reload_slots_leave_two_records_or_are_refused(fsw, tmp_path):
    # the rocket's banks take 2 x (9 + 24) = 66 B; slots 2 x (header + size)
    from fswkit.autocode.reloadcheck import eeprom_bytes

    size = next(s for s in range(64, 1024, 2) if 66 + eeprom_bytes(s) + 64 > 1024 - 64)  # room for one record
    assert 66 + eeprom_bytes(size) + 64 <= 1024
    r = fsw("check", str(rocket(tmp_path, 0, RELOAD.format(size=size))))
    assert r.code == 1, r.out
    assert "the recorder at least 2 records of 64 B" in r.err
    r = fsw("check", str(rocket(tmp_path / "b", 0, RELOAD.format(size=size - 64))))
    assert r.code == 0, r.err
