"""End to end on the simulated Uno (simavr, fswkit.sim.board): the tank firmware
built for the board streams telemetry over UART0; the ground decodes the
value the harness put on A0, bit for bit as the ATmega computes it, a
command sent over the link changes what the firmware does, and faults
injected between the board and the ground are refused and counted exactly."""

from __future__ import annotations

import random
import shutil
import struct

import numpy as np
import pytest

from conftest import run_fsw
from fswkit.autocode.iotables import analog_gain
from fswkit.autocode.numeric import F32MODE
from fswkit.link import wire
from fswkit.link.session import Session
from support.linkfw import TANK, tank_layout

sim = pytest.importorskip("fswkit.sim.board")
pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or shutil.which("simavr") is None,
                                reason="gcc-avr / simavr not installed")
VOLTS = 3.76  # 769 counts: 814.7 psi, between 775 and 825: the controller holds the valve open


def psi_f32(raw: int) -> float:
    """tank.aio's calibration as the Uno computes it: binary32, one
    multiply-add per count (the generator's gain, fsw_io.h), stored into the
    F64 element exactly."""
    f = np.float32
    gain = f(analog_gain(250.0, 5.0, 10, F32MODE))
    return float(f(f(raw) * gain) + f(-125.0))


@pytest.fixture(scope="module")
def elf(tmp_path_factory):
    out = tmp_path_factory.mktemp("uno")
    r = run_fsw("build", str(TANK), "--out", str(out))
    assert r.code == 0, r.err
    return str(out / "tank.elf")


def test_uno_streams_what_the_pin_reads_and_obeys_commands(elf):
    lay = tank_layout()
    s = Session(lay)
    raw = int(VOLTS * 1000 * 1023 // 5000)
    captured = bytearray()

    def uart(b):
        data = b.uart_read()
        captured.extend(data)
        return data

    with sim.SimBoard(elf, "uno", analog={"A0": VOLTS}, sim_limit=120, wall_limit=120) as b:
        b.run_for(2.0)
        evs = s.feed(uart(b))
        assert s.hello is not None and s.hello["schema_ok"], "no hello with the configs' schema"
        assert s.values["tankPressure"] == psi_f32(raw)
        assert s.values["state"] == 1 and s.values["valveOpen"] is True
        assert b.digital(4)  # the valve's pin
        assert s.stats.lost == 0 and s.deframer.stats.crc_errors == 0 and s.deframer.stats.framing_errors == 0
        assert any(e.kind == "health" for e in evs)

        control = lay.task_index("control")
        valve = lay.element("valveOpen").index
        last = s.hello["last_seq"]
        b.uart_write(wire.uplink(wire.OP_MODE, last + 1, bytes((control, 1))))  # safe the controller
        b.uart_write(wire.uplink(wire.OP_SET, last + 2, struct.pack("<HB", valve, 0)))  # close the valve
        b.uart_write(wire.uplink(wire.OP_SET, last + 3, struct.pack("<HI", lay.element("state").index, 3)))
        b.run_for(0.5)
        s.feed(uart(b))
        acks = {a["cmd_seq"]: a["status_name"] for a in s.acks}
        assert acks == {last + 1: "OK", last + 2: "OK", last + 3: "NOT_WRITABLE"}
        assert s.values["valveOpen"] is False and not b.digital(4)  # the ground's write holds
        assert s.values["state"] == 1

        b.uart_write(wire.uplink(wire.OP_MODE, last + 4, bytes((control, 2))))
        b.run_for(0.5)
        s.feed(uart(b))
        assert s.values["valveOpen"] is True and b.digital(4)  # the controller opened it again

        b.run_for(20.0)  # a clean link for a while longer: nothing lost, nothing dropped
        s.feed(uart(b))
        assert s.stats.lost == 0 and s.health["dropped"] == 0 and s.deframer.stats.crc_errors == 0
        assert s.health["rx_ok"] == 3 and s.health["rx_refused"] == 1

    # faults injected between the simulated board and the ground: bit errors,
    # dropped bytes, garbage at boot
    from test_fault_injection import check_faults

    for seed in (1, 2):
        assert check_faults(bytes(captured), lay, random.Random(seed)) > 50


def test_fsw_monitor_and_cmd_on_the_simulated_uno(elf, tmp_path):
    """The tools a person uses: `fsw sim` puts UART0 on a pty, `fsw monitor
    --headless` decodes it, `fsw cmd` changes what the firmware does."""
    import re
    import subprocess
    import sys
    import time
    from pathlib import Path

    from conftest import run_fsw

    fsw = Path(sys.executable).parent / "fsw"
    out = tmp_path / "sim.out"
    with open(out, "w") as f:
        proc = subprocess.Popen([str(fsw), "sim", str(TANK), "--board", "uno", "--analog", f"A0={VOLTS}",
                                 "--duration", "30", "--out", str(Path(elf).parent)],
                                stdout=f, stderr=subprocess.DEVNULL)
    try:
        port = None
        deadline = time.monotonic() + 120
        while port is None and time.monotonic() < deadline and proc.poll() is None:
            m = re.search(r"^(/dev/\S+)$", out.read_text(), re.M)
            port = m.group(1) if m else None
            time.sleep(0.2)
        assert port, out.read_text()
        r = run_fsw("monitor", str(TANK), "--port", port, "--headless", "--duration", "1.5")
        assert r.code == 0, r.err
        raw = int(VOLTS * 1000 * 1023 // 5000)
        shown = set(re.findall(r"tankPressure=(\S+)", r.out))
        assert shown == {f"{psi_f32(raw):.6g}"}, shown
        assert "valveOpen=true" in r.out
        assert run_fsw("cmd", "mode", "control", "safed", "--port", port, "-p", str(TANK)).code == 0
        assert run_fsw("cmd", "set", "valveOpen", "false", "--port", port, "-p", str(TANK)).code == 0
        r = run_fsw("monitor", str(TANK), "--port", port, "--headless", "--duration", "1")
        assert r.code == 0 and set(re.findall(r"valveOpen=(\S+)", r.out)) == {"false"}, r.out[-500:]
    finally:
        import signal

        proc.send_signal(signal.SIGINT)  # Ctrl-C: fsw sim stops its board
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=10)
