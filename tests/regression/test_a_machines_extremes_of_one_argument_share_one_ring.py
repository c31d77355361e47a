"""The rocket's mission arms on `roll_min(accel, 5) > LAUNCH_G and
roll_max(accel, 5) < PINNED_G`: two windows of the same samples, each
with a deque of its own (values, sequence numbers and four indices: 29 B
each, 58 of the core rocket's RAM). Now the roll_min, roll_max and
roll_range windows of one argument and one N up to 16 that keep more than
one extreme (two windows or more, or a roll_range) share one ring of the
last N samples (`fsw::RollMinMaxN`, 22 B here), each extreme found by a
scan of the N samples where it is read: the same values bit for bit
(tests/firmware/test_window.cpp holds them equal to the windows of their
own on samples with zeros of both signs, infinities and NaNs; the
differential tests and the flights' checks are unchanged). A lone
roll_min or roll_max, and a window of more samples, keep their deques."""

from __future__ import annotations

import re

from conftest import run_fsw
from support.configs import example_copy


def _mission(proj, tmp_path) -> str:
    r = run_fsw("gen", str(proj), "--out", str(tmp_path / "gen"))
    assert r.code == 0, r.out + r.err
    return (tmp_path / "gen" / "mission.gen.cpp").read_text()


def test_the_rockets_arming_windows_share_one_ring(tmp_path):
    cpp = _mission(example_copy("rocket", tmp_path), tmp_path)
    assert re.search(r"fsw::RollMinMaxN<5> (win\.)?w0;", cpp + "\n" + (tmp_path / "gen" / "mission.gen.h").read_text())
    assert "RollMinN" not in cpp and "RollMaxN" not in cpp
    assert "w0.least() > " in cpp and "w0.greatest() < 15.0f" in cpp, cpp  # LAUNCH_G is a parameter
    assert len(re.findall(r"w0\.push\(", cpp)) == 1 and not re.search(r"w1\.", cpp), cpp


def test_a_lone_extreme_and_a_long_window_keep_their_deques(tmp_path):
    proj = example_copy("rocket", tmp_path)
    sm = proj / "mission.sm"
    text = sm.read_text()
    assert "roll_max(accel, 5)" in text
    sm.write_text(text.replace("roll_max(accel, 5)", "roll_max(accel, 17)"))
    cpp = _mission(proj, tmp_path) + (tmp_path / "gen" / "mission.gen.h").read_text()
    assert re.search(r"fsw::RollMinN<5> (win\.)?w0;", cpp) and re.search(r"fsw::RollMaxN<17> (win\.)?w1;", cpp)
    assert "RollMinMaxN" not in cpp
