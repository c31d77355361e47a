"""The rocket's mission in Descent tested `altitude > still + STILL_BAND or
altitude < still - STILL_BAND` every step: two float additions a step (on
AVR two library routines, about 6 µs a cycle on the demo flight, where
Descent is half of it), though `still` is written only when the state is
entered.

Now the generated code keeps `x + c`, `x - c` and `c - x` (x an F32 local
that no .step writes, c a known finite constant) that a .step reads in an
F32 slot of their own after the locals (`C_0`, ...), worked out from the
value stored at each write of x, and the step reads the slot: the same
bits (an F32 holds a binary32 sum exactly, never a NaN for a finite c) with
R binary32 only, and not in a build a script writes locals in. The slot's
initial bytes are the sum of x's initial value and c, or 0 where every
state whose step reads it writes x first in its .entry (then never read:
the rocket's locals stay in .bss). The core rocket: 402.6 -> 396.3 µs awake
a cycle, mission's step 47.8 -> 41.5 µs, +8 B of RAM, +70 B of flash."""

from __future__ import annotations

import re
import struct

from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.emit.machine import cached_sums, emit_machine
from fswkit.autocode.numeric import REALS
from fswkit.autocode.project import load_machine

from conftest import EXAMPLES

SV = "[Inputs]\nU64 time\nU32 state\nF32 a\n[Outputs]\nbool hit\n"


def _machine(tmp_path, body: str):
    (tmp_path / "m.sv").write_text(SV)
    (tmp_path / "m.sm").write_text("[state_vector]\nU64 time @alias G\nU32 state @alias S\nF32 a @read_only\n"
                                   "bool hit\n" + body)
    d = Diagnostics()
    m = load_machine(str(tmp_path / "m.sm"), d)
    assert m is not None, d.render()
    return m


def _loc_init(cpp: str) -> bytes:
    got = re.search(r"const uint8_t kLocInit\[kLocSize\] = \{([^}]*)\};", cpp)
    assert got, cpp
    return bytes(int(b) for b in got.group(1).split(","))


def test_the_rockets_descent_reads_its_band_where_still_is_written(tmp_path):
    m = load_machine(str(EXAMPLES / "rocket" / "mission.sm"), Diagnostics())
    files = emit_machine(m, REALS["f32"])
    cpp, h = files["mission.gen.cpp"], files["mission.gen.h"]
    entry = cpp[cpp.index("// [Descent] .entry"):cpp.index("// [Descent] .step")]
    step = cpp[cpp.index("// [Descent] .step"):cpp.index("// [Landed] .entry")]
    assert "fsw::write_F32(locp + C_0, (f0 + 5.0f));" in entry and "fsw::write_F32(locp + C_1, (f0 - 5.0f));" in entry
    assert "(f0 > fsw::read_F32(locp + C_0)) || (f0 < fsw::read_F32(locp + C_1))" in step, step
    assert "5.0f" not in step
    assert "C_0 = 17,  // F32: still + STILL_BAND" in h and "kLocSize = 25;" in h
    # Descent writes `still` on entry before its step reads the band: the slots start at 0 (.bss)
    assert _loc_init(cpp) == bytes(25)
    # binary64 R: an F32 slot would round the sum; none
    assert "C_0" not in emit_machine(m, REALS["f64"])["mission.gen.cpp"]


def test_a_sum_read_before_any_write_starts_at_the_initial_values_sum(tmp_path):
    m = _machine(tmp_path, "[local]\nF32 x = 0.1\nF32 K = 2\n"
                           "[A]\n.step\n    hit = a > x + K\n    a > 5: -> B\n"
                           "[B]\n.entry\n    x = a\n.step\n    hit = a < 3 - x\n")
    cpp = emit_machine(m, REALS["f32"])["m.gen.cpp"]
    assert [k[0] for k, _, _ in cached_sums(m, REALS["f32"])] == ["+", "-"]
    init = _loc_init(cpp)
    # x, then x + K read in A before any write of x: 0.1f + 2 in binary32; then 3 - x, read only
    # in B, which writes x on entry: 0
    assert init[:4] == struct.pack("<f", 0.1)
    assert init[4:8] == struct.pack("<f", struct.unpack("<f", struct.pack("<f", 0.1))[0] + 2.0)
    assert init[8:] == bytes(4)
    assert "fsw::read_F32(locp + C_0)" in cpp or "fsw::read_F32(loc + C_0)" in cpp


def test_no_slot_for_a_local_a_step_writes_nor_in_a_scriptable_build(tmp_path):
    m = _machine(tmp_path, "[local]\nF32 x = 0\n"
                           "[A]\n.step\n    x = a\n    hit = a > x + 1\n")
    assert cached_sums(m, REALS["f32"]) == []
    assert "C_0" not in emit_machine(m, REALS["f32"])["m.gen.cpp"]
    m = _machine(tmp_path, "[local]\nF32 x = 0\n"
                           "[A]\n.entry\n    x = a\n.step\n    hit = a > x + 1\n")
    assert len(cached_sums(m, REALS["f32"])) == 1
    assert cached_sums(m, REALS["f32"], scriptable=True) == []
    # a NaN or infinite constant is no finite sum: none
    m = _machine(tmp_path, "[local]\nF32 x = 0\nF32 BIG = 1e39\n"
                           "[A]\n.entry\n    x = a\n.step\n    hit = a > x + BIG\n")
    assert cached_sums(m, REALS["f32"]) == []


def test_the_generated_code_flies_the_same_as_the_interpreter(fsw, tmp_path):
    # A machine whose sums start at their initial value (read in A before any write) and are worked
    # out again at each entry of B, stepped by a script through both: the same trace in binary32.
    (tmp_path / "m.sv").write_text(SV)
    (tmp_path / "m.sm").write_text(
        "[state_vector]\nU64 time @alias G\nU32 state @alias S\nF32 a @read_only\nbool hit\n"
        "[local]\nF32 x = 0.1\nF32 K = 2.5\n"
        "[A]\n.step\n    hit = a > x + K or a < x - K\n    a > 7: -> B\n"
        "[B]\n.entry\n    x = a * 0.3\n.step\n    hit = a > x + K or a < K - x\n    a < 1: -> A\n"
        "    a > 20: -> B\n")
    (tmp_path / "m.ss").write_text(
        "[options]\ndelta_t 10\ninit_state A\nmax_steps 60\n\n[all_states]\n"
        "G == 0: a = 2.6\nG == 50: a = 2.65\nG == 100: a = 8.1\nG == 150: a = 4.4\nG == 200: a = 0.5\n"
        "G == 250: a = 30.7\nG == 300: a = 9.9\nG == 350: a = 0.25\nG == 450: @stop\n")
    a, b = tmp_path / "interp.csv", tmp_path / "native.csv"
    interp = fsw("test", "m.ss", "--real", "f32", "--trace", str(a), cwd=tmp_path)
    native = fsw("test", "m.ss", "--real", "f32", "--native", "--trace", str(b), cwd=tmp_path)
    assert interp.code in (0, 1), interp.err
    assert native.code == interp.code, native.err
    rows = a.read_text()
    assert rows.count("\n") > 10 and "1" in rows
    assert b.read_text() == rows
