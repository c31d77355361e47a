"""The core rocket's link (examples/rocket without its recorder, parameters
and pyro channels: tools/bench_firmware.py core) copied every byte the UART
driver's receive ring held into a receive buffer of its own, 24 bytes of
its 68 (fsw::Link rx), beside the 32-byte ring sized for the one command
its ground keeps in flight: the core took 601 B of static RAM. Now an
application whose ground keeps one command in flight (no parameters, no
`[reload]`: fsw_app.h kAppRxRing) decodes a command where the ring holds
it (pal::console_peek, console_run, console_drop); an application whose
ground pipelines its commands keeps the buffer, which the ring is emptied
into each run (kAppRxBuffer, generated code's `link_rx`).

What the link does with the bytes is what it did: a command split across
two runs of the uplink task, one that wraps round the ring's end, a
corrupt, an oversized and a truncated frame are answered and counted as
before, with the kit's UART driver (the Uno) and with the core's Serial
(FSW_CONSOLE_ARDUINO_SERIAL=1, on the Mega), whose bytes the link's ring
takes as it reads them."""

from __future__ import annotations

import re
import shutil
import subprocess

import pytest

from conftest import ROOT, run_fsw
from fswkit.autocode import protocol as P
from fswkit.link import wire
from fswkit.link.session import Session
from support.core_rocket import build_core, core_project
from support.linkfw import hello_seq, tank_layout
from support.simfw import OUT

sim = pytest.importorskip("fswkit.sim.board")
pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or shutil.which("simavr") is None,
                                reason="gcc-avr / simavr not installed")

BUILD_MK = ROOT / "mk" / "build.mk"
MEGA = ["MCU=atmega2560", "F_CPU=16000000", "VARIANT=mega", "BOARD_DEFINE=ARDUINO_AVR_MEGA2560"]
ANALOG = {"A0": 0.5, "A1": 1.25, "A2": 2.5, "A3": 2.5}


@pytest.fixture(scope="module")
def core(tmp_path_factory):
    return build_core(tmp_path_factory)


def _serial_core(tmp_path_factory):
    """The core rocket generated for the Mega and built with its console on
    the core's Serial (mk/build.mk's EXTRA_DEFS): (project, elf). Built
    into build/sim-tests/ as support.core_rocket builds the Uno's (kept
    between runs: make rebuilds what changed, and nothing when nothing did)."""
    from fswkit.target.build import build_lock
    from fswkit.target.libcache import avr_tools_key

    project = core_project(tmp_path_factory.mktemp("core-serial"))
    out = OUT / "core-rocket-mega2560-console-serial"
    gen = out / "gen"
    with build_lock(str(out), "test"):  # another test session may build it too
        r = run_fsw("gen", str(project), "--board", "mega2560", "--out", str(gen))
        assert r.code == 0, r.err
        p = subprocess.run(["make", "--no-print-directory", "-j2", "-f", str(BUILD_MK), f"GEN={gen}", f"OUT={out}",
                            "NAME=rocket", "avr", "EXTRA_DEFS=-DFSW_CONSOLE_ARDUINO_SERIAL=1",
                            f"AVR_TOOLS_KEY={avr_tools_key('atmega2560')}"] + MEGA,
                           capture_output=True, text=True)
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-4000:]
    return project, out / "rocket.elf"


def test_the_core_link_keeps_no_receive_buffer_of_its_own(core):
    _, out = core
    nm = subprocess.run(["avr-nm", "-S", "-C", str(out / "rocket.elf")], capture_output=True, text=True,
                        check=True).stdout
    sizes = {m.group(2): int(m.group(1), 16) for m in re.finditer(r"^[0-9a-f]+ ([0-9a-f]+) [bBdD] (.+)$", nm, re.M)}
    # fsw_gen's `link` (LTO leaves its name mangled)
    link = [size for name, size in sizes.items() if re.search(r"(::|_14)link(E)?(\.lto_priv\.\d+)?$", name)]
    # 68 B before, its receive buffer 24 of them
    assert len(link) == 1 and link[0] <= 44, (link, sizes)
    assert not any("link_rx" in name for name in sizes), sizes
    ring = [size for name, size in sizes.items() if name == "fsw_console_rx"]
    assert ring == [32], sizes  # the ring itself as it was: one command in flight


def _exchange(elf: str, board: str, project) -> tuple[dict, dict, dict]:
    """The commands below sent to the board, each part after the one before
    had time to arrive and be read: (acks by sequence number, the health
    frame's receive counters before, and after)."""
    lay = tank_layout(project)
    s = Session(lay)
    tasks = [name for name, _ in lay.tasks]
    act = tasks.index("act")
    counters = ("rx_ok", "rx_crc", "rx_malformed", "rx_oversized", "rx_replayed", "rx_refused")
    with sim.SimBoard(elf, board, analog=ANALOG, sim_limit=60, wall_limit=180) as b:
        seq = hello_seq(b, s)
        assert s.health is not None
        before = {k: s.health[k] for k in counters}
        mode = wire.uplink(P.OP_MODE, seq + 1, bytes((act, 2)))
        pings = b"".join(wire.uplink(P.OP_PING, seq + k) for k in (2, 3, 4))
        wrapped = wire.uplink(P.OP_MODE, seq + 5, bytes((act, 2)))
        bad_crc = bytearray(wire.uplink(P.OP_PING, seq + 6))
        bad_crc[-2] ^= 0x40  # the CRC's low byte (never zero here: still a well-formed COBS frame)
        assert 0 not in bad_crc[1:-1]
        parts = [
            mode[:5], mode[5:],  # a command split across two runs of the uplink task
            # three commands and the first bytes of a fourth, whose rest comes later: with a ring of 32
            # that started from its front, the fourth wraps round its end
            pings + wrapped[:3], wrapped[3:],
            bytes(bad_crc),  # counted, not answered
            b"\0" + bytes([0x11]) * 26 + b"\0",  # longer than any command: counted oversized
            b"\0\x05\x04\x02\0",  # a code byte that promises more than the frame holds: malformed
            wire.uplink(P.OP_PING, seq + 7),  # and the link takes the next command as ever
        ]
        for part in parts:
            b.uart_write(part)
            b.run_for(0.05)
            s.feed(b.uart_read())
        b.run_for(1.5)  # a health frame after the last command
        s.feed(b.uart_read())
        after = {k: s.health[k] for k in counters}
    acks = {a["cmd_seq"] - seq: a["status_name"] for a in s.acks}
    assert s.stats.lost == 0
    return acks, before, after


@pytest.mark.parametrize("console", ["uart0-driver", "arduino-serial"])
def test_split_wrapped_corrupt_oversized_and_truncated_commands_are_taken_as_before(core, console,
                                                                                    tmp_path_factory):
    if console == "uart0-driver":
        project, out = core
        elf, board = str(out / "rocket.elf"), "uno"
    else:
        project, elf = _serial_core(tmp_path_factory)
        elf, board = str(elf), "mega2560"
    acks, before, after = _exchange(elf, board, project)
    assert acks == {1: "OK", 2: "OK", 3: "OK", 4: "OK", 5: "OK", 7: "OK"}, acks
    delta = {k: after[k] - before[k] for k in after}
    assert delta == {"rx_ok": 6, "rx_crc": 1, "rx_malformed": 1, "rx_oversized": 1, "rx_replayed": 0,
                     "rx_refused": 0}, (before, after)
