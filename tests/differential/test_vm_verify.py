"""The host verifier (autocode/vmverify.py) and the runtime's vm_verify
(firmware/src/fsw_vm.cpp) give the same reason code for the same image:
compiled images of generated machines, each corrupted many ways (a byte
changed, a byte dropped or added, the image cut short), go through both.
The corruptions reach every reason of the format, so a rule one side
checks and the other does not shows up as a disagreement.

FSW_VM_VERIFY_CASES (default 12 machines) sets how many machines."""

from __future__ import annotations

import os
import random
import shlex
import shutil
import struct
import subprocess

import pytest

import gen_programs as gp
import harness as H
from fswkit.autocode import vmverify as V
from fswkit.autocode.emit.bytecode import compile_machine
from fswkit.autocode.numeric import REALS
from fswkit.run import native

CASES = int(os.environ.get("FSW_VM_VERIFY_CASES", "12"))
SEED = int(os.environ.get("FSW_DIFF_SEED", "1"))
PER_IMAGE = 400

needs_cxx = pytest.mark.skipif(shutil.which(shlex.split(H.default_cxx())[0]) is None,
                               reason="no host C++ compiler")

DRIVER = r"""
#include <stdio.h>
#include "fswkit.h"
// stdin: schema (u32), count (u16), count x (offset u16, type u8), then
// images as (length u16, bytes) to the end; stdout: one reason a line.
static uint8_t buf[65536];
static fsw::VmElem elems[4096];
static bool get(void* p, size_t n) { return fread(p, 1, n, stdin) == n; }
#ifdef FEATURES  // a board's VM (fsw_vm.h); without, psl_native.cpp's: every feature
extern const uint16_t fsw::vm_features = FEATURES;
#endif
int main() {
    uint32_t schema; uint16_t count;
    if (!get(&schema, 4) || !get(&count, 2) || count > 4096) return 2;
    for (uint16_t k = 0; k < count; ++k) {
        if (!get(&elems[k].off, 2) || !get(&elems[k].type, 1)) return 2;
    }
    const fsw::VmLayout layout = {elems, count, schema};
    uint16_t len;
    while (get(&len, 2)) {
        if (!get(buf, len)) return 2;
        printf("%d\n", static_cast<int>(fsw::vm_verify(buf, len, layout, 0xFFFFFFFFUL)));
    }
    return 0;
}
"""


def _driver(tmp, real, features: int = V.ALL_FEATURES) -> str:
    """The driver linked with the runtime's verifier. Each object is kept in
    the differential tests' cache (harness._compile_cached: keyed by the
    runtime's files, the source and the flags), so a warm run links
    only (it compiled the runtime four times, 5 s of CPU, every run)."""
    cxx = H.default_cxx()
    fl = H.flags(real, "-O1")
    defs = [] if features == V.ALL_FEATURES else [f"-DFEATURES={features}"]  # the driver's alone reads it
    rt_key = H._runtime_hash()
    objs = [H._compile_cached(DRIVER, "verify_driver.cpp", fl + defs, [], rt_key, tmp, cxx)]
    for name in H.RUNTIME_SOURCES + ("fsw_vm.cpp",):
        with open(os.path.join(native.RUNTIME, name)) as f:
            objs.append(H._compile_cached(f.read(), "rt_" + name, fl, [native.RUNTIME], rt_key, tmp, cxx))
    exe = os.path.join(tmp, f"verify_{real.name}")
    r = subprocess.run(shlex.split(cxx) + objs + ["-o", exe], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-4000:]
    return exe


def _corruptions(im: bytes, rnd: random.Random) -> list[bytes]:
    out = []
    hot = [4, 5, 6, 7, 12, 14, 16, 18, 19, 20, 22, 24, 26]
    for _ in range(PER_IMAGE):
        b = bytearray(im)
        how = rnd.random()
        if how < 0.15:
            b[rnd.choice(hot)] = rnd.randrange(256)
        elif how < 0.75:
            code = len(im) - struct.unpack_from("<H", im, 26)[0]
            at = rnd.randrange(code, len(im)) if rnd.random() < 0.8 else rnd.randrange(len(im))
            b[at] = rnd.choice((rnd.randrange(256), rnd.randrange(0x20), b[at] ^ 1, 0))
        elif how < 0.85:
            del b[rnd.randrange(len(b))]
        elif how < 0.95:
            b.insert(rnd.randrange(len(b)), rnd.randrange(0x20))
        else:
            b = b[:rnd.randrange(len(b))]
        out.append(bytes(b))
    return out


# A board's VM with F64 values, roll_avg and roll_max only (refusing F32
# locals and the other windows), beside libfswsm's with every feature.
FEW = V.FEAT_F64 | 1 << V.WINDOW_FUNCS["avg"] | 1 << V.WINDOW_FUNCS["max"]


@needs_cxx
@pytest.mark.parametrize("features", [V.ALL_FEATURES, FEW], ids=["all", "few"])
@pytest.mark.parametrize("mode", ["f64", "f32"])
def test_host_and_runtime_verifiers_agree(tmp_path, mode, features):
    real = REALS[mode]
    exe = _driver(str(tmp_path), real, features)
    rnd = random.Random(SEED)
    seen: dict[int, int] = {}
    for c in gp.cases(SEED, CASES):
        s, _ = H.load(c)
        m = s.machine
        layout = V.layout_of(m.sv)
        im = compile_machine(m, real)
        images = [im, im[:5] + bytes([12 - real.bits // 8]) + im[6:]] + _corruptions(im, rnd)
        data = bytearray(struct.pack("<IH", layout.schema, len(layout.elems)))
        for off, t in layout.elems:
            data += struct.pack("<HB", off, t)
        for b in images:
            data += struct.pack("<H", len(b)) + b
        r = subprocess.run([exe], input=bytes(data), capture_output=True, timeout=120)
        assert r.returncode == 0, r.stderr[-2000:]
        got = [int(x) for x in r.stdout.split()]
        assert len(got) == len(images)
        for b, c_code in zip(images, got):
            py = V.verify(b, layout, real.bits // 8, features=features)
            assert py == c_code, (f"case {c.index}: host verifier {py} ({V.REASONS[py]}), runtime {c_code} "
                                  f"({V.REASONS.get(c_code)}) for image {b.hex()}")
            seen[py] = seen.get(py, 0) + 1
        assert got[0] in ((V.OK,) if features == V.ALL_FEATURES else (V.OK, V.NO_FEATURE)) and got[1] == V.BAD_REAL
    if features != V.ALL_FEATURES:
        assert seen.get(V.NO_FEATURE), seen
        return
    # Every reason but the RAM check (the host verifier leaves RAM to the board)
    # and nesting (which needs more pending jumps than these machines hold).
    missing = set(range(17)) - set(seen) - {V.NO_RAM, V.TOO_NESTED}  # 17, the mask, is no image's: the board's
    assert not missing, f"no corruption reached reasons {sorted(missing)}: {seen}"


def test_nesting_limit_is_the_runtimes():
    """A machine of 16 nested `if`s compiles and verifies; the verifier with
    fewer pending jumps allowed refuses it with TOO_NESTED."""
    from fswkit.autocode import model as M

    c = gp.case(SEED, 0)
    s, _ = H.load(c)
    m = s.machine
    x = next(v for v in m.vars if v.kind == M.ELEMENT and v.type.kind == "float")
    body: tuple = ()
    for k in range(V.VM_PENDING):
        body = (M.If(M.Ref(x.index, 1, 1), body, (), 1, 1),)
    st = m.states[0]
    import dataclasses
    m2 = dataclasses.replace(m, states=(dataclasses.replace(st, step=body),) + m.states[1:])
    im = compile_machine(m2, REALS["f64"])
    layout = V.layout_of(m.sv)
    assert V.verify(im, layout, 8) == V.OK
    assert V.verify(im, layout, 8, pending=V.VM_PENDING - 1) == V.TOO_NESTED
