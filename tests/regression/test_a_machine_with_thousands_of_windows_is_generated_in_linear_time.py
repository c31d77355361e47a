"""`fsw gen` of a machine with thousands of rolling windows takes time in
proportion to the machine, not to its square. The comment on each window
the generated code declares (the `roll_*` calls it serves) searched every
window of the machine for each: 16 million tests for the 4,000 windows of
`tools/bench.py`'s 2,000-state machine, a second of its 2.2 s `fsw gen`.
Now the windows are grouped by the one that holds them in one pass, and
the code is the same byte for byte."""

from __future__ import annotations

import time

from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.emit.machine import emit_machine
from fswkit.autocode.numeric import F32MODE
from fswkit.autocode.project import load_machine


def _machine(folder, states: int):
    """A ring of `states` states, each reading two windows of its own
    (roll_avg: never kept in a shared ring) and two it shares with every
    other state (roll_min and roll_max of one argument and one size)."""
    (folder / "w.sv").write_text("[Sensors]\nU64 time\nU32 state\nF32 p\n[Effectors]\nbool v\n")
    lines = ["[state_vector]", "U64 time @alias G", "U32 state @alias S", "F32 p @read_only", "bool v"]
    for i in range(states):
        lines += [f"[S{i}]", ".step",
                  f"    v = roll_avg(p, {2 + i % 5}) > roll_avg(p, {3 + i % 7}) and roll_min(p, 4) < roll_max(p, 4)",
                  f"    T > {10 + i}: -> S{(i + 1) % states}"]
    path = folder / "w.sm"
    path.write_text("\n".join(lines) + "\n")
    d = Diagnostics()
    m = load_machine(str(path), d)
    assert m is not None, d.render()
    assert len(m.windows) == 4 * states
    return m


def _seconds(m) -> float:
    t = time.process_time()
    files = emit_machine(m, F32MODE)
    took = time.process_time() - t
    assert "roll_min" in files["w.gen.cpp"]
    return took


def test_the_code_of_4_times_the_windows_takes_about_4_times_as_long(tmp_path):
    (tmp_path / "small").mkdir()
    (tmp_path / "large").mkdir()
    small = _machine(tmp_path / "small", 250)
    large = _machine(tmp_path / "large", 1000)
    t_small = min(_seconds(small) for _ in range(3))
    t_large = min(_seconds(large) for _ in range(2))
    # linear: about 4 times as long; the search of every window for each: about 16 times
    assert t_large <= 8 * max(t_small, 0.005), (t_small, t_large)


def test_each_window_says_the_calls_it_serves(tmp_path):
    m = _machine(tmp_path, 3)
    h = emit_machine(m, F32MODE)["w.gen.cpp"]
    declared = [line.strip() for line in h.split("\n") if line.startswith("fsw::Roll")]
    # each roll_avg its own window; the six roll_min and roll_max calls one ring
    assert declared == [
        "fsw::RollAvgN<2> w0;  // w.sm:8 roll_avg",
        "fsw::RollAvgN<3> w1;  // w.sm:8 roll_avg",
        "fsw::RollMinMaxN<4> w2;  // w.sm:8 roll_min, w.sm:8 roll_max, w.sm:12 roll_min, w.sm:12 roll_max, "
        "w.sm:16 roll_min, w.sm:16 roll_max",
        "fsw::RollAvgN<3> w4;  // w.sm:12 roll_avg",
        "fsw::RollAvgN<4> w5;  // w.sm:12 roll_avg",
        "fsw::RollAvgN<4> w8;  // w.sm:16 roll_avg",
        "fsw::RollAvgN<5> w9;  // w.sm:16 roll_avg",
    ], declared
