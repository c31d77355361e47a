"""The simulated board (fswkit.sim.board, `fsw sim`): firmware ELFs on simavr,
driven in lock-step and free-running, with the UART on the control channel
and on a pty, pins mapped from the Arduino variants, limits, bad input."""

from __future__ import annotations

import os
import re
import shutil
import signal
import struct
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
import serial

from conftest import EXAMPLES, ROOT
from support.simfw import OUT, dive_uno, halt_uno, probe_uno, spin_uno, tank_mega, tank_uno, toggle_uno  # noqa: F401

from fswkit.sim.board import SimBoard, SimError, harness, pin_map, sim_board

pytestmark = pytest.mark.skipif(
    shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
    reason="gcc-avr and libsimavr-dev are needed (make setup)")

MS = 16000  # cycles per millisecond at 16 MHz


def volts_for_psi(psi: float) -> float:
    """The tank transducer: psi = volts * 250 - 125 (tank.aio)."""
    return (psi + 125) / 250


# ---- pins ------------------------------------------------------------------------------

def test_uno_pins_come_from_the_standard_variant():
    m = pin_map(sim_board("uno"))
    assert m.digital[4] == ("D", 4)
    assert m.digital[13] == ("B", 5)
    assert m.digital[14] == ("C", 0)  # A0
    assert m.analog["A0"] == 0 and m.analog["A5"] == 5
    assert set(m.timers) == set(sim_board("uno").pwm_pins)
    assert m.timers[3] == "TIMER2B" and m.timers[9] == "TIMER1A"


def test_mega_pins_come_from_the_mega_variant():
    b = sim_board("mega2560")
    m = pin_map(b)
    assert m.digital[4] == ("G", 5)
    assert m.digital[13] == ("B", 7)
    assert m.digital[54] == ("F", 0)  # A0
    assert m.analog["A8"] == 8
    assert set(m.timers) == set(b.pwm_pins)
    assert m.timers[46] == "TIMER5A"


# ---- the tank rig ------------------------------------------------------------------------

def _tank_scenario(elf: str, board: str) -> None:
    # 625 psi at power-up: the vent controller keeps the valve shut.
    with SimBoard(elf, board, analog={"A0": volts_for_psi(625)}, sim_limit=5, wall_limit=30) as b:
        b.watch(4)
        r = b.run_for(0.05)
        assert (r.stop, r.state) == ("target", "sleeping")  # between cycles the executor sleeps
        assert b.is_output(4) and not b.digital(4)
        # 800 psi (3.7 V): above 775, the valve opens within a 10 ms cycle.
        t_set = b.cycle
        b.set_analog("A0", 3.7)
        b.run_for(0.05)
        assert b.digital(4)
        edges = b.edges()
        assert [e.level for e in edges] == [True] and edges[0].pin == 4
        assert 0 < edges[0].cycle - t_set <= 2 * 10 * MS
        # Back to 625 psi: it closes again.
        b.step(50 * MS, analog={"A0": volts_for_psi(625)})
        assert not b.digital(4)
        # 850 psi (3.9 V) leaves (500, 825): Abort, and the valve stays open
        # even when the pressure comes back.
        b.step(50 * MS, analog={"A0": 3.9})
        assert b.digital(4)
        b.step(100 * MS, analog={"A0": volts_for_psi(625)})
        assert b.digital(4)
        assert [e.level for e in b.edges()] == [False, True]
        assert abs(b.time - 0.3) < 1e-3


def test_tank_firmware_on_a_simulated_uno(tank_uno):
    _tank_scenario(tank_uno, "uno")


def test_tank_firmware_on_a_simulated_mega(tank_mega):
    _tank_scenario(tank_mega, "mega2560")


def test_low_pressure_aborts_with_the_valve_open(tank_uno):
    with SimBoard(tank_uno, "uno", analog={"A0": 1.0}, sim_limit=5) as b:  # 125 psi
        b.run_for(0.05)
        assert b.digital(4)


def test_the_state_vector_reads_the_transducer(tank_uno):
    # simavr converts 3900 mV to floor(3900 * 1023 / 5000) = 797 counts; the
    # firmware makes that 797 * 5 / 1023 volts, then psi (in binary32).
    with SimBoard(tank_uno, "uno", analog={"A0": 3.9}, sim_limit=5) as b:
        b.run_for(0.03)
        addr, size = b.symbol("fsw_gen::sv")
        assert size > 0
        header = (Path(tank_uno).parent / "gen" / "sv.gen.h").read_text()
        off = int(re.search(r"E_tankPressure\s*=\s*(\d+)", header).group(1))
        psi = struct.unpack("<d", b.peek(addr + off, 8))[0]
        assert psi == pytest.approx(797 * 5.0 / 1023 * 250 - 125, abs=1e-3)


# ---- timing ----------------------------------------------------------------------------

def test_executor_period_is_one_millisecond_at_1khz(toggle_uno):
    with SimBoard(toggle_uno, "uno", sim_limit=5) as b:
        b.watch(13)
        b.run_for(0.25)
        edges = b.edges()
    assert len(edges) >= 240
    assert all(a.level != b.level for a, b in zip(edges, edges[1:]))
    steady = edges[10:]
    periods = [(b.cycle - a.cycle) / MS for a, b in zip(steady, steady[1:])]
    mean = sum(periods) / len(periods)
    assert abs(mean - 1.0) < 0.001
    assert max(abs(p - 1.0) for p in periods) < 0.1  # no cycle skipped or doubled


def test_lock_step_lands_on_the_cycle_asked_for(spin_uno):
    with SimBoard(spin_uno, "uno", sim_limit=5) as b:
        for k in range(1, 50):
            r = b.until(k * 1000)
            assert 0 <= r.cycle - k * 1000 <= 4  # an instruction takes at most 4 cycles here
        r = b.step(0)
        assert r.stop == "target"


# ---- UART, PWM, inputs -------------------------------------------------------------------

def test_uart_through_the_control_channel(probe_uno):
    with SimBoard(probe_uno, "uno", sim_limit=5) as b:
        b.run_for(0.01)
        assert b.uart_read() == b"probe ready\n"
        b.uart_write(b"ping, 1 2 3")
        b.run_for(0.01)  # 11 bytes at 115200 baud: about 1 ms
        assert b.uart_read() == b"ping, 1 2 3"


def test_pwm_duty_and_driven_inputs(probe_uno):
    with SimBoard(probe_uno, "uno", sim_limit=5) as b:
        b.run_for(0.01)
        assert b.pwm(3) == pytest.approx(64 / 255)
        assert b.pwm(9) == pytest.approx(200 / 255)
        assert b.pwm(5) == 1.0  # digitalWrite(HIGH) on a PWM pin
        assert not b.digital(8)
        b.set_digital(7, True)
        b.run_for(0.001)
        assert b.digital(8)
        b.set_digital(7, False)
        b.run_for(0.001)
        assert not b.digital(8)
        with pytest.raises(SimError, match="no PWM"):
            b.pwm(4)


def test_pty_bridge_talks_to_pyserial(probe_uno):
    with SimBoard(probe_uno, "uno", uart="pty", sim_limit=30, wall_limit=30) as b:
        assert b.port and b.port.startswith("/dev/pts/")
        s = serial.Serial(b.port, 115200, timeout=0.05)
        try:
            runner = threading.Thread(target=lambda: b.go(until=1.0, realtime=True))
            runner.start()
            s.write(b"over the pty")
            got = b""
            deadline = time.monotonic() + 5
            while b"over the pty" not in got and time.monotonic() < deadline:
                got += s.read(64)
            runner.join()
            assert b"over the pty" in got
        finally:
            s.close()


# ---- fsw sim -----------------------------------------------------------------------------------

def _fsw_sim(*args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "fswkit.cli", "sim", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=ROOT, start_new_session=True)


def test_fsw_sim_prints_the_port_and_stops_after_the_duration():
    out = OUT / "fsw-sim-tank"
    p = _fsw_sim("examples/tank", "--board", "uno", "--duration", "2", "--out", str(out))
    try:
        port = p.stdout.readline().strip()
        assert port.startswith("/dev/pts/"), p.stderr.read()
        s = serial.Serial(port, 115200, timeout=0.1)  # opens like a real port while it runs
        s.write(b"x")
        s.close()
        code = p.wait(timeout=20)
    finally:
        if p.poll() is None:
            p.kill()
    err = p.stderr.read()
    assert code == 0, err
    assert "duration reached at 2.000000 s simulated" in err
    m = re.search(r"stack high-water (\d+) B; RAM ([\d,]+) B static \+ \d+ B stack = ([\d,]+) of 2,048 B", err)
    assert m, err
    stack, static, total = int(m.group(1)), int(m.group(2).replace(",", "")), int(m.group(3).replace(",", ""))
    # the tank's stack is used (63 B since 2026-12-07: see the next test)
    assert 32 <= stack and static == _static_bytes(str(out / "tank.elf")) and total == static + stack


def test_fsw_sim_stops_on_ctrl_c(probe_uno):
    p = _fsw_sim(probe_uno, "--board", "uno")
    try:
        port = p.stdout.readline().strip()
        assert port.startswith("/dev/pts/"), p.stderr.read()
        s = serial.Serial(port, 115200, timeout=0.05)
        s.write(b"echo me")
        got = b""
        deadline = time.monotonic() + 5
        while b"echo me" not in got and time.monotonic() < deadline:
            got += s.read(64)
        s.close()
        assert b"echo me" in got
        os.killpg(p.pid, signal.SIGINT)  # Ctrl-C at a terminal reaches the whole group
        code = p.wait(timeout=10)
    finally:
        if p.poll() is None:
            p.kill()
    err = p.stderr.read()
    assert code == 0, err
    assert "stopped at" in err and "Traceback" not in err


# ---- stack and RAM ---------------------------------------------------------------------

def _static_bytes(elf: str) -> int:
    """.data + .bss + .noinit of an ELF, as avr-size counts them."""
    out = subprocess.run(["avr-size", "-A", elf], capture_output=True, text=True, check=True).stdout
    sizes = {p[0]: int(p[1]) for p in (line.split() for line in out.splitlines())
             if len(p) == 3 and p[0].startswith(".")}
    return sum(sizes.get(name, 0) for name in (".data", ".bss", ".noinit"))


def test_stack_high_water_grows_one_frame_a_level(dive_uno):
    marks = {}
    for depth, elf in dive_uno.items():
        with SimBoard(elf, "uno", sim_limit=1) as b:
            assert b.step(50 * MS).state == "done"  # it recursed, then stopped itself
            marks[depth] = b.stack_high_water()
    grown = marks[16] - marks[8]
    frame = grown // 8
    assert grown == 8 * frame  # the same frame each level
    assert 34 <= frame <= 40  # 32 bytes of locals + the return address (+ a saved frame pointer)
    assert marks[8] >= 8 * frame


def test_tank_stack_and_ram_on_a_simulated_uno(tank_uno):
    with SimBoard(tank_uno, "uno", analog={"A0": 3.76}, sim_limit=5) as b:
        b.run_for(1.0)
        first = b.ram_usage()
        b.run_for(1.0)
        later = b.ram_usage()
    assert first.ram == 2048
    assert first.static == _static_bytes(tank_uno)
    # used (main's loop calling a task's step, an interrupt on top: 63 B on
    # 2026-12-07, since the link frames on its composers' callers' stack),
    # and never reached the static data
    assert 32 <= first.stack < first.ram - first.static
    assert first.total == first.static + first.stack
    assert later.stack >= first.stack  # a high-water mark
    with SimBoard(tank_uno, "uno", analog={"A0": 3.76}, sim_limit=5) as b:
        b.run_for(1.0)
        assert b.stack_high_water() == first.stack  # simulated time is deterministic


def test_firmware_that_does_not_paint_its_stack(spin_uno):
    with SimBoard(spin_uno, "uno", sim_limit=1) as b:
        b.step(MS)
        with pytest.raises(SimError, match="does not paint its stack"):
            b.stack_high_water()


# ---- limits ----------------------------------------------------------------------------

def test_simulated_time_limit_stops_a_spinning_firmware(spin_uno):
    with SimBoard(spin_uno, "uno", sim_limit=0.01) as b:
        r = b.step(10 ** 12)
        assert r.stop == "sim-limit"
        assert r.cycle == pytest.approx(160000, abs=4)
        assert b.go(realtime=False).stop == "sim-limit"


def test_simulated_time_limit_stops_a_sleeping_firmware_at_the_limit(tank_uno):
    # the tank's executor sleeps between its cycles: the core wakes at the limit (a cycle timer, as at a
    # step's target), not at its next event after it
    for run in (lambda b: b.step(10 ** 12), lambda b: b.go(realtime=False)):
        with SimBoard(tank_uno, "uno", sim_limit=0.05) as b:
            r = run(b)
            assert r.stop == "sim-limit"
            assert r.cycle == pytest.approx(800000, abs=4), r


def test_wall_clock_limit_stops_a_spinning_firmware(spin_uno):
    t0 = time.monotonic()
    with SimBoard(spin_uno, "uno", wall_limit=0.5) as b:
        r = b.go(realtime=False)
        assert r.stop == "wall-limit"
        assert r.cycle > 0
        assert b.step(1000).stop == "wall-limit"
    assert time.monotonic() - t0 < 5


def test_firmware_that_stops_itself(halt_uno):
    with SimBoard(halt_uno, "uno", sim_limit=1) as b:
        r = b.step(MS)
        assert (r.state, r.stop) == ("done", "done")
        assert r.cycle < MS


def test_the_harness_compiles_without_warnings(tmp_path):
    """Compiled once (the link's libraries do not change the compile),
    then linked each way it may be."""
    from fswkit.sim import board as sim

    obj = str(tmp_path / "harness.o")
    r = subprocess.run([sim.CC] + sim.CFLAGS + ["-Werror", "-c", sim.HARNESS_SRC, "-o", obj],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    for libs in (sim.LIBS_STATIC, sim.LIBS):
        r = subprocess.run([sim.CC, obj, "-o", str(tmp_path / "simboard")] + libs, capture_output=True, text=True)
        assert r.returncode == 0 and not r.stderr, r.stderr


def test_the_harness_has_simavr_linked_in_where_its_static_library_is_installed():
    """libsimavr-dev installs libsimavr.a beside libsimavr.so (make setup):
    the harness then calls simavr directly, about 15 % cheaper a simulated
    second, and loads no libsimavr.so."""
    import glob

    if not glob.glob("/usr/lib/*/libsimavr.a") + glob.glob("/usr/lib/libsimavr.a"):
        pytest.skip("no libsimavr.a on this machine: the harness links the shared library")
    r = subprocess.run(["ldd", harness()], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "libsimavr" not in r.stdout, r.stdout


def test_the_harness_bridges_the_uart_to_standard_io(probe_uno):
    r = subprocess.run([harness(), "-u", "stdio", "-t", "0.05", probe_uno], input=b"via stdin", capture_output=True,
                       timeout=30)
    assert r.returncode == 0, r.stderr
    assert r.stdout == b"probe ready\nvia stdin"


def test_the_harness_runs_free_on_its_own(spin_uno):
    r = subprocess.run([harness(), "-m", "atmega328p", "-t", "0.02", spin_uno], capture_output=True, text=True,
                       timeout=30)
    assert r.returncode == 0
    assert "stopped (sim-limit) at cycle 320000" in r.stderr


# ---- bad input -------------------------------------------------------------------------

def test_missing_project(fsw):
    r = fsw("sim", "no/such/project")
    assert r.code == 2 and "no/such/project: no such file or folder" in r.err


def test_unknown_board(fsw):
    r = fsw("sim", str(EXAMPLES / "tank"), "--board", "nosuch")
    assert r.code == 2 and "unknown board `nosuch`" in r.err


def test_board_without_a_simulator(fsw):
    r = fsw("sim", str(EXAMPLES / "tank"), "--board", "native")
    assert r.code == 2 and "board `native` has no simulated MCU" in r.err


def test_corrupt_elf(fsw, tmp_path):
    bad = tmp_path / "bad.elf"
    bad.write_bytes(b"\x7fELF" + os.urandom(200))
    r = fsw("sim", str(bad), "--board", "uno")
    assert r.code == 1 and "bad.elf" in r.err and "Traceback" not in r.err
    junk = tmp_path / "junk.elf"
    junk.write_bytes(b"not an elf at all")
    r = fsw("sim", str(junk), "--board", "uno")
    assert r.code == 1 and "not an ELF file" in r.err
    with pytest.raises(SimError, match="not an ELF file"):
        SimBoard(str(junk), "uno")


def test_truncated_elf_is_refused_by_the_harness(fsw, tmp_path, spin_uno):
    cut = tmp_path / "cut.elf"
    cut.write_bytes(open(spin_uno, "rb").read()[:300])
    r = fsw("sim", str(cut), "--board", "uno")
    assert r.code == 1 and "cut.elf" in r.err and "Traceback" not in r.err


def test_elf_for_another_mcu(fsw, tank_mega):
    r = fsw("sim", tank_mega, "--board", "uno")
    assert r.code == 1 and "built for avr6, not for the atmega328p (avr5)" in r.err


def test_elf_needs_a_board(fsw, spin_uno):
    r = fsw("sim", spin_uno)
    assert r.code == 2 and "needs --board" in r.err


def test_bad_analog_settings(fsw, spin_uno):
    r = fsw("sim", spin_uno, "--board", "uno", "--analog", "A9=1")
    assert r.code == 2 and "no analog input `A9`" in r.err
    r = fsw("sim", spin_uno, "--board", "uno", "--analog", "A0=7")
    assert r.code == 2 and "between 0 and 5" in r.err
    r = fsw("sim", spin_uno, "--board", "uno", "--duration", "0")
    assert r.code == 2 and "--duration" in r.err


def test_protocol_errors_are_messages(spin_uno):
    with SimBoard(spin_uno, "uno", sim_limit=1) as b:
        with pytest.raises(SimError, match="unknown command `bogus`"):
            b.command("bogus")
        with pytest.raises(SimError, match="usage: peek"):
            b.peek(0x10000, 4)
        with pytest.raises(SimError, match="no analog input A7"):
            b.set_analog("A7", 1.0)
        with pytest.raises(SimError, match="no digital pin 40"):
            b.digital(40)
        with pytest.raises(SimError, match="usage: step"):
            b.exchange(["step x", "step 100", "info"])
        assert b.info()["mcu"] == "atmega328p"  # still answering, in step


def test_an_input_driven_again_after_a_reset_reaches_the_pin(toggle_uno):
    """A reset clears the PIN registers; driving an input to the level it
    had before must reach the pin again (simavr drops a raise of an IRQ's
    current value: a brown-out flight's arming key read low after the reset)."""
    with SimBoard(toggle_uno, "uno", sim_limit=5) as b:
        b.run_for(0.01)
        b.set_digital(2, True)
        b.run_for(0.01)
        assert b.ports()["D"][2] & 0x04
        b.reset()
        b.run_for(0.01)
        assert not b.ports()["D"][2] & 0x04  # power-on level
        b.set_digital(2, True)
        b.run_for(0.01)
        assert b.ports()["D"][2] & 0x04
