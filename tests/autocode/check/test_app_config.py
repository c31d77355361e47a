"""The application config and I/O tables: every check with its located
message, and what the generated entry point wires up."""

from __future__ import annotations

import shutil
import struct
import subprocess

import pytest

SV = """\
[Sensors]
U64 time
U32 state
F64 pressure
F32 temp
bool button
[Control]
U8 controlMode
U16 controlOverruns
U32 controlWorst
U8 resetCause
bool valve
F32 heater
U16 notMode
"""

SM = """\
[state_vector]
U64 time @alias G
U32 state @alias S
F64 pressure @read_only
bool valve

[Run]
.step
    valve = pressure > 100
"""

APP = """\
[application]
board uno
rate 100
reset_cause resetCause

[configs]
state_vector rig.sv
machine rig.sm
io rig.aio
io rig.dio

[time]
source cycle
unit ms

[tasks]
sense inputs rate=100
control machine rig rate=50 mode=controlMode overruns=controlOverruns worst_us=controlWorst
act outputs rate=100

[uplink]
heater
"""

AIO = """\
i A0 pressure scale=250 offset=-125
o 3 heater
"""

DIO = """\
i 2 button
o 4 valve
"""


def project(tmp_path, app=APP, aio=AIO, dio=DIO, sm=SM):
    for name, text in (("rig.sv", SV), ("rig.sm", sm), ("rig.app", app), ("rig.aio", aio), ("rig.dio", dio)):
        (tmp_path / name).write_text(text)
    return tmp_path


def test_valid_project_checks_clean(fsw, tmp_path):
    r = fsw("check", str(project(tmp_path) / "rig.app"))
    assert r.code == 0, r.err


@pytest.mark.parametrize("where, old, new, message", [
    ("app", "board uno", "board pdp11", "application config error @ {p}/rig.app:2:7:\n  | board pdp11\n  |       ^ unknown board `pdp11`"),
    ("app", "rate=50", "rate=30", "rig.app:18:26:\n  | control machine rig rate=30 mode=controlMode overruns=controlOverruns worst_us=controlWorst\n  |                          ^ task rate 30 Hz must divide the executor rate 100 Hz"),
    ("app", "mode=controlMode", "mode=notMode", "^ a task's mode element must be U8 (0 disabled, 1 safed, 2 enabled); `notMode` is U16"),
    ("app", "overruns=controlOverruns", "overruns=controlWorst", "`overruns` needs a U16 element; `controlWorst` is U32"),
    ("app", "machine rig rate", "machine rog rate", "unknown machine `rog` (machines: rig)"),
    ("app", "control machine rig", "control inputs", "machine `rig` runs in no task"),
    ("app", "sense inputs", "sense telepathy", "expected what the task runs: one of inputs, outputs, machine, telemetry, uplink"),
    ("app", "heater\n", "time\n", "element `time` is `G` of machine `rig`: it cannot be written over the uplink"),
    ("app", "heater\n", "pressure\n", "element `pressure` is written by input channel"),
    ("app", "reset_cause resetCause", "reset_cause heater", "`reset_cause` needs a U8 element; `heater` is F32"),
    ("app", "rate 100", "rate 3", "`rate` must be a whole number of cycles per second that divides 1000000"),
    ("app", "[uplink]", "[downlink]", "unknown section `[downlink]`"),
    ("app", "[uplink]\n", "[telemetry]\nSensors rate=10 batch=4\n[uplink]\n", "unknown stream setting `batch`: a stream takes `rate=HZ`"),
    ("app", "[uplink]", "[budget]\nflash 40000\n[uplink]", "^ a flash budget of 40,000 B is more than the uno has (32,256 B)"),
    ("app", "[uplink]", "[budget]\nram 1.5\n[uplink]", "`ram` is a whole number of bytes, found `1.5`"),
    ("app", "[uplink]", "[budget]\nstack 100\n[uplink]", "unknown budget `stack`: expected `flash` or `ram` (bytes)"),
    ("app", "[uplink]", "[budget]\nram 100\nram 200\n[uplink]", "`ram` is given twice"),
    ("app", "[uplink]", "[budget]\nram 100 200\n[uplink]", "`ram` takes one value, a number of bytes"),
    ("aio", "i A0", "i A7", "I/O config error @ {p}/rig.aio:1:3:\n  | i A7 pressure scale=250 offset=-125\n  |   ^ board `uno` has no pin `A7`"),
    ("aio", "o 3 heater", "o 4 heater", "pin `4` of `uno` cannot drive PWM (PWM pins: 3, 5, 6, 11)"),
    ("aio", "o 3 heater", "o 10 heater",
     "pin `10` of `uno` cannot drive PWM: its timer (Timer1) paces the executor (PWM pins: 3, 5, 6, 11)"),
    ("aio", "i A0 pressure", "i A0 button", "analog channels need an F32 or F64 element; `button` is bool"),
    ("aio", "scale=250", "scale=", "expected a number after `scale=`"),
    ("dio", "i 2 button", "i 0 button", "pin `0` is reserved on `uno`: serial RX (USART0)"),
    ("dio", "o 4 valve", "o 3 valve", "pin `3` is already used ("),
    ("dio", "i 2 button", "i 2 temp", "digital channels need a bool element; `temp` is F32"),
    ("dio", "i 2 button", "x 2 button", "expected a direction `i` or `o`, found `x`"),
])
def test_errors_are_located(fsw, tmp_path, where, old, new, message):
    texts = {"app": APP, "aio": AIO, "dio": DIO}
    assert old in texts[where]
    texts[where] = texts[where].replace(old, new, 1)
    p = project(tmp_path, texts["app"], texts["aio"], texts["dio"])
    r = fsw("check", str(p / "rig.app"))
    assert r.code == 1
    assert message.format(p=tmp_path) in r.err


@pytest.mark.skipif(shutil.which("g++") is None, reason="no host C++ compiler")
def test_entry_point_wires_modes_and_cycle_time(fsw, tmp_path):
    p = project(tmp_path)
    out = tmp_path / "out"
    r = fsw("build", str(p), "--board", "native", "--out", str(out))
    assert r.code == 0, r.err
    gen = (out / "gen" / "app.gen.cpp").read_text()
    assert "E_controlMode, E_controlOverruns, E_controlWorst, 2}" in gen
    assert "kPeriodUs, E_resetCause, 3, kSvLock" in gen
    sv = bytes.fromhex(subprocess.run([str(out / "rig"), "7"], capture_output=True, text=True,
                                      check=True).stdout.strip())
    # `source cycle`: G = cycles x 10 ms; the machine runs every other cycle,
    # last in cycle 6 (0-based), at G = 60 ms.
    assert int.from_bytes(sv[0:8], "little") == 60
    assert sv[25] == 2  # controlMode: enabled at boot
    # The simulated transducer reads 0 V: -125 through the calibration, and
    # the machine keeps the valve closed (pressure > 100 is false).
    assert struct.unpack("<d", sv[12:20])[0] == -125.0
    assert len(sv) == 40
    assert sv[33] == 0  # valve: Sensors (25 B), then controlMode, controlOverruns, controlWorst, resetCause
