"""Each analog input of a generated inputs task kept a memo of its last
count and of the value that count converts to (`fsw::AnalogMemo`, 6 bytes
of RAM an input: 24 of the core rocket's), and wrote the value into its
element at every run, although nothing else writes that element (fsw
check lets neither a machine nor the uplink write an input's element): the
element already held it. Now an application whose machines are all
generated keeps the count alone (`uint16_t` keys, `fsw::analog_count_new`,
`fsw::io_analog_inputs_kept`): a count that did not change is neither
converted nor written, and the element keeps the value, bit for bit what
the memo gave (tests/firmware/test_io.cpp). An application with machines
replaced at run time ([reload]: a bytecode image the board's verifier lets
store to any element) keeps the memo of the value, written at every run."""

from __future__ import annotations

from conftest import run_fsw
from support.configs import example_copy


def _app_cpp(proj, out):
    r = run_fsw("gen", str(proj), "--out", str(out))
    assert r.code == 0, r.out + r.err
    return (out / "app.gen.cpp").read_text()


def test_the_rocket_keeps_a_count_an_input(tmp_path):
    cpp = _app_cpp(example_copy("rocket", tmp_path), tmp_path / "gen")
    assert "uint16_t kAnalogInKey[4];" in cpp, cpp
    assert "fsw::io_analog_inputs_kept(kAnalogInRows, 4, kAnalogInKey, kAnalogInRaw, sv);" in cpp, cpp
    assert "AnalogMemo" not in cpp, cpp


def test_an_application_with_machines_replaced_at_run_time_keeps_the_values(tmp_path):
    example_copy("tank", tmp_path)  # the stand's tables are the tank's
    cpp = _app_cpp(example_copy("stand", tmp_path), tmp_path / "gen")
    assert "[reload]" in (tmp_path / "stand" / "stand.app").read_text()
    assert "fsw::AnalogMemo kAnalogInMemo[" in cpp, cpp
    assert "analog_count_new" not in cpp and "io_analog_inputs_kept" not in cpp, cpp
