"""The core rocket (examples/rocket without its recorder, parameters and
pyro channels: the 8 KB / 640 B target's basis, tools/bench_firmware.py
core) reached 86 bytes of stack on its demo flight, of its 687 B of RAM:
the link's composers of a frame (send_batch, 18 B of saved registers;
send_control, 28 B with a copy of the time) called the framer (cobs_frame,
19 B) from their own frames, the telemetry step kept 8 B of locals beside
its 18 saved registers, and the framer's caller kept the frame's length
across the UART's call, the copy of a body's bytes their count across
memcpy and the room check the link across its look at the UART. Now the
composer's caller frames and hands the frame once the composer has
returned (fsw_link.cpp frame_end), the time's high half waits in the frame
itself, the telemetry step walks its streams' rows and records, and none
of those keeps anything across a call: the demo flight's stack is 65 B,
and with the ground's commands driving the control paths (acks, hello,
snapshot) 66 B where it was 92 B."""

from __future__ import annotations

import shutil

import pytest

from fswkit.link.session import Session
from support.core_rocket import build_core
from support.linkfw import control_commands, hello_seq, send_one_at_a_time, tank_layout

sim = pytest.importorskip("fswkit.sim.board")
pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or shutil.which("simavr") is None,
                                reason="gcc-avr / simavr not installed")

# 92 B before with its control paths driven as below (86 B on the demo
# flight); 66 B then (65 B on the demo flight); 55 B since the kit's
# main() saves no register for its caller (OS_main, 2026-12-07, night: 56
# B on the demo flight), and 51 B since the uplink's frame handling went out
# of line and the frame's time is put by a call of its own; 47 B since the
# compiler's value-range propagation is off and its register allocation is
# by priority (mk/build.mk, 2026-12-07, night)
CORE_STACK_MAX = 49


@pytest.fixture(scope="module")
def core_elf(tmp_path_factory):
    project, out = build_core(tmp_path_factory)
    return project, out / "rocket.elf"


def test_the_core_rockets_control_paths_keep_its_stack_small(core_elf):
    project, elf = core_elf
    lay = tank_layout(project)
    s = Session(lay)
    with sim.SimBoard(str(elf), "uno", analog={"A0": 0.5, "A1": 1.25, "A2": 2.5, "A3": 2.5},
                      sim_limit=60, wall_limit=120) as b:
        seq = hello_seq(b, s)
        commands = control_commands(lay)
        send_one_at_a_time(b, s, commands, seq)
        b.run_for(1.0)  # health frames, samples
        s.feed(b.uart_read())
        stack = b.stack_high_water()
    acks = {a["cmd_seq"]: a["status_name"] for a in s.acks}
    assert acks == {seq + k: "OK" for k in range(1, len(commands) + 1)}, acks
    assert s.stats.lost == 0
    assert 44 <= stack <= CORE_STACK_MAX, stack
