"""`[time] source cycle`: the executor's 32-bit cycle count wrapped after
2^32 cycles (49.7 days at 1 kHz), `G` went back to 0 and the machine's task
was safed for good. The cycle count is 64 bits; `G` keeps growing across the
wrap. Checked on the generated firmware, built for the host and started a
few cycles before the wrap."""

from __future__ import annotations

import shutil
import struct
import subprocess

import pytest

SV = """\
[Flight]
U64 time
U32 state
U32 steps
U8 controlMode
"""

SM = """\
[state_vector]
U64 time @alias G
U32 state @alias S
U32 steps

[Run]
.step
    steps = steps + 1
"""

APP = """\
[application]
board native
rate 1000

[configs]
state_vector rig.sv
machine rig.sm

[time]
source cycle
unit {unit}

[tasks]
control machine rig mode=controlMode
"""

pytestmark = pytest.mark.skipif(shutil.which("g++") is None, reason="no host C++ compiler")


def build(fsw, folder, unit):
    for name, text in (("rig.sv", SV), ("rig.sm", SM), ("rig.app", APP.format(unit=unit))):
        (folder / name).write_text(text)
    r = fsw("build", str(folder), "--out", str(folder / "out"))
    assert r.code == 0, r.err
    return folder / "out" / "rig"


def state_vector(exe, cycles: int, first: int) -> dict:
    r = subprocess.run([str(exe), str(cycles), "--first-cycle", str(first)], capture_output=True, text=True,
                       timeout=60, check=True)
    raw = bytes.fromhex(r.stdout.strip())
    time, state, steps, mode = struct.unpack_from("<QIIB", raw)
    return {"G": time, "S": state, "steps": steps, "mode": mode}


@pytest.mark.parametrize("unit, per_cycle", [("ms", 1), ("us", 1000)])
def test_g_keeps_counting_across_the_wrap(fsw, tmp_path, unit, per_cycle):
    exe = build(fsw, tmp_path, unit)
    first = 2**32 - 3
    sv = state_vector(exe, 6, first)
    # the 6th cycle ran with the count at first + 5, past 2^32
    assert sv == {"G": (first + 5) * per_cycle, "S": 1, "steps": 6, "mode": 2}
    # and far on: a count that does not fit 32 bits at all
    first = 5 * 2**32 + 7
    assert state_vector(exe, 2, first)["G"] == (first + 1) * per_cycle
