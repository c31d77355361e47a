"""An AVR writes its EEPROM a byte in 3.4 ms: 294 B/s. A `[log]` of raw
elements at 100 Hz (14 B a sample: about 1,500 B/s) passed `fsw check`,
and `fsw sim` too, whose simulated EEPROM writes at once: on the board the
RAM ring overflows and most samples are dropped, found only after a
flight. The byte rate a log needs at its highest rate (a record's samples
at their usual size, with its header and tail) is now compared with the
EEPROM's at `fsw check`: a warning at the fastest `rate`, with the figures
and what to change. The rigs and examples, well within it, stay quiet."""

from __future__ import annotations

import shutil

from conftest import ROOT, run_fsw

RIG = ROOT / "tests" / "recorder" / "logged"


def _check(tmp_path, log: str):
    proj = tmp_path / "p"
    shutil.copytree(RIG, proj)
    app = (proj / "logged.app").read_text()
    (proj / "logged.app").write_text(app[:app.index("[log]")] + log)
    return run_fsw("check", str(proj / "logged.app"))


def test_raw_elements_at_100_hz_are_a_warning_at_the_rate(tmp_path):
    r = _check(tmp_path, "[log]\nstore eeprom\nrecord 64\nmachine logged\ntrigger Run\nrate 100\nrate 0 Done\n"
                         "element level\nelement count\nelement time\n")
    text = r.out + r.err
    assert r.code == 0 and "1 warning" in text, text
    assert "logged.app:30:6" in text and "294 B/s" in text and "dropped" in text, text
    assert run_fsw("check", "--strict", str(tmp_path / "p" / "logged.app")).code != 0


def test_the_rig_as_it_is_stays_quiet(tmp_path):
    r = run_fsw("check", str(RIG / "logged.app"))
    assert r.code == 0 and "0 warnings" in r.out + r.err, r.out + r.err


def test_spi_nor_is_not_held_to_the_eeproms_rate(tmp_path):
    r = run_fsw("check", str(ROOT / "tests" / "recorder" / "spi" / "spi.app"))
    assert r.code == 0 and "0 warnings" in r.out + r.err, r.out + r.err
