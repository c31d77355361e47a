"""What every firmware paid for and the rocket's RAM target could not
afford (issue 17): the Arduino core's start-up (its init() and Timer0's
millis() tick, interrupt and state, although the executor's timer keeps the
clock), and copies of the link's, the recorder's and the parameter store's
configuration on the stack (54, 49 and 20 bytes) on the deepest paths, one
of them in main()'s own frame, which every path pays. The rocket's stack
reached 253 bytes through the demo flight. A firmware without PWM outputs
now starts through the kit's main(); one with PWM outputs keeps the core's
start-up (its timers), and drives its pin."""

from __future__ import annotations

import shutil
import struct
import subprocess
from pathlib import Path

import pytest

from conftest import EXAMPLES, run_fsw
from fswkit.autocode import protocol as P
from fswkit.autocode.iotables import analog_gain
from fswkit.autocode.numeric import F32MODE
from fswkit.link import wire
from fswkit.link.session import Session
from support.linkfw import control_commands, hello_seq, send_one_at_a_time, tank_layout
from support.simfw import project_elf

sim = pytest.importorskip("fswkit.sim.board")
pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or shutil.which("simavr") is None,
                                reason="gcc-avr / simavr not installed")

ROCKET = EXAMPLES / "rocket"
# The whole rocket's stack with the link's control paths driven (below):
# 253 bytes before through the demo flight alone, which drives none of them.
STACK_MAX = 200


def _symbols(elf) -> dict[str, str]:
    nm = subprocess.run(["avr-nm", str(elf)], capture_output=True, text=True, check=True).stdout
    return {line.split()[-1]: line.split()[-2] for line in nm.splitlines() if len(line.split()) >= 2}


@pytest.fixture(scope="module")
def rocket():
    return Path(project_elf(str(ROCKET), "uno"))  # kept between runs (support.simfw)


def test_a_firmware_without_pwm_links_no_timer0_tick(rocket):
    sym = _symbols(rocket)
    assert "main" in sym
    # the core's init() and millis() state, and Timer0's overflow handler
    # (a defined __vector_16; the vector table's default is a weak alias)
    assert not {"init", "timer0_millis", "timer0_overflow_count"} & set(sym), sorted(sym)
    assert sym.get("__vector_16") != "T"


def test_the_control_paths_keep_the_rocket_stack_small(rocket):
    lay = tank_layout(ROCKET)
    s = Session(lay)
    with sim.SimBoard(str(rocket), "uno", analog={"A0": 0.5, "A1": 1.25, "A2": 2.5, "A3": 2.5},
                      sim_limit=60, wall_limit=120) as b:
        seq = hello_seq(b, s)
        commands = control_commands(lay) + [
            (P.OP_PARAM_INFO, b""), (P.OP_PARAM_GET, bytes((0, 1))), (P.OP_PARAM_SAVE, b""),
            (P.OP_LOG_INFO, b""), (P.OP_LOG_READ, struct.pack("<HBB", 0, 0, 16))]
        send_one_at_a_time(b, s, commands, seq)
        b.run_for(1.0)  # the parameter bank written to the EEPROM, byte by byte
        s.feed(b.uart_read())
        # SET of the first parameter's own value (allowed in any state):
        # the deepest path, through the store's check of what changed
        got = next(a for a in s.acks if a["cmd_seq"] == seq + 7)["data"]
        assert got[:2] == bytes((0, 1)), got
        b.uart_write(wire.uplink(P.OP_PARAM_SET, seq + 11, bytes((0,)) + got[2:]))
        b.run_for(0.2)
        s.feed(b.uart_read())
        stack = b.stack_high_water()
    acks = {a["cmd_seq"]: a["status_name"] for a in s.acks}
    assert acks == {seq + k: "OK" for k in range(1, len(commands) + 2)}, acks
    assert s.stats.lost == 0
    assert 64 <= stack <= STACK_MAX, stack


def test_a_firmware_with_pwm_keeps_the_cores_start_up(tmp_path):
    project = tmp_path / "tank"
    shutil.copytree(EXAMPLES / "tank", project, ignore=shutil.ignore_patterns("build", "*typo*"))
    with open(project / "tank.aio", "a") as f:
        f.write("o      3    tankPressure\n")  # a PWM output: Timer2's pin, set up by the core's init()
    gen = run_fsw("gen", str(project), "--out", str(tmp_path / "gen"))
    assert gen.code == 0, gen.err
    app = (tmp_path / "gen" / "app.gen.cpp").read_text()
    assert "int main() {" not in app  # the core's main() and init()
    r = run_fsw("build", str(project), "--out", str(tmp_path / "uno"))
    assert r.code == 0, r.err
    elf = tmp_path / "uno" / "tank.elf"
    sym = _symbols(elf)
    assert "timer0_millis" in sym and sym.get("__vector_16") == "T"  # the core's init() and its Timer0 tick
    # 0.51 V: 104 counts, tankPressure about 2.08 (psi = volts * 250 - 125),
    # driven as that many volts of the 5 V reference
    counts = int(0.51 * 1023 / 5)
    psi = counts * analog_gain(250.0, 5.0, 10, F32MODE) - 125.0
    with sim.SimBoard(str(elf), "uno", analog={"A0": 0.51}, sim_limit=5) as b:
        b.run_for(0.1)
        assert b.pwm(3) == pytest.approx(int(psi / 5.0 * 255 + 0.5) / 255)
