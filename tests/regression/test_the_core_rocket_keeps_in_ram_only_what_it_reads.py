"""The rocket as the 8 KB target measured it (issue 17: 640 B of RAM with
the stack; 791 + 83 B) kept bytes of RAM that nothing read, or that it
could work out from others: each task's last fault code (6 B: written at a
fault, read by nothing, sent by nothing), why each late cycle was late
(4 B: counted apart from `late`, which health frames send, and read by
nothing either), each task's countdown to its next
run (12 B: every task of the rocket runs every cycle, and then the
executor never reads it), each machine's T (16 B: always G at its last step
less G at its state's entry, both kept), and the link's copy of where its
transmit buffer is and how big (6 B: constants of its configuration in
flash). Now a task's record is its time, overruns, faults and mode (8 B),
the countdowns are an array of their own that only an application with a
task slower than every cycle has, T is worked out from the two times where
it is read, and the link reads its buffer's address and size out of its
configuration."""

from __future__ import annotations

import re
import shutil
import subprocess

import pytest

from test_the_runtime_drops_what_an_application_does_not_use import core  # noqa: F401 (the fixture)

pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or shutil.which("simavr") is None,
                                reason="gcc-avr / simavr not installed")


def _sizes(elf) -> dict[str, int]:
    """{demangled name without LTO's suffix: bytes} of the ELF's RAM symbols."""
    nm = subprocess.run(["avr-nm", "-C", "-S", str(elf)], capture_output=True, text=True, check=True).stdout
    out = {}
    for line in nm.splitlines():
        parts = line.split(maxsplit=3)
        if len(parts) == 4 and parts[2] in "bBdD":
            name = re.sub(r"\.lto_priv\.\d+$", "", parts[3])
            name = re.sub(r"^_ZN7fsw_gen12_GLOBAL__N_1\d+(\w+?)E$", r"fsw_gen::\1", name)
            out[name] = int(parts[1], 16)
    return out


def test_the_core_rocket_keeps_no_byte_it_does_not_read(core):
    sizes = _sizes(core[1] / "rocket.elf")
    # six tasks: worst_us, overruns, faults and mode each (no last fault, no countdown)
    assert sizes["fsw_gen::stats"] == 6 * 8, sizes
    assert not any("countdowns" in name for name in sizes), sizes
    # the state, its flags and the two times (no T)
    assert sizes["fsw_gen::nav::machine"] == sizes["fsw_gen::mission::machine"] == 23, sizes
    # the executor's record without its two counters of why cycles were late
    assert sizes["fsw_gen::ex"] == 20 - 4, sizes
    # the link's record without its transmit buffer's address, size and room for a control frame,
    # nor the bytes of the buffer handed to the UART (it sends them from the buffer: console_send),
    # nor a receive buffer (it reads a command where the UART's ring holds it: kAppRxRing), nor
    # the sensor parts' codes (named by its configuration)
    assert sizes["fsw_gen::link"] == 76 - 6 - 2 - 24 - 3, sizes
