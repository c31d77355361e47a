"""`fsw check` accepted a `[log]` whose recorder alone needs more RAM than
the board has: `before 4.9` at 50 Hz of every element of the logged rig is
a ring of 249 samples of 18 B, 4,556 B with the recorder's other buffers,
on a 2,048 B Uno; only `fsw build`, after compiling, said the firmware did
not fit. As with the state vector, a machine's locals, a window and the
transmit buffer, the recorder's RAM is now checked against the board's at
`fsw check`, at the `[log]` section, saying what takes it and what to
lower."""

from __future__ import annotations

import shutil

from conftest import ROOT, run_fsw

RIG = ROOT / "tests" / "recorder" / "logged"


def _project(tmp_path, before: str):
    proj = tmp_path / "p"
    shutil.copytree(RIG, proj)
    app = (proj / "logged.app").read_text()
    log = ("[log]\nstore eeprom\nrecord 255\nmachine logged\ntrigger Run\n"
           f"before {before}\nrate 50\nelement level\nelement count\nelement state raw\nelement time\nelement go\n")
    (proj / "logged.app").write_text(app[:app.index("[log]")] + log)
    return proj / "logged.app"


def test_a_ring_past_the_boards_ram_is_an_error_at_the_log_section(tmp_path):
    r = run_fsw("check", str(_project(tmp_path, "4.9")))
    assert r.code == 1, r.out + r.err
    text = r.out + r.err
    assert "logged.app:26:1" in text and "4,556 B of RAM" in text and "2,048 B" in text, text
    assert "before" in text


def test_one_that_fits_passes(tmp_path):
    r = run_fsw("check", str(_project(tmp_path, "0.5")))
    assert r.code == 0, r.out + r.err
