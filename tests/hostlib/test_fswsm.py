"""libfswsm (firmware/host/fswsm.h) and its Python binding (fswkit.sm):
the runtime's VM as a host library with a C ABI.

1. Every example machine through the library against the kit's interpreter
   (fswkit.run), binary64 and binary32: every example state script replayed
   in lockstep (the state, T and every byte of the state vector after each
   step), and each machine driven by random inputs through the element API.
2. A C program compiled with gcc against the header and the library.
3. Every refusal: its exception, code and words, and no crash.
4. Several machines at once, of both evaluation types, in one process.
5. The tank's test-stand script (examples/tank/stand.py) runs.
Also `fsw compile --layout` and concurrent builds of the library."""

from __future__ import annotations

import math
import os
import random
import shutil
import struct
import subprocess
import sys
import textwrap

import pytest

from conftest import EXAMPLES, ROOT
from fswkit import sm as S
from fswkit.autocode import model as M
from fswkit.autocode import vmverify as V
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.emit.bytecode import compile_machine
from fswkit.autocode.numeric import REALS
from fswkit.autocode.project import load_machine, load_script
from fswkit.run import script as RS
from fswkit.run.interp import ERR_TIME, OK, MachineRun

pytestmark = pytest.mark.skipif(shutil.which(os.environ.get("CXX", "g++")) is None, reason="no host C++ compiler")

MODES = ("f64", "f32")
FORMATS = {"I8": "<b", "I16": "<h", "I32": "<i", "I64": "<q", "U8": "<B", "U16": "<H", "U32": "<I", "U64": "<Q",
           "F32": "<f", "F64": "<d", "bool": "<B"}


def _example_machines() -> dict:
    """{MACHINE.sm: its checked machine} of every example machine `fsw
    compile` accepts: with the .sv beside it, or else the one its folder's
    application names (examples/stand: `fsw compile tank_700.sm --sv
    ../tank/tank.sv`)."""
    import re

    out = {}
    for p in sorted(EXAMPLES.rglob("*.sm")):
        if "build" in p.relative_to(EXAMPLES).parts:
            continue
        svs = [None] + [p.parent / m.group(1) for app in sorted(p.parent.glob("*.app"))
                        for m in re.finditer(r"^state_vector\s+(\S+)", app.read_text(), re.M)]
        for sv in svs:
            m = load_machine(str(p), Diagnostics(), None if sv is None else str(sv))
            if m is not None:
                out[p] = m
                break
    return out


MACHINES = _example_machines()
KNOWN = {"hpr/mission", "hpr/nav", "rocket/mission", "rocket/nav", "tank/tank"}
SCRIPTS = sorted(EXAMPLES.rglob("*.ss"))
TANK = EXAMPLES / "tank" / "tank.sm"


def _pack(t: M.ElemType, x) -> bytes:
    return struct.pack(FORMATS[t.name], int(x) if t.kind != "float" else x)


def _element_vars(m: M.Machine) -> list[tuple[M.Var, int]]:
    """The machine's elements with their byte offsets in the state vector."""
    return [(v, m.sv.find(v.name).offset) for v in m.vars if v.kind == M.ELEMENT]


# ---- 1. the library against the interpreter ------------------------------------------------

class _Lockstep(MachineRun):
    """The interpreter's machine, with the library's stepping beside it:
    before each step the state vector the script wrote is copied into the
    library's (its bytes, exactly), after it every element, the state and T
    are compared. fswkit.run.script.run drives it as it drives its own."""

    def __init__(self, lib: S.Machine, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.lib = lib
        self.elems = sorted(_element_vars(self.m), key=lambda e: e[1])
        # the machine's elements in one struct over the state vector (the
        # elements it does not list are padding: zero here and there)
        fmt, at = "<", 0
        for var, off in self.elems:
            fmt += f"{off - at}x{FORMATS[var.type.name][1]}"
            at = off + var.type.size
        self.struct = struct.Struct(fmt)
        self.idx = [var.index for var, _ in self.elems]
        self.diff: str | None = None
        self.steps = 0

    def step(self) -> int:
        v, sv, lib = self.v, self.lib.sv, self.lib
        self.struct.pack_into(sv, 0, *[v[i] for i in self.idx])
        try:
            lib.step()
            code = OK
        except S.StepTimeError:
            code = ERR_TIME
        r = super().step()
        self.steps += 1
        if self.diff is not None:
            return r
        if r != code:
            self.diff = f"step {self.steps}: interpreter {r}, library {code}"
        elif r == OK:
            want = bytearray(sv)
            self.struct.pack_into(want, 0, *[v[i] for i in self.idx])
            if want == sv and lib.state_id == self.state + 1 and lib.T == v[self.m.t]:
                return r
            bad = [f"{var.display}: interpreter {v[var.index]!r}, library "
                   f"{struct.unpack(FORMATS[var.type.name], bytes(sv[off:off + var.type.size]))[0]!r}"
                   for var, off in self.elems if _pack(var.type, v[var.index]) != bytes(sv[off:off + var.type.size])]
            if lib.state_id != self.state + 1:
                bad.append(f"state: interpreter {self.m.states[self.state].name}, library {lib.state}")
            if lib.T != v[self.m.t]:
                bad.append(f"T: interpreter {v[self.m.t]}, library {lib.T}")
            if bad:
                self.diff = f"step {self.steps}: " + "; ".join(bad)
        return r


@pytest.mark.parametrize("mode", MODES)
def test_example_scripts_step_as_the_interpreter(monkeypatch, mode):
    real = REALS[mode]
    ran = []
    for path in SCRIPTS:
        s = load_script(str(path), Diagnostics(), real=real)
        if s is None:  # a script written to fail its checks
            continue
        lib = S.Machine.from_model(s.machine, mode)
        lib.reset(s.init_state + 1)
        made = []

        def lockstep(*args, **kwargs):
            made.append(_Lockstep(lib, *args, **kwargs))
            return made[-1]

        monkeypatch.setattr(RS, "MachineRun", lockstep)
        got = RS.run(s, real)
        monkeypatch.undo()
        assert made[0].diff is None, f"{path.relative_to(ROOT)} ({mode}): {made[0].diff}"
        assert made[0].steps == got.steps > 0  # the library stepped with the interpreter at every step
        assert got.passed == (path.name != "tank_counter.ss")  # the one example script written to fail
        ran.append((path, os.path.splitext(os.path.basename(s.machine.path))[0], got.steps))
        lib.close()
    # every example machine was run, and the flights ran for thousands of steps
    assert {f"{p.parent.name}/{m}" for p, m, _ in ran} >= KNOWN
    assert len(ran) >= 14 and sum(n for _, _, n in ran) > 50_000, ran


def _next_value(rng: random.Random, t: M.ElemType, x):
    """An input's next value: mostly a random walk (so thresholds are
    crossed and states reached), sometimes a value at the edge of its type
    (NaN, infinities, -0, an integer type's extremes)."""
    if t.kind == "bool":
        return (not x) if rng.random() < 0.2 else bool(x)
    edge = rng.random() < 0.05
    if t.kind != "float":
        if edge:
            return rng.choice((t.lo, t.hi, 0))
        return min(t.hi, max(t.lo, int(x) + rng.randint(-3, 3)))
    if edge:
        y = rng.choice((math.nan, math.inf, -math.inf, -0.0, 1e30, -1e30, 5e-324))
    else:
        y = (x if x == x and abs(x) < 1e6 else rng.uniform(0, 1000)) + rng.gauss(0, 25)
    return struct.unpack("<f", struct.pack("<f", y))[0] if t.size == 4 else y


@pytest.mark.parametrize("mode", MODES)
def test_example_machines_driven_by_random_inputs(mode):
    """Each example machine, its read-only elements written through the
    element API (NaN and infinities included; the interpreter reads a NaN as
    the 0 it is, spec 4.5) at random steps of G, three times from a reset:
    what the machine writes, read back through the element API, is the
    interpreter's every step."""
    real = REALS[mode]
    total, states = 0, {}
    for path, m in MACHINES.items():
        # a stream of its own: another example machine's inputs change no other's draws
        rng = random.Random(f"20261128 {path.parent.name}/{path.stem}")
        lib = S.Machine.from_model(m, mode)
        run = MachineRun(m, real)
        inputs = [v for v in m.vars if v.kind == M.ELEMENT and v.read_only and v.index not in (m.g, m.s)]
        outputs = [v for v in m.vars if v.kind == M.ELEMENT and v not in inputs and v.index != m.g]
        g = 0
        visited = set()
        for n in range(300):
            if n % 100 == 0:  # three runs from a reset, each from its own inputs
                if n:  # the machine as loaded: its locals and windows reset, its state vector zero
                    lib.reset(1)
                    lib.sv[:] = bytes(len(lib.sv))
                    run = MachineRun(m, real)
                now = {v.index: (rng.uniform(400, 900) if v.type.kind == "float" else 0) for v in inputs}
                for v in inputs:  # every run starts from its inputs, not from a zero state vector
                    x = now[v.index]
                    if v.type.kind == "float" and v.type.size == 4:
                        x = now[v.index] = struct.unpack("<f", struct.pack("<f", x))[0]
                    lib[v.name] = x
                    run.v[v.index] = x
            for v in rng.sample(inputs, k=rng.randint(0, len(inputs))):
                x = now[v.index] = _next_value(rng, v.type, now[v.index])
                lib[v.name] = x
                run.v[v.index] = 0.0 if x != x else x
            g += rng.choice((1, 10, 100, 1000, 123457))
            lib.step(g)
            run.v[m.g] = g
            assert run.step() == OK
            for v in outputs:
                got, want = lib[v.name], run.v[v.index]
                assert _pack(v.type, got) == _pack(v.type, want), \
                    f"{path.name} ({mode}) step {n + 1}: {v.display}: interpreter {want!r}, library {got!r}"
                if v.type.kind == "float":  # the double view is the same value
                    assert struct.pack("<d", lib.get_double(v.name)) == struct.pack("<d", float(got))
            assert lib.state_id == run.state + 1 and lib.T == run.v[m.t], f"{path.name} ({mode}) step {n + 1}"
            visited.add(lib.state)
            total += 1
        lib.close()
        states[f"{path.parent.name}/{path.stem}"] = visited
    assert total == 300 * len(MACHINES) and set(states) >= KNOWN
    assert len(states["tank/tank"]) >= 2 and len(states["rocket/mission"]) >= 3, states  # the inputs move them


# ---- fsw compile --layout and the C program ------------------------------------------------------

@pytest.fixture(scope="module")
def tank_files(tmp_path_factory):
    """tank.fsm and tank.layout in both evaluation types, as `fsw compile` writes them."""
    from fswkit.testing.runner import run_fsw

    d = tmp_path_factory.mktemp("tank")
    out = {}
    for mode in MODES:
        image, layout = d / f"tank{mode}.fsm", d / f"tank{mode}.layout"
        r = run_fsw("compile", str(TANK), "--real", mode, "-o", str(image), "--layout", str(layout))
        assert r.code == 0, r.err
        assert f"{layout}: the layout of 4 elements (21 bytes) and 3 states" in r.err
        out[mode] = (image, layout)
    return out


def test_fsw_compile_writes_the_layout(tank_files, tmp_path, fsw):
    image, layout = tank_files["f64"]
    m = load_machine(str(TANK), Diagnostics())
    text = layout.read_text()
    assert text == S.layout_text(m, 64, str(image))
    lines = [ln for ln in text.splitlines() if not ln.startswith("#")]
    assert lines[:5] == ["fswsm-layout 1", "real 64", f"schema 0x{V.layout_of(m.sv).schema:08x}", "size 21",
                         "elements 4"]
    assert "element 0 time U64 0 8 G" in lines and "element 2 tankPressure F64 12 8" in lines
    assert lines[-4:] == ["states 3", "state 1 TankVentControl", "state 2 Abort", "state 3 Idle"]
    assert image.read_bytes() == compile_machine(m, REALS["f64"])
    # refused before anything is written
    r = fsw("compile", str(TANK), "-o", str(tmp_path / "a.fsm"), "--layout", str(tmp_path / "no" / "a.layout"))
    assert r.code == 1 and "no such folder" in r.err and not (tmp_path / "a.fsm").exists()
    r = fsw("compile", str(TANK), "-o", "-", "--layout", "-")
    assert r.code == 2 and "the layout needs a file" in r.err
    r = fsw("compile", str(TANK), "-o", str(tmp_path / "a.fsm"), "--layout", str(tmp_path / "a.fsm"))
    assert r.code == 2 and "the image's own path" in r.err
    r = fsw("compile", str(TANK), "-o", str(tmp_path / "a.fsm"), "--layout", str(TANK))
    assert r.code == 1 and "would overwrite an input" in r.err and TANK.read_text().startswith("[state_vector]")
    # the image's path spelt another way (a relative path, a link) is the image's own path: it was written
    # with the layout's text over the image, exit 0
    import os

    (tmp_path / "link.fsm").symlink_to(tmp_path / "b.fsm")
    for out, lay in ((str(tmp_path / "b.fsm"), os.path.relpath(tmp_path / "b.fsm")),
                     (str(tmp_path / "b.fsm"), str(tmp_path / "link.fsm"))):
        r = fsw("compile", str(TANK), "-o", out, "--layout", lay)
        assert r.code == 2 and "the image's own path" in r.err, r.err
    # a layout that cannot be written leaves the image's path as it was (docs/cli.md)
    keep = tmp_path / "keep.fsm"
    keep.write_bytes(b"FSMB OLD")  # an image of before (another file is not replaced unasked at all)
    r = fsw("compile", str(TANK), "-o", str(keep), "--layout", "/dev/full")
    assert r.code == 1 and "cannot write /dev/full" in r.err and keep.read_bytes() == b"FSMB OLD", r.err


C_STAND = r"""
#include <stdio.h>
#include <string.h>
#include "fswsm.h"

#define CHECK(call) do { int rc_ = (call); if (rc_ != FSWSM_OK) { \
    printf("%s: %s (%s)\n", #call, fswsm_error_name(rc_), fswsm_last_error(h)); return 1; } } while (0)

int main(int argc, char** argv) {
    uint8_t sv[64];
    uint32_t p, g, valve, states, size, id;
    double open;
    int k, rc;
    fswsm* h = fswsm_create();
    if (argc != 3 || h == NULL) return 2;
    memset(sv, 0, sizeof sv);
    CHECK(fswsm_layout_file(h, argv[2]));
    CHECK(fswsm_load_image_file(h, argv[1]));
    CHECK(fswsm_sv_size(h, &size));
    CHECK(fswsm_state_count(h, &states));
    printf("R %d bytes, %u states, sv %u bytes\n", fswsm_real_bytes(), states, size);
    CHECK(fswsm_bind(h, sv, sizeof sv));
    CHECK(fswsm_element_index(h, "G", &g));
    CHECK(fswsm_element_index(h, "tankPressure", &p));
    CHECK(fswsm_element_index(h, "valveOpen", &valve));
    for (k = 0; k < 8; ++k) {
        CHECK(fswsm_set(h, g, 10.0 * k));
        CHECK(fswsm_set(h, p, 770.0 + 10.0 * k));
        CHECK(fswsm_step(h));
        CHECK(fswsm_get(h, valve, &open));
        CHECK(fswsm_state(h, &id));
        printf("step %d pressure %.0f valve %.0f state %s\n", k, 770.0 + 10.0 * k, open, fswsm_state_name(h, id));
    }
    rc = fswsm_step(h);  /* G did not increase */
    printf("again: %d %s\n", rc, fswsm_error_name(rc));
    rc = fswsm_load_image(h, (const uint8_t*)"not an image at all, not at all", 31);
    printf("garbage: %s reason %d (%s)\n", fswsm_error_name(rc), fswsm_reason(h), fswsm_reason_text(fswsm_reason(h)));
    rc = fswsm_bind(h, sv, 3);
    printf("small: %s: %s\n", fswsm_error_name(rc), fswsm_last_error(h));
    rc = fswsm_get(h, 99, &open);
    printf("index: %s: %s\n", fswsm_error_name(rc), fswsm_last_error(h));
    printf("null: %s\n", fswsm_error_name(fswsm_step(NULL)));
    fswsm_destroy(h);
    fswsm_destroy(NULL);
    return 0;
}
"""


@pytest.mark.skipif(shutil.which("gcc") is None, reason="no gcc")
@pytest.mark.parametrize("mode", MODES)
def test_a_c_program_uses_the_library(tank_files, tmp_path, mode):
    lib = S.library_path(mode)
    src = tmp_path / "stand.c"
    src.write_text(C_STAND)
    exe = tmp_path / "stand"
    libdir = os.path.dirname(lib)
    r = subprocess.run(["gcc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-I", S.HOST, str(src),
                        "-L", libdir, f"-lfswsm{S.REAL_BITS[mode]}", f"-Wl,-rpath,{libdir}", "-o", str(exe)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    image, layout = tank_files[mode]
    r = subprocess.run([str(exe), str(image), str(layout)], capture_output=True, text=True, timeout=30)
    assert r.returncode == 0, r.stdout + r.stderr
    out = r.stdout.splitlines()
    assert out[0] == f"R {S.REAL_BITS[mode] // 8} bytes, 3 states, sv 21 bytes"
    assert out[1:9] == [
        "step 0 pressure 770 valve 0 state TankVentControl",
        "step 1 pressure 780 valve 1 state TankVentControl",
        "step 2 pressure 790 valve 1 state TankVentControl",
        "step 3 pressure 800 valve 1 state TankVentControl",
        "step 4 pressure 810 valve 1 state TankVentControl",
        "step 5 pressure 820 valve 1 state TankVentControl",
        "step 6 pressure 830 valve 1 state Abort",  # not below P_AbortThreshold (825): .exit opens the valve
        "step 7 pressure 840 valve 1 state Abort",
    ]
    assert out[9] == "again: 1 FSWSM_STEP_TIME"
    assert out[10] == "garbage: FSWSM_E_VERIFY reason 1 (bad magic (not a state-machine image))"
    assert out[11] == "small: FSWSM_E_SMALL: a buffer of 3 bytes: the state vector has 21"
    assert out[12] == "index: FSWSM_E_INDEX: element index 99 out of range: the layout has 4 elements (0..3)"
    assert out[13] == "null: FSWSM_E_ARG"


# ---- 3. refusals ----------------------------------------------------------------------------------

def _raises(exc, fn, *args, code=None, words=None):
    with pytest.raises(exc) as e:
        fn(*args)
    if code is not None:
        assert e.value.code == code, e.value
    if words is not None:
        assert words in str(e.value), str(e.value)
    return e.value


def test_bad_images_are_refused_with_the_verifiers_reason():
    m = load_machine(str(TANK), Diagnostics())
    image = compile_machine(m, REALS["f64"])
    lib = S.Machine.from_sm(TANK)
    for bad, reason in ((b"", V.BAD_SIZE), (b"FSMB", V.BAD_SIZE), (b"x" * 300, V.BAD_MAGIC),
                        (image[:-1], V.BAD_SIZE), (image + b"\0", V.BAD_SIZE),
                        (image[:4] + bytes((V.VERSION + 1,)) + image[5:], V.BAD_VERSION)):
        e = _raises(S.ImageRefused, lib.load_image, bad, code=S.E_VERIFY)
        assert e.reason == reason and e.reason_text == V.REASONS[reason]
        assert f"reason {reason}" in e.message and e.name == "FSWSM_E_VERIFY"
    _raises(S.SizeError, lib.load_image, image + bytes(70000), code=S.E_SIZE, words="at most 65535")
    # 300 corruptions: the library's verdict is the host verifier's, and an
    # image it accepts steps (the VM trusts what the verifier passed)
    rng = random.Random(7)
    layout = V.layout_of(m.sv)
    refused = set()
    g = 0
    for _ in range(300):
        bad = bytearray(image)
        for _ in range(rng.randint(1, 3)):
            bad[rng.randrange(len(bad))] = rng.randrange(256)
        want = V.verify(bytes(bad), layout, 8)
        try:
            lib.load_image(bytes(bad))
            got = V.OK
        except S.ImageRefused as e:
            got = e.reason
        assert got == want, bytes(bad).hex()
        if got == V.OK:
            for k in range(5):
                lib["tankPressure"] = 700.0 + 30 * k
                g += 10
                lib.step(g)
        refused.add(got)
    assert len(refused - {V.OK}) >= 6, refused
    lib.load_image(image)  # and the good one still loads after all that
    assert lib.state == "TankVentControl"


def test_the_other_evaluation_type_is_refused(tank_files):
    for mode, other in (("f64", "f32"), ("f32", "f64")):
        image, layout = tank_files[mode]
        e = _raises(S.WrongReal, S.Machine.from_image, image, layout, other, code=S.E_REAL)
        bits = S.REAL_BITS[mode]
        assert e.reason == V.BAD_REAL
        assert f"the image is binary{bits}" in e.message and f"load it with libfswsm{bits}" in e.message
        assert S.Machine.from_image(image, layout).real == mode  # by default the image's own library


def test_an_image_of_another_state_vector_is_refused(tank_files):
    image, _ = tank_files["f64"]
    rocket = load_machine(str(EXAMPLES / "rocket" / "mission.sm"), Diagnostics())
    lib = S.Machine()
    lib.load_layout_text(S.layout_text(rocket, 64))
    e = _raises(S.WrongSchema, lib.load_image, image.read_bytes(), code=S.E_SCHEMA)
    assert e.reason == V.BAD_SCHEMA and "the image is bound to state vector 0xef27b66a of 4 elements" in e.message
    tank = load_machine(str(TANK), Diagnostics())
    lay = V.layout_of(tank.sv)
    lib.set_layout(lay.elems, lay.schema ^ 1, tank.sv.size)  # the same elements, another hash
    _raises(S.WrongSchema, lib.load_image, image.read_bytes(), code=S.E_SCHEMA)
    lib.set_layout(lay.elems[:2] + ((lay.elems[2][0], 8),) + lay.elems[3:], lay.schema, tank.sv.size)
    e = _raises(S.ImageRefused, lib.load_image, image.read_bytes(), code=S.E_VERIFY)  # tankPressure made F32
    assert e.reason == V.BAD_ELEMENT


def test_buffers_indices_values_and_states_are_checked():
    lib = S.Machine.from_sm(TANK)
    _raises(S.BufferTooSmall, lib.bind, bytearray(20), code=S.E_SMALL, words="a buffer of 20 bytes: the state "
            "vector has 21")
    _raises(S.BufferTooSmall, lib.bind, bytearray(0), code=S.E_SMALL)
    big = bytearray(100)
    lib.bind(big)  # larger is fine: the state vector is its first 21 bytes
    lib["tankPressure"] = 123.5
    assert struct.unpack_from("<d", big, 12)[0] == 123.5
    for bad in (4, 99, 2 ** 32 - 1):
        _raises(S.ElementIndexError, lib.get_raw, bad, code=S.E_INDEX, words=f"element index {bad} out of range")
        _raises(S.ElementIndexError, lib.get_double, bad, code=S.E_INDEX)
        _raises(S.ElementIndexError, lib.set_double, bad, 1.0, code=S.E_INDEX)
        _raises(S.ElementIndexError, lib.__getitem__, bad, code=S.E_INDEX)
    _raises(S.ElementIndexError, lib.__getitem__, -1, code=S.E_INDEX)
    _raises(S.ElementIndexError, lib.__getitem__, 2 ** 40, code=S.E_INDEX)
    e = _raises(S.NameNotFound, lib.__getitem__, "nosuch", code=S.E_NAME, words="no element named `nosuch`")
    assert isinstance(e, KeyError)
    _raises(S.ValueNotHeld, lib.__setitem__, "valveOpen", 2, code=S.E_VALUE, words="a bool takes 0 or 1")
    _raises(S.ValueNotHeld, lib.set_double, "valveOpen", 0.5, code=S.E_VALUE)
    _raises(S.ValueNotHeld, lib.__setitem__, "S", -1, code=S.E_VALUE)
    _raises(S.ValueNotHeld, lib.__setitem__, "S", 2 ** 32, code=S.E_VALUE)
    for x in (1.5, math.nan, math.inf, 4294967296.0, -1.0):
        _raises(S.ValueNotHeld, lib.set_double, "S", x, code=S.E_VALUE, words="cannot hold")
    lib.set_double("S", 4294967295.0)
    assert lib["S"] == 4294967295
    lib.set_double("G", 2.0 ** 63)
    assert lib["G"] == 2 ** 63
    lib["tankPressure"] = math.nan  # a float element holds what it is given
    assert math.isnan(lib["tankPressure"]) and math.isnan(lib.get_double(2))
    _raises(S.SizeError, lib.set_raw, "tankPressure", b"123", code=S.E_SIZE, words="F64 of 8 bytes, not 3")
    _raises(S.SizeError, lib.set_raw, "tankPressure", b"", code=S.E_SIZE)
    for bad in (0, 4, 2 ** 32 - 1):
        _raises(S.StateError, lib.reset, bad, code=S.E_STATE, words="states 1..3")
    _raises(S.NameNotFound, lib.reset, "Nowhere", code=S.E_NAME)
    lib.reset("Idle")
    assert lib.state == "Idle" and lib.state_id == 3
    lib.step(5)
    _raises(S.StepTimeError, lib.step, 5, code=S.STEP_TIME, words="G did not increase: 5 after 5")
    _raises(S.StepTimeError, lib.step, 4, code=S.STEP_TIME)
    lib.step(6)


def test_calls_out_of_order_and_null_arguments_are_refused():
    lib = S.Machine()
    for fn, args in ((lib._lib.fswsm_step, ()), (lib._lib.fswsm_reset, (1,))):
        assert fn(lib._h, *args) == S.E_NO_IMAGE
    _raises(S.NotReady, lib.bind, bytearray(8), code=S.E_NO_LAYOUT)
    _raises(S.NotReady, getattr, lib, "sv_size", code=S.E_NO_LAYOUT, words="no layout given yet")
    _raises(S.NotReady, getattr, lib, "state", code=S.E_NO_IMAGE, words="no image loaded yet")
    _raises(S.NotReady, lib.load_image, b"FSMB", code=S.E_NO_LAYOUT)
    tank = load_machine(str(TANK), Diagnostics())
    lib.load_layout_text(S.layout_text(tank, 64))
    _raises(S.NotReady, lib.__getitem__, "valveOpen", code=S.E_NO_SV, words="no state vector bound")
    lib.load_image(compile_machine(tank, REALS["f64"]))
    _raises(S.NotReady, lib.step, None, code=S.E_NO_SV)
    c, raw = lib._lib, S.library("f64")
    assert c is raw
    import ctypes
    n, d = ctypes.c_uint32(), ctypes.c_double()
    for call in (lambda: c.fswsm_step(None), lambda: c.fswsm_reset(None, 1), lambda: c.fswsm_bind(None, None, 0),
                 lambda: c.fswsm_get(None, 0, ctypes.byref(d)), lambda: c.fswsm_get(lib._h, 0, None),
                 lambda: c.fswsm_set(None, 0, 1.0), lambda: c.fswsm_get_raw(lib._h, 0, None, 8),
                 lambda: c.fswsm_set_raw(lib._h, 0, None, 8), lambda: c.fswsm_load_image(lib._h, None, 10),
                 lambda: c.fswsm_load_image(None, b"x", 1), lambda: c.fswsm_layout_file(lib._h, None),
                 lambda: c.fswsm_layout_text(None, b""), lambda: c.fswsm_set_layout(lib._h, None, None, 3, 0, 9),
                 lambda: c.fswsm_element_count(None, ctypes.byref(n)), lambda: c.fswsm_element_count(lib._h, None),
                 lambda: c.fswsm_state(None, ctypes.byref(n)), lambda: c.fswsm_element_index(lib._h, None, None),
                 lambda: c.fswsm_time_in_state(lib._h, None), lambda: c.fswsm_state_id(lib._h, b"x", None)):
        assert call() == S.E_ARG
    c.fswsm_destroy(None)
    assert c.fswsm_element_name(None, 0) is None and c.fswsm_state_name(lib._h, 0) is None
    assert c.fswsm_state_name(lib._h, 4) is None and c.fswsm_element_name(lib._h, 4) is None
    assert c.fswsm_last_error(None) == b"a null handle"
    # every code has a name and words; every reason the docs' words
    for code in [S.OK, S.STEP_TIME, S.STEP_CONFIG] + list(range(-1, -17, -1)):
        assert c.fswsm_error_name(code).startswith(b"FSWSM_") and c.fswsm_error_text(code) != b"unknown code"
        assert code in S._ERRORS or code == S.OK
    assert c.fswsm_error_name(-99) == b"unknown" and c.fswsm_reason_text(19) == b"unknown reason"
    for reason, words in V.REASONS.items():
        assert c.fswsm_reason_text(reason).decode() == words
    assert [c.fswsm_type_name(t).decode() for t in range(11)] == list(V.TYPE_CODES)
    assert [c.fswsm_type_size(t) for t in range(12)] == list(V.TYPE_SIZES) + [0]


BAD_LAYOUTS = [
    ("", "no `fswsm-layout 1` line (an empty file, or not a layout)"),
    ("elements 1\n", "not a layout file"),
    ("fswsm-layout 2\n", "layout format 2"),
    ("fswsm-layout 1\nschema 0x1\nsize 8\nelements 1\nelement 0 time U64 1 8\n", "ends past the state vector"),
    ("fswsm-layout 1\nschema 0x1\nsize 8\nelements 1\nelement 0 time U65 0 8\n", ":5: unknown type `U65`"),
    ("fswsm-layout 1\nschema 0x1\nsize 8\nelements 1\nelement 0 time U64 0 4\n", ":5: size 4 is not a U64's 8"),
    ("fswsm-layout 1\nschema 0x1\nsize 8\nelements 2\nelement 0 time U64 0 8\n", "1 element lines, `elements 2`"),
    ("fswsm-layout 1\nschema 0x1\nsize 8\nelements 1\nelement 1 time U64 0 8\n", ":5: element index 1: expected 0"),
    ("fswsm-layout 1\nschema 0x1\nsize 8\nelements 1\nelement 0 ti-me U64 0 8\n", "`ti-me` is not a name"),
    ("fswsm-layout 1\nschema 0x1\nsize 9\nelements 2\nelement 0 t U64 0 8\nelement 1 t U8 8 1\n",
     "a second element named `t`"),
    ("fswsm-layout 1\nschema -1\nsize 8\nelements 0\n", ":2: `schema` takes a number"),
    ("fswsm-layout 1\nschema 0x100000000\n", ":2: `schema` takes a number"),
    ("fswsm-layout 1\nschema 0x1\nsize 8\nelements 0\nstates 1\nstate 2 A\n", ":6: state id 2: expected 1"),
    ("fswsm-layout 1\nschema 0x1\nsize 8\nelements 0\nbogus 1\n", ":5: unknown line `bogus`"),
    ("fswsm-layout 1\nsize 8\n", "no `schema`"),
    ("fswsm-layout 1\nschema 0x1 2 3 4 5 6 7 8 9\n", ":2: too many fields"),
    # a name and another element's alias: the C lookup and Python's found different elements
    ("fswsm-layout 1\nschema 0x1\nsize 9\nelements 2\nelement 0 t U64 0 8 G\nelement 1 v U8 8 1 t\n",
     ":6: a second element named `t`"),
    ("fswsm-layout 1\nschema 0x1\nsize 9\nelements 2\nelement 0 t U64 0 8 v\nelement 1 v U8 8 1\n",
     ":6: a second element named `v`"),
    ("fswsm-layout 1\nschema 0x1\nsize 16\nelements 2\nelement 0 t U64 0 8 G\nelement 1 v U64 4 8\n",
     "elements 0 (offset 0, 8 bytes) and 1 (offset 4) overlap"),
    ("fswsm-layout 1\nschema 0x1\nsize 16\nelements 1\nelement 0 t F64 0 8 G\n", ":5: `t` aliased G is a F64: G is a U64"),
    ("fswsm-layout 1\nschema 0x1\nsize 8\nelements 1\nelement 0 s U8 0 1 S\n", ":5: `s` aliased S is a U8: S is a U32"),
    ("fswsm-layout 1\nschema 0x1\nsize 8\nelements 0\nstates 0\n", ":5: `states 0`"),
]


@pytest.mark.parametrize("text, words", BAD_LAYOUTS)
def test_bad_layouts_are_refused_with_their_line(tmp_path, text, words):
    path = tmp_path / "bad.layout"
    path.write_text(text)
    lib = S.Machine()
    e = _raises(S.LayoutError, lib.load_layout_file, path, code=S.E_LAYOUT, words=words)
    assert str(path) in e.message
    _raises(S.LayoutError, lib.load_layout_text, text, code=S.E_LAYOUT, words=words)


def test_unreadable_files_and_bad_set_layout_are_refused(tmp_path):
    lib = S.Machine()
    _raises(S.FileUnreadable, lib.load_layout_file, tmp_path / "none.layout", code=S.E_FILE,
            words="No such file or directory")
    _raises(S.FileUnreadable, lib.load_layout_file, tmp_path, code=S.E_FILE)
    (tmp_path / "nul.layout").write_bytes(b"fswsm-layout 1\n\0")
    _raises(S.LayoutError, lib.load_layout_file, tmp_path / "nul.layout", code=S.E_LAYOUT, words="a NUL byte")
    _raises(S.FileUnreadable, S.Machine.from_image, tmp_path / "none.fsm", tmp_path / "none.layout", "f64")
    (tmp_path / "tank.layout").write_text(S.layout_text(load_machine(str(TANK), Diagnostics()), 64))
    _raises(S.FileUnreadable, S.Machine.from_image, tmp_path / "none.fsm", tmp_path / "tank.layout",
            code=S.E_FILE, words="none.fsm")
    _raises(S.LayoutError, lib.set_layout, ((0, 11),), 0, 8, code=S.E_LAYOUT, words="unknown type code 11")
    _raises(S.LayoutError, lib.set_layout, ((0, 7), (8, 9)), 0, 15, code=S.E_LAYOUT,
            words="element 1 (F64 at offset 8) ends past the state vector's 15 bytes")
    with pytest.raises(S.ConfigError, match="tank_typo.sm:18:9"):
        S.Machine.from_sm(EXAMPLES / "tank" / "tank_typo.sm")
    # numbers the C types would have wrapped without a word
    _raises(S.LayoutError, lib.set_layout, ((0, 7 + 256),), 0, 8, code=S.E_LAYOUT, words="a type code 0..255")
    _raises(S.LayoutError, lib.set_layout, ((0x10000, 4),), 0, 8, code=S.E_LAYOUT, words="an offset is 0..65535")
    _raises(S.LayoutError, lib.set_layout, ((0, 7),), 2**32, 8, code=S.E_LAYOUT, words="schema 4294967296")
    _raises(S.LayoutError, lib.set_layout, ((0, 7),), 0, 2**32 + 8, code=S.E_LAYOUT, words="sv_size 4294967304")
    # a FIFO (or a device) as a layout or an image: it waited for a writer for good
    import os

    os.mkfifo(tmp_path / "fifo")
    _raises(S.FileUnreadable, lib.load_layout_file, tmp_path / "fifo", code=S.E_FILE, words="not a regular file")
    _raises(S.FileUnreadable, S.Machine.from_image, tmp_path / "fifo", tmp_path / "tank.layout", code=S.E_FILE,
            words="not a regular file")


def test_a_layout_that_is_not_the_images_is_refused(tank_files, tmp_path):
    """The layout's state names and its G and S aliases are the image's:
    a layout of another machine or another state vector that passed the
    verifier named states the image has not and wrote G into another
    element."""
    image, layout = tank_files["f64"]
    text = layout.read_text()
    bad = tmp_path / "bad.layout"
    five = text.replace("states 3", "states 5") + "state 4 D\nstate 5 E\n"
    bad.write_text(five)
    _raises(S.LayoutError, S.Machine.from_image, image, bad, code=S.E_LAYOUT,
            words="the layout names 5 states and the image has 3")
    # G on another U64 of the same offsets and types: a layout of another state vector with the same schema
    assert "element 0 time U64 0 8 G" in text and "element 1 state U32 8 4 S" in text
    sv = tmp_path / "two.sv"
    sv.write_text("[Sv]\nU64 time\nU32 state\nU64 other\n")
    sm = tmp_path / "two.sm"
    sm.write_text("[state_vector]\nU64 time @alias G\nU32 state @alias S\nU64 other\n\n[A]\n.step\n    other = T\n")
    from fswkit.testing.runner import run_fsw

    r = run_fsw("compile", str(sm), "-o", str(tmp_path / "two.fsm"), "--layout", str(tmp_path / "two.layout"))
    assert r.code == 0, r.err
    two = (tmp_path / "two.layout").read_text()
    moved = two.replace("element 0 time U64 0 8 G", "element 0 time U64 0 8").replace(
        "element 2 other U64 12 8", "element 2 other U64 12 8 G")
    assert moved != two
    bad.write_text(moved)
    _raises(S.LayoutError, S.Machine.from_image, tmp_path / "two.fsm", bad, code=S.E_LAYOUT,
            words="the layout calls element 2 G, and the image's G is element 0")
    assert S.Machine.from_image(tmp_path / "two.fsm", tmp_path / "two.layout").names == ["time", "state", "other"]


def test_a_layout_of_the_other_evaluation_type_is_refused(tank_files):
    """An f64 image with the layout `fsw compile --real f32` wrote (its
    `real 32` line): the layout of another compile of the machine."""
    image, layout32 = tank_files["f64"][0], tank_files["f32"][1]
    e = _raises(S.WrongReal, S.Machine.from_image, image, layout32, code=S.E_REAL,
                words="the layout is of binary32 images, and this library is libfswsm64")
    assert e.reason == 0


def test_names_with_a_nul_and_state_ids_past_32_bits_are_refused(tank_files):
    m = S.Machine.from_image(*tank_files["f64"])
    _raises(S.NameNotFound, m.__getitem__, "tankPressure\0junk", code=S.E_NAME, words="a name holds no NUL")
    _raises(S.StateError, m.reset, "Idle\0zzz", code=S.E_STATE, words="a name holds no NUL")
    _raises(S.StateError, m.reset, 2**32 + 3, code=S.E_STATE, words="state 4294967299")
    m.reset("Idle")
    assert m.state == "Idle"


# ---- 4. several machines at once -----------------------------------------------------------------

def test_several_machines_at_once():
    """Two tanks in each evaluation type and the rocket's mission, stepped
    in turn with different inputs in one process: each follows its own
    interpreter, and none sees another's state."""
    tank = load_machine(str(TANK), Diagnostics())
    rocket = load_machine(str(EXAMPLES / "rocket" / "mission.sm"), Diagnostics())
    runs = []
    for m, mode, bias in ((tank, "f64", 0.0), (tank, "f64", 40.0), (tank, "f32", 20.0), (tank, "f32", 60.0),
                          (rocket, "f64", 0.0)):
        runs.append((m, S.Machine.from_model(m, mode), MachineRun(m, REALS[mode]), bias))
    assert len({id(lib._lib) for _, lib, _, _ in runs}) == 2  # both libraries loaded
    for n in range(1, 200):
        for m, lib, run, bias in runs:
            if m is tank:
                p = 760.0 + bias + 0.5 * n
                lib["tankPressure"] = p
                run.v[m.var("tankPressure").index] = p
            lib.step(10 * n)
            run.v[m.g] = 10 * n
            assert run.step() == OK
            for v, off in _element_vars(m):
                assert _pack(v.type, run.v[v.index]) == bytes(lib.sv[off:off + v.type.size]), (n, v.display)
            assert lib.state_id == run.state + 1
    assert [lib.state for _, lib, _, _ in runs] == ["Abort", "Abort", "Abort", "Abort", "Safe"]
    # the steps at which each tank aborted differ with its input: they are separate machines
    assert len({lib.T for m, lib, _, _ in runs if m is tank}) == 4
    for _, lib, _, _ in runs:
        lib.close()


# ---- 5. the stand, and the builds ------------------------------------------------------------------

@pytest.mark.parametrize("mode", MODES)
def test_the_tank_stand_script_runs(mode):
    S.library_path(mode)  # built here, so the script finds it in the cache
    r = subprocess.run([sys.executable, str(EXAMPLES / "tank" / "stand.py"), "--real", mode],
                       capture_output=True, text=True, timeout=120, cwd=str(ROOT))
    assert r.returncode == 0, r.stdout + r.stderr
    rows = [ln.split() for ln in r.stdout.splitlines()[2:-1]]
    assert len(rows) == 25 and [int(row[1]) for row in rows] == [10 * k for k in range(25)]
    valve = {float(row[2]): row[4] for row in rows if row[3] == "TankVentControl"}
    assert all((v == "OPEN") == (p > 775) for p, v in valve.items()), valve
    opened = [row[2] for row in rows if "opened" in row]
    closed = [row[2] for row in rows if "closed" in row]
    assert opened == ["776.0", "778.0"] and closed == ["771.0"]
    assert rows[20][3] == "TankVentControl" and rows[21][:4] == ["21", "210", "826.0", "Abort"]
    assert r.stdout.splitlines()[-1] == "final state: Abort"


def test_the_build_command_prints_the_libraries_and_the_header(capsys):
    assert S.main(["build", "f32", "f64"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out == [S.library_path("f32"), S.library_path("f64"), S.HEADER]
    assert out[0].endswith("/libfswsm32.so") and out[2].endswith(os.path.join("firmware", "host", "fswsm.h"))
    assert S.main(["build", "f16"]) == 2 and "usage:" in capsys.readouterr().err


def test_concurrent_builds_from_an_empty_cache(tmp_path):
    """Two processes building the same library into an empty cache at once
    both end with a library that loads and runs."""
    code = textwrap.dedent(f"""
        from fswkit.sm import Machine
        m = Machine.from_sm({str(TANK)!r})
        m["tankPressure"] = 780.0
        m.step(1)
        print(m["valveOpen"], m.state)
    """)
    env = dict(os.environ, FSW_CACHE_DIR=str(tmp_path / "cache"))
    procs = [subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True, env=env) for _ in range(2)]
    outs = [p.communicate(timeout=300) for p in procs]
    for p, (out, err) in zip(procs, outs):
        assert p.returncode == 0, err
        assert out == "True TankVentControl\n"
    built = list((tmp_path / "cache" / "native").iterdir())
    assert [p.name for p in built[0].iterdir()] == ["libfswsm64.so"] and len(built) == 1, built
