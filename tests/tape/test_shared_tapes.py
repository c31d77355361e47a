"""The eight real flights of ../shared/flights/ read through fswkit.tape:
each tape and its truth file parse, and the tape agrees with its truth
(span, pad pressure, unsmoothed apogee, max accel). Skipped, with a message,
only when the folder is absent (a user's clone)."""

from __future__ import annotations

import time

import numpy as np
import pytest

from conftest import SHARED, run_fsw
from fswkit.tape import read_tape, read_truth, truth_path

FLIGHTS = SHARED / "flights"
NAMES = ("prometheus_telemega", "prometheus_telemetrum", "hedy_cats", "ndrt2020_raven", "camoes_cats",
         "genesis_cats", "lince_cats", "halcyon_cats")

pytestmark = pytest.mark.skipif(not FLIGHTS.is_dir(), reason=f"{FLIGHTS} is absent (the shared flight tapes "
                                "sit beside the repository, not in it): nothing to read")


def test_the_folder_holds_the_eight_tapes():
    assert sorted(p.stem for p in FLIGHTS.glob("*.csv")) == sorted(NAMES)


@pytest.mark.parametrize("name", NAMES)
def test_tape_agrees_with_its_truth(name):
    path = str(FLIGHTS / f"{name}.csv")
    t0 = time.perf_counter()
    tape = read_tape(path)
    seconds = time.perf_counter() - t0
    assert seconds < 5.0  # the largest (halcyon, 66k rows, 1.1 MB) reads in ~0.1 s
    truth = read_truth(truth_path(path))
    assert truth.name == name
    assert tape.sources and tape.derived and tape.flight
    assert tape.rows > 3000
    assert tape.start < 0 < tape.end
    assert tape.end == pytest.approx(truth.log_end_s, abs=0.01)
    assert "pressure_pa" in tape.columns_available() and "accel_g" in tape.columns_available()
    # pad pressure, and the unsmoothed apogee through the README's ISA formula
    assert tape.pad_pressure() == pytest.approx(truth.pad_pressure_pa, abs=0.1)
    alt = tape.altitude_agl(truth.pad_pressure_pa)
    after = tape.time >= 0
    assert np.nanmax(alt[after]) == pytest.approx(truth.raw_max_alt_m_agl, abs=0.2)
    assert truth.apogee_m_agl <= truth.raw_max_alt_m_agl + 0.1
    assert truth.apogee_band5m_from_s <= truth.apogee_s <= truth.apogee_band5m_to_s
    # accel: about +1 g on the pad, the truth's max where it is
    pad = tape.available("accel_g") & (tape.time < -0.2)
    if pad.any():
        assert np.median(tape.accel[pad]) == pytest.approx(1.0, abs=0.15)
    assert np.nanmax(tape.accel) == pytest.approx(truth.max_accel_g, abs=0.01)
    i = int(np.nanargmax(tape.accel))
    assert tape.time[i] == pytest.approx(truth.max_accel_s, abs=0.01)
    assert truth.liftoff_s == 0.0


def test_fsw_tape_show_reads_a_shared_tape_and_its_truth():
    r = run_fsw("tape", "show", str(FLIGHTS / "ndrt2020_raven.csv"))
    assert r.code == 0, r.err
    assert "rows:    3,547" in r.out and "ndrt2020_raven.truth.toml" in r.out
    assert "accel_g:" in r.out and "400.0 Hz" in r.out and "recorder_" in r.out
