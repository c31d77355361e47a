"""A tape's truth file took any number its keys hold: TOML's `nan`, `inf`
and 1e308 for the recording altimeter's own events
(`recorder_apogee_event_s = nan`, `recorder_burnout_flag_s = 1e308`) went
into `fsw sim --tape`'s event table as a 300-digit time and its
differences, and into `fsw tape show`'s events as `nan s`; an
`apogee_m_agl` of 1e308 or a `max_accel_g` of -1e308 were shown as the
truth. Every number of a truth file whose key says its unit (`_s`, `_pa`,
`_g`, `_m_agl`) now has the range of the tape column it is worked out from
(docs/tapes.md, "Ranges"; an altitude above the pad is within the ISA
troposphere's 12 km), and one beyond it, or not a finite number, is an
error at its line of the truth file."""

from __future__ import annotations

import shutil

import pytest

from conftest import EXAMPLES, SHARED, run_fsw
from fswkit.tape import TapeError, read_truth

NDRT = SHARED / "flights" / "ndrt2020_raven.csv"
pytestmark = pytest.mark.skipif(not NDRT.exists(), reason=f"{NDRT} is not there")


def truth_with(tmp_path, key: str, value: str):
    tape = tmp_path / "f.csv"
    shutil.copy(NDRT, tape)
    lines = NDRT.with_name("ndrt2020_raven.truth.toml").read_text().splitlines(keepends=True)
    at = next((i for i, x in enumerate(lines) if x.startswith(f"{key} =")), None)
    if at is None:
        lines.append(f"{key} = {value}\n")
        at = len(lines) - 1
    else:
        lines[at] = f"{key} = {value}\n"
    (tmp_path / "f.truth.toml").write_text("".join(lines))
    return tape, tmp_path / "f.truth.toml", at + 1


@pytest.mark.parametrize("key, value, said", [
    ("recorder_apogee_event_s", "nan", "must be a finite number, found nan"),
    ("recorder_burnout_flag_s", "1e308", "-3,600 to 3,600 s"),
    ("recorder_main_event_alt_m_agl", "-inf", "must be a finite number, found -inf"),
    ("apogee_m_agl", "1e308", "-12,000 to 12,000 m"),
    ("max_accel_g", "-1e308", "-250 to 250 g"),
    ("log_end_s", "7200", "-3,600 to 3,600 s"),
    ("pad_pressure_pa", "1e9", "1,000 to 120,000 Pa"),
])
def test_a_truth_number_beyond_its_range_is_refused_at_its_line(tmp_path, key, value, said):
    tape, truth, line = truth_with(tmp_path, key, value)
    with pytest.raises(TapeError) as e:
        read_truth(str(truth))
    assert str(e.value).startswith(f"{truth}:{line}:1: `{key}`"), str(e.value)
    assert said in str(e.value), str(e.value)
    r = run_fsw("tape", "show", str(tape))
    assert r.code == 1 and f"truth:   {truth}:{line}:1: `{key}`" in r.out, r.out


def test_a_replay_refuses_a_recorder_time_that_is_no_flights(tmp_path):
    tape, truth, line = truth_with(tmp_path, "recorder_burnout_flag_s", "1e308")
    r = run_fsw("sim", str(EXAMPLES / "hpr"), "--tape", str(tape), "--out", str(tmp_path / "out"))
    assert r.code != 0 and f"{truth}:{line}:1: `recorder_burnout_flag_s`" in r.err, r.err
    assert not (tmp_path / "out").exists()


def test_the_shared_truth_files_are_within_every_range():
    for p in sorted((SHARED / "flights").glob("*.truth.toml")):
        read_truth(str(p))
