"""A generated inputs task converted every analog input at every run: a
float multiplication and addition, about 260 AVR cycles an input, the
rocket's four 66 us of its 100 Hz cycle's sense step. Most runs the count
is the one before (an igniter's continuity, the barometer on the pad and
under a parachute: the noise under a count of the converter). Each input
now has a memo of its last count and value (`fsw::AnalogMemo`,
`fsw::analog_value_memo`): a count that did not change takes the value
kept, bit for bit the conversion's (tests/firmware/test_io.cpp holds the
two equal for every case; the flights' checks and the differential tests
are unchanged). Where nothing else writes an input's element (no machine
replaced at run time), the element keeps the value, and the memo is the
count alone (test_an_input_element_keeps_its_value_between_new_counts.py)."""

from __future__ import annotations

import re

from conftest import run_fsw
from support.configs import example_copy


def test_each_analog_input_converts_through_its_memo(tmp_path):
    proj = example_copy("rocket", tmp_path)
    r = run_fsw("gen", str(proj), "--out", str(tmp_path / "gen"))
    assert r.code == 0, r.out + r.err
    cpp = (tmp_path / "gen" / "app.gen.cpp").read_text()
    assert "uint16_t kAnalogInKey[4];" in cpp, cpp
    # the four in one loop over their rows, input i through key i (fsw::io_analog_inputs_kept)
    assert "fsw::io_analog_inputs_kept(kAnalogInRows, 4, kAnalogInKey, kAnalogInRaw, sv);" in cpp, cpp
    rows = re.findall(r"^    \{[^{}]*, E_(\w+)\},", cpp, re.M)
    assert rows == ["pressure", "accel", "drogueSense", "mainSense"], rows
    assert "fsw::analog_value(" not in cpp  # no input converted around its memo


def test_an_input_converted_by_a_call_of_its_own_goes_through_its_memo(tmp_path):
    proj = example_copy("rocket", tmp_path)
    sv = proj / "rocket.sv"
    sv.write_text("[options]\nlock\n\n" + sv.read_text())
    r = run_fsw("gen", str(proj), "--out", str(tmp_path / "gen"))
    assert r.code == 0, r.out + r.err
    cpp = (tmp_path / "gen" / "app.gen.cpp").read_text()
    # a state vector with `lock`: each input's write guarded, a call each, when its count is new
    calls = re.findall(r"const uint16_t n = fsw::io_analog_count\(kAnalogInRaw, (\d)\); "
                       r"if \(fsw::analog_count_new\(kAnalogInKey\[(\d)\], n\)\) "
                       r"\{ fsw::SvGuard<true> lock; fsw::write_F32\(sv \+ E_(\w+), fsw::analog_value\(n, ", cpp)
    assert calls == [("0", "0", "pressure"), ("1", "1", "accel"), ("2", "2", "drogueSense"),
                     ("3", "3", "mainSense")], calls
    assert "io_analog_inputs" not in cpp and "analog_value_memo" not in cpp
