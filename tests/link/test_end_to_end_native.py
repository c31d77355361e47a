"""End to end on the host: the tank firmware built for `native` runs in
real time with its console on a pseudo-terminal; `fsw monitor`, `fsw cmd`
and the log tools talk to it as they would to a board's serial port."""

from __future__ import annotations

import csv
import io
import re
import shutil
import struct
import time

import pytest

from conftest import run_fsw
from fswkit.link import wire
from fswkit.link.client import Ground
from fswkit.link.log import LogReader
from fswkit.link.port import open_port
from fswkit.link.session import Session
from support.linkfw import TANK, PtyTarget, build_native, needs_cxx, tank_layout, volts_psi

pytestmark = [needs_cxx(), pytest.mark.costly(11, waits=True)]
RAW = 770  # 770 counts -> 815.4 psi: between 775 and 825, the vent valve opens


@pytest.fixture(scope="module")
def exe():
    return build_native(TANK)


@pytest.fixture
def target(exe):
    with PtyTarget(exe, f"a14={RAW}") as t:
        time.sleep(0.3)
        yield t


def monitor_lines(port: str, *extra: str, seconds: float = 1.0):
    r = run_fsw("monitor", str(TANK), "--port", port, "--headless", "--duration", str(seconds), *extra)
    assert r.code == 0, r.err
    return r.out.splitlines(), r.err


def values_of(lines, element):
    out = []
    for line in lines:
        out += re.findall(rf"\b{element}=(\S+)", line)
    return out


def test_monitor_decodes_what_the_pin_reads(target):
    lines, err = monitor_lines(target.port)
    assert any(" hello " in ln and "matches" in ln for ln in lines), lines[:5]
    pressures = values_of(lines, "tankPressure")
    assert len(pressures) >= 20  # Sensors at 50 Hz, for a second
    assert {float(p) for p in pressures} == {float(f"{volts_psi(RAW):.6g}")}
    # exact to the bit through the decoder (the headless line rounds)
    s = Session(tank_layout())
    port = open_port(target.port, 115200)
    try:
        g = Ground(port, s)
        g.handshake()
        deadline = time.monotonic() + 2
        while s.values["tankPressure"] is None and time.monotonic() < deadline:
            g.read()
    finally:
        port.close()
    assert s.values["tankPressure"] == volts_psi(RAW)
    assert s.values["state"] == 1  # TankVentControl
    assert "0 lost" in err and "0 CRC errors" in err


def test_a_command_changes_the_firmwares_behaviour(target):
    p = target.port
    lines, _ = monitor_lines(p, seconds=0.6)
    assert values_of(lines, "valveOpen")[-1] == "true"  # 815 psi > 775: the controller opens the valve
    # safe the controller, then close the valve from the ground: it stays closed
    assert run_fsw("cmd", "mode", "control", "safed", "--port", p, "-p", str(TANK)).code == 0
    r = run_fsw("cmd", "set", "valveOpen", "false", "--port", p, "-p", str(TANK))
    assert r.code == 0 and "OK" in r.out, r.err
    lines, _ = monitor_lines(p, seconds=0.6)
    assert set(values_of(lines, "valveOpen")) == {"false"}
    # back to enabled: the controller opens it again
    assert run_fsw("cmd", "mode", "control", "enabled", "--port", p, "-p", str(TANK)).code == 0
    lines, _ = monitor_lines(p, seconds=0.6)
    assert values_of(lines, "valveOpen")[-1] == "true"


def test_every_element_not_listed_is_refused(target):
    lay = tank_layout()
    s = Session(lay)
    port = open_port(target.port, 115200)
    try:
        g = Ground(port, s)
        g.handshake()
        # through the CLI, with a value of the element's type: a NACK with its reason
        for el in lay.elements:
            if el.name in lay.writable:
                continue
            value = "1" if el.type != "bool" else "true"
            port.close()
            r = run_fsw("cmd", "set", el.name, value, "--port", target.port, "-p", str(TANK))
            assert r.code == 1 and "NOT_WRITABLE" in r.err, (el.name, r.err)
            port = open_port(target.port, 115200)
            g = Ground(port, s)
        # raw: every element index the 16-bit field can name, every value length 0..8
        statuses = {}
        for index in list(range(0, 64)) + [255, 256, 0x7FFF, 0xFFFF]:
            for size in (0, 1, 2, 4, 8):
                ack = g.command(wire.OP_SET, struct.pack("<H", index) + b"\x01" * size)
                statuses[(index, size)] = ack["status"]
        valve = lay.element("valveOpen").index
        for (index, size), st in statuses.items():
            if index == valve:
                assert st == (0 if size == 1 else 3), (index, size, st)  # BAD_LENGTH unless 1 byte
            else:
                assert st == 4, (index, size, st)  # NOT_WRITABLE
        g.command(wire.OP_SET, struct.pack("<HB", valve, 0))
    finally:
        port.close()


def test_schema_mismatch_refuses_to_decode(target, tmp_path):
    other = tmp_path / "tank"
    shutil.copytree(TANK, other, ignore=shutil.ignore_patterns("build"))
    app = (other / "tank.app").read_text().replace("\nvalveOpen\n", "\n")  # no writable element
    (other / "tank.app").write_text(app)
    r = run_fsw("monitor", str(other), "--port", target.port, "--headless", "--duration", "1")
    assert r.code == 1
    assert "schema mismatch" in r.err and "--ignore-schema" in r.err and "Traceback" not in r.err
    r = run_fsw("monitor", str(other), "--port", target.port, "--headless", "--duration", "0.5", "--ignore-schema")
    assert r.code == 0 and "sample Sensors" in r.out
    r = run_fsw("cmd", "ping", "--port", target.port, "-p", str(other))
    assert r.code == 1 and "schema mismatch" in r.err


def test_log_replay_csv_plot(target, tmp_path):
    log = tmp_path / "run.fswlog"
    lines, _ = monitor_lines(target.port, "--log", str(log), seconds=1.2)
    reader = LogReader(str(log))
    assert reader.layout.schema == tank_layout().schema
    assert sum(1 for _ in reader.records()) > 0 and not reader.truncated
    # replay shows the same frames the monitor showed
    r = run_fsw("replay", str(log), "--headless", "--speed", "0")
    assert r.code == 0
    assert r.out.splitlines() == lines
    # one row per sample, in the target's time order
    r = run_fsw("log2csv", str(log))
    assert r.code == 0, r.err
    rows = list(csv.DictReader(io.StringIO(r.out)))
    assert rows and {"target time [s]", "time", "tankPressure", "valveOpen", "state", "state name"} <= set(rows[0])
    sensor_rows = [x for x in rows if x["from frame"] == "Sensors"]
    assert len(sensor_rows) >= 40
    assert all(float(x["tankPressure"]) == volts_psi(RAW) for x in sensor_rows)
    times = [float(x["target time [s]"]) for x in rows]
    assert times == sorted(times) and {x["target boot"] for x in rows} == {"1"}
    out = tmp_path / "rows.csv"
    assert run_fsw("log2csv", str(log), "-o", str(out)).code == 0
    assert out.read_text() == r.out
    png = tmp_path / "p.png"
    r = run_fsw("plot", str(log), "-e", "tankPressure", "valveOpen", "-o", str(png))
    assert r.code == 0, r.err
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_yanked_cable_keeps_the_log(exe, tmp_path):
    log = tmp_path / "yank.fswlog"
    import threading

    with PtyTarget(exe, f"a14={RAW}") as t:
        time.sleep(0.3)

        def yank():  # the board goes away mid-run: 0.8 s after the monitor knew it and named its log
            deadline = time.monotonic() + 3.0  # (however long a loaded machine takes to get there)
            while not log.exists() and time.monotonic() < deadline:
                time.sleep(0.01)
            time.sleep(0.8)
            t.stop()
        threading.Thread(target=yank, daemon=True).start()
        r = run_fsw("monitor", str(TANK), "--port", t.port, "--headless", "--duration", "5", "--log", str(log))
    assert r.code == 1 and "the port went away" in r.err and "Traceback" not in r.err
    printed = [ln for ln in r.out.splitlines() if " sample " in ln]
    r2 = run_fsw("replay", str(log), "--headless", "--speed", "0")
    replayed = [ln for ln in r2.out.splitlines() if " sample " in ln]
    assert len(printed) > 10 and replayed == printed  # every frame shown was logged
