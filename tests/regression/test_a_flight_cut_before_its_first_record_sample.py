"""A closed-loop flight that ended after the recorder began its flight but
before the first sample was written (a short `max_s`, a replayed study
run) crashed `fsw sim` in the recorder's report: `fsw: internal error:
IndexError` (it read the first sample of an empty flight). The report now
says the flight holds no sample and fails that check, and the flight's
files are written."""

from __future__ import annotations

from conftest import EXAMPLES
from support.closed_loop import needs_avr_sim

pytestmark = needs_avr_sim


def test_a_flight_cut_before_the_first_record_sample_is_reported(fsw, tmp_path):
    plant = tmp_path / "short.toml"  # launch at 3 s; the record's first sample is written later
    plant.write_text(f'extends = "{EXAMPLES / "rocket" / "plant.toml"}"\n\n[scenario]\nmax_s = 5\n')
    out = tmp_path / "out"
    r = fsw("sim", str(EXAMPLES / "rocket"), "--plant", "rocket", "--params", str(plant), "--out", str(out))
    assert "internal error" not in r.err, r.err
    assert r.code == 1, r.out + r.err  # the flight's checks fail: it was cut in coast
    assert "flight 1: no sample stored yet (1 record begun)" in r.out, r.out
    assert ("FAIL  the recorder stored the flight's samples: flight 1 holds no sample: the run ended before "
            "the first was written") in r.out, r.out
    assert (out / "summary.txt").is_file() and (out / "record.log").is_file()
