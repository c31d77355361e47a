"""A generated machine's state functions wrote and read the state vector's
and the locals' bools and integers at their absolute addresses: on AVR an
`lds`/`sts` of 4 bytes of flash a byte, the rocket's mission about 40 of
them. A machine whose state functions access 8 bytes or more of one area
so now takes it through a pointer register (`fsw::by_pointer` in step(),
an argument `svp` or `locp` to each state function, which LTO inlines into
step()): a displacement of 2 bytes each, 66 B of the mission's flash (for
3.5 us of its step a cycle: the registers kept). The step does what it did (the differential tests hold it to the
interpreter bit for bit); a machine with fewer such accesses (the rocket's
nav) is emitted as before, where the pointer register's keeping would cost
more than it saves. The arguments have their own names (no shadowing of
`sv`, `loc`) and are unnamed in a state function that does not use them,
so the code compiles warning-free under -Wall -Wextra -Wshadow, its
`leave()` (an uploaded machine taking over) included."""

from __future__ import annotations

import re
import subprocess

from conftest import EXAMPLES, ROOT, run_fsw
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.emit.machine import emit_machine
from fswkit.autocode.emit.sv import emit_sv
from fswkit.autocode.numeric import F32MODE
from fswkit.autocode.project import load_machine

SV = "[S]\nU64 time\nU32 state\nbool a\nbool b\nbool c\nU8 n\nF32 x\n"
SM = """[state_vector]
U64 time @alias G
U32 state @alias S
bool a
bool b
bool c
U8 n
F32 x

[local]
U32 k = 0

[One]
.entry
    a = true
    b = false
.step
    c = not c
    n = n + 1
    k = k + n
    x > 3: -> Two
.exit
    a = false

[Two]
.entry
    x = 0
.exit
    b = true
"""


def test_the_rockets_mission_takes_its_state_vector_through_a_pointer(tmp_path):
    r = run_fsw("gen", str(EXAMPLES / "rocket"), "--out", str(tmp_path))
    assert r.code == 0, r.err
    mission = (tmp_path / "mission.gen.cpp").read_text()
    assert "    uint8_t* const svp = fsw::by_pointer(sv);" in mission
    assert re.search(r"^uint8_t s1_entry\(uint8_t\* const svp, uint8_t\* const\) \{$", mission, re.M), mission
    assert "fsw::store_bool(svp + E_onPad, true);" in mission
    assert "fsw::store_bool(sv + E_" not in mission  # every direct access through the pointer
    assert "    uint8_t* const locp = fsw::by_pointer(loc);" in mission  # burnTime (U32), high (bool)
    assert re.search(r"^uint8_t s4_step\(uint8_t\* const svp, uint8_t\* const locp\) \{$", mission, re.M), mission
    assert "next = s1_entry(svp, locp);" in mission
    nav = (tmp_path / "nav.gen.cpp").read_text()  # two bool reads: as before
    assert "by_pointer" not in nav and "uint8_t s1_step() {" in nav


def _emitted(tmp_path, sm: str) -> dict:
    """The binary32 C++ of machine `sm` over SV, written into tmp_path: file name -> text."""
    (tmp_path / "m.sm").write_text(sm)
    (tmp_path / "m.sv").write_text(SV)
    diags = Diagnostics()
    m = load_machine(str(tmp_path / "m.sm"), diags, str(tmp_path / "m.sv"))
    assert m is not None, diags.render()
    files = dict(emit_sv(m.sv))
    files.update(emit_machine(m, F32MODE, leave=True))
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    return files


def _compiles_without_warnings(tmp_path) -> None:
    # compiled to an object in the test's folder, named relative to it: as
    # strict as a syntax-only run, and a compiler cache (ccache) keeps it
    r = subprocess.run(["g++", "-std=gnu++11", "-c", "-Wall", "-Wextra", "-Wshadow", "-Werror",
                        "-DFSW_REAL_IS_FLOAT=1", "-DFSW_F64_SOFT=1", f"-I{ROOT / 'firmware' / 'src'}",
                        "-I.", "m.gen.cpp", "-o", "m.gen.o"], capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 0, r.stderr


def test_the_pointer_form_compiles_without_warnings(tmp_path):
    code = _emitted(tmp_path, SM)["m.gen.cpp"]
    assert "uint8_t* const svp = fsw::by_pointer(sv);" in code and "uint8_t* const locp = fsw::by_pointer(loc);" in code
    assert re.search(r"^uint8_t s2_entry\(uint8_t\* const svp, uint8_t\* const\) \{$", code, re.M)  # x = 0: svp
    assert re.search(r"^void s2_exit\(uint8_t\* const svp, uint8_t\* const\) \{$", code, re.M)
    assert "case S_One: s1_exit(sv, loc); break;" in code  # leave(): the areas themselves
    _compiles_without_warnings(tmp_path)


def test_a_machine_whose_step_calls_no_state_function_takes_no_pointer(tmp_path):
    # its one state has only an .exit, which step() never runs (leave() does): a pointer taken
    # in step() would be an unused variable, which -Werror builds refuse
    sm = SM[:SM.index("[One]")] + "[One]\n.exit\n    a = true\n    b = false\n    k = k + n\n    k = k + 2\n"
    assert "by_pointer" not in _emitted(tmp_path, sm)["m.gen.cpp"]
    _compiles_without_warnings(tmp_path)
