"""Differential on the board: a sample of the generated machines + scripts
(the first FSW_DIFF_AVR_CASES of test_generated.py's run, default 40) built
for an ATmega2560 and run under simavr, binary32 with avr-libc's and
libgcc's own float code, against the interpreter in binary32 mode: same
per-step trace, same ending, steps and asserts.

avr-libc's float division is not always correctly rounded when the quotient
is subnormal (below 2^-126): test_avr_float_library pins that down on fixed
operands, and a sample case whose interpreter run divides into that range is
the only kind allowed to differ (docs/differential.md)."""

from __future__ import annotations

import os
import random
import struct
import subprocess
import time
from concurrent.futures import ThreadPoolExecutor
from fractions import Fraction

import pytest

import avr_sim as A
import gen_programs as gp
import harness as H
from fswkit.autocode.numeric import f32

AVR_CASES = int(os.environ.get("FSW_DIFF_AVR_CASES", "40"))
SEED = int(os.environ.get("FSW_DIFF_SEED", "1"))
PER_ELF = 20  # RAM: each case's state vector, locals and windows are static

missing = A.available()
pytestmark = pytest.mark.skipif(missing is not None, reason=f"AVR toolchain or simavr missing: {missing}")

TINY = A.TINY  # the smallest normal binary32


def test_generated_cases_on_simavr(tmp_path, monkeypatch):
    t0 = time.monotonic()
    cases = gp.cases(SEED, AVR_CASES)
    loaded = [(c, *H.load(c)) for c in cases]
    with ThreadPoolExecutor(H.JOBS) as pool:
        outcomes, sizes = A.run_sample(str(tmp_path), loaded, pool, PER_ELF)
    built = time.monotonic() - t0
    r = A.compare(loaded, outcomes, str(tmp_path), monkeypatch)
    assert not r.bad, "\n\n".join(f"=== case {c.index} (binary32, simavr): {d}\n{c.repro()}" for c, d in r.bad[:3])
    print(f"\nsimavr: {len(loaded)} cases ({'; '.join(sizes)}); {r.dividing} divide into the subnormal range, "
          f"{len(r.documented)} of them differ; {time.monotonic() - t0:.1f}s ({built:.1f}s building and simulating)")


# ---- the float library itself ---------------------------------------------------------

PROBE = r"""
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/pgmspace.h>
#include <avr/sleep.h>
#include <stdint.h>
#include <string.h>
#include "pairs.h"
static void out(const void* p, uint8_t n) {
    const uint8_t* b = (const uint8_t*)p;
    for (uint8_t i = 0; i < n; ++i) { while (!(UCSR0A & (1 << UDRE0))) {} UDR0 = b[i]; }
}
static float as_float(uint32_t u) { float x; memcpy(&x, &u, 4); return x; }
int main() {
    UBRR0 = 0; UCSR0A = 1 << U2X0; UCSR0B = 1 << TXEN0; UCSR0C = 3 << UCSZ00;
    for (uint16_t i = 0; i < NPAIRS; ++i) {
        volatile float a = as_float(pgm_read_dword(&kPairs[i][0]));
        volatile float b = as_float(pgm_read_dword(&kPairs[i][1]));
        const float r[4] = {a + b, a - b, a * b, a / b};
        const uint8_t c = (uint8_t)((a < b) | ((a == b) << 1) | ((a > b) << 2));
        out(r, 16);
        out(&c, 1);
    }
    const uint8_t z[2] = {'Z', 'Z'};
    out(z, 2);
    cli(); sleep_enable(); sleep_cpu();
}
"""


def _probe_pairs() -> list[tuple[int, int]]:
    """Operand bit patterns: specials, random ones, and pairs whose product
    or quotient lands in or near the subnormal range."""
    r = random.Random(2024)
    special = [0x00000000, 0x80000000, 0x00000001, 0x80000001, 0x007FFFFF, 0x00400000, 0x00800000, 0x00800001,
               0x3F800000, 0x3F800001, 0x3F7FFFFF, 0x40400000, 0x3DCCCCCD, 0x7F7FFFFF, 0xFF7FFFFF, 0x7F800000,
               0xFF800000, 0x7FC00000, 0x4B800000, 0x4B800001, 0x4B7FFFFF, 0x34000000, 0x33800000, 0x3F000000]
    pairs = [(a, b) for a in special for b in special]
    for i in range(3800 - len(pairs)):
        if i % 3 == 0:
            pairs.append((r.getrandbits(32) & 0xFF7FFFFF, r.getrandbits(32) & 0xFF7FFFFF))
            continue
        ea = r.randint(1, 120)
        eb = 127 - ea + r.randint(-26, 1) if i % 3 == 1 else ea + 127 - r.randint(-25, 1)
        mb = r.getrandbits(23) if r.random() < 0.6 else r.choice((0, 1 << 22, (1 << 23) - 1, 1))
        pairs.append(((r.getrandbits(1) << 31) | (ea << 23) | r.getrandbits(23),
                      (max(1, min(254, eb)) << 23) | mb))
    return pairs


def _f(u: int) -> float:
    return struct.unpack("<f", struct.pack("<I", u))[0]


def _bits(x: float) -> int:
    return struct.unpack("<I", struct.pack("<f", x))[0]


def _exact(u: int) -> Fraction:
    e, m = (u >> 23) & 0xFF, u & 0x7FFFFF
    v = Fraction(m if e == 0 else m | 0x800000) * Fraction(2) ** ((e or 1) - 150)
    return -v if u >> 31 else v


def test_avr_float_library(tmp_path):
    """avr-libc's +, -, *, / and comparisons against correctly rounded
    binary32 on 3,800 operand pairs: all identical, except quotients below
    2^-126, which come out at most one unit toward zero too small."""
    pairs = _probe_pairs()
    (tmp_path / "pairs.h").write_text(
        f"#define NPAIRS {len(pairs)}\nstatic const uint32_t kPairs[][2] PROGMEM = {{\n"
        + ",\n".join(f"{{0x{a:08x}UL, 0x{b:08x}UL}}" for a, b in pairs) + "};\n")
    (tmp_path / "probe.cpp").write_text(PROBE)
    elf = tmp_path / "probe.elf"
    subprocess.run([A.AVR_CXX, "-mmcu=" + A.MCU, "-Os", "-std=gnu++11", "-I", str(tmp_path),
                    str(tmp_path / "probe.cpp"), "-o", str(elf)], check=True, capture_output=True)
    out = tmp_path / "probe.bin"
    A.run_uart(str(elf), str(out), sim_s=60, wall=60)
    data = out.read_bytes()
    assert len(data) == 17 * len(pairs) + 2 and data.endswith(b"ZZ")
    wrong, subnormal_quotients, off = {}, 0, []
    for i, (ua, ub) in enumerate(pairs):
        got = struct.unpack_from("<4IB", data, 17 * i)
        a, b = _f(ua), _f(ub)
        finite = (ua >> 23) & 0xFF != 0xFF and (ub >> 23) & 0xFF != 0xFF
        sub = finite and ub & 0x7FFFFFFF != 0 and 0 < abs(_exact(ua) / _exact(ub)) < Fraction(TINY)
        subnormal_quotients += sub
        # the correctly rounded results, from the host's IEEE arithmetic
        want = [f32(a + b), f32(a - b), f32(a * b), None]
        if b != 0 and a == a:
            want[3] = f32(a / b) if abs(a) != float("inf") or abs(b) != float("inf") else float("nan")
        for k, (g, w) in enumerate(zip(got[:4], want)):
            if w is None or w != w:  # NaN or division by zero: any NaN/inf the library gives
                continue
            if g == _bits(w):
                continue
            if k == 3 and sub:
                off.append(g - _bits(w))
                continue
            wrong.setdefault("+-*/"[k], []).append((hex(ua), hex(ub), hex(g), hex(_bits(w))))
        c = (a < b) | ((a == b) << 1) | ((a > b) << 2)
        if got[4] != c:
            wrong.setdefault("compare", []).append((hex(ua), hex(ub), got[4], c))
    assert not wrong, wrong
    # Subnormal quotients: most right, a few one unit toward zero (the
    # magnitude's bit pattern one lower, whatever the sign).
    assert subnormal_quotients > 1000
    assert 0 < len(off) < subnormal_quotients // 20, (len(off), subnormal_quotients)
    assert set(off) == {-1}, off
