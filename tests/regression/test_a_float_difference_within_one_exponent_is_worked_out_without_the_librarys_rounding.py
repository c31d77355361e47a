"""On AVR every binary32 addition and subtraction went through avr-libc's
__addsf3: both operands unpacked, the smaller one's significand aligned,
the sum rounded, and a difference's cancelled bits shifted out one at a
time (8 cycles each). The core rocket's nav subtracts pressures near each
other twice a cycle (a reading less the last one taken, the pad's pressure
less the average), 8 to 14 bits cancelled each time, and its sense task
takes 20 g off an accelerometer near 1 g: about 3 such differences a
cycle, some 190 cycles each.

Now the kit's __addsf3/__subsf3 (firmware/src/fsw_element.cpp, weak, ahead
of avr-libc's) work out the one case where nothing is left to round: signs
that differ (after the subtraction's flip) and one exponent, 24 to 254 (the
difference exact, Sterbenz's lemma, and normal), a byte then a bit at a
time; every other case is avr-libc's own path. The results are avr-libc's
bits (tests/firmware/test_float.cpp, on the simulated board: random
patterns of every kind, pairs of one exponent at its edges, pairs a few
units in the last place apart), and the core rocket's CPU awake a cycle on
the demo flight went from 413.6 to 402.6 µs (docs/runtime.md)."""

from __future__ import annotations

import re
import shutil
import subprocess

import pytest

from support.core_rocket import build_core

pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")


def test_the_core_rocket_links_the_kits_float_addition(tmp_path_factory):
    _, out = build_core(tmp_path_factory)
    elf = str(out / "rocket.elf")
    nm = subprocess.run(["avr-nm", elf], capture_output=True, text=True, check=True).stdout
    syms = {m.group(3): (m.group(2), int(m.group(1), 16)) for m in re.finditer(r"^([0-9a-f]+) (\w) (\S+)$", nm, re.M)}
    # the kit's pair (weak), __subsf3 a flip of b's sign in front of __addsf3, as avr-libc's is
    assert syms.get("__subsf3", ("", 0))[0] == "W" and syms.get("__addsf3", ("", 0))[0] == "W", nm
    assert syms["__addsf3"][1] == syms["__subsf3"][1] + 2
    # its first test (mov r26, r25: the signs and exponents compared), where avr-libc's clears r26 and r27;
    # avr-libc's __addsf3x is still what every other case runs
    dump = subprocess.run(["avr-objdump", "-d", f"--start-address=0x{syms['__addsf3'][1]:x}",
                           f"--stop-address=0x{syms['__addsf3'][1] + 4:x}", elf],
                          capture_output=True, text=True, check=True).stdout
    assert re.search(r"\bmov\s+r26, r25", dump), dump
    assert "__addsf3x" in syms, nm
