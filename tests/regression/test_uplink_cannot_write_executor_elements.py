"""`[uplink]` could list a task's mode element, the uplink's own included:
`fsw cmd set upMode 0` was acknowledged and the ground was locked out for
good; `set controlMode 7` left a safed task reading 7. The elements the
executor writes (every task's mode, overruns and worst_us, the reset
cause; a machine's `G` and `S`) are refused in `[uplink]` by `fsw check`,
and the firmware itself refuses a SET of any of them (LOCKED) even from a
writable table that lists one, as it refuses a MODE that would disable or
safe the uplink task."""

from __future__ import annotations

import dataclasses
import os
import pty
import shutil
import struct
import subprocess
import time
import tty

import pytest

SV = """\
[Flight]
U64 time
U32 state
F32 alt
[Cmd]
U8 upMode
U8 controlMode
U16 ctlOver
U32 ctlWorst
U8 cause
F32 heater
"""

SM = """\
[state_vector]
U64 time @alias G
U32 state @alias S
F32 alt

[Idle]
.step
    alt = alt + 1
"""

APP = """\
[application]
board {board}
reset_cause cause

[configs]
state_vector rig.sv
machine rig.sm

[tasks]
up       uplink             mode=upMode
control  machine rig        mode=controlMode overruns=ctlOver worst_us=ctlWorst
down     telemetry

[telemetry]
Cmd rate=20

[uplink]
{uplink}
"""


def project(tmp_path, uplink="heater", board="uno"):
    for name, text in (("rig.sv", SV), ("rig.sm", SM), ("rig.app", APP.format(uplink=uplink, board=board))):
        (tmp_path / name).write_text(text)
    return tmp_path / "rig.app"


def test_an_ordinary_element_is_writable(fsw, tmp_path):
    r = fsw("check", str(project(tmp_path)))
    assert r.code == 0, r.err


@pytest.mark.parametrize("element, owner", [
    ("upMode", "the mode of task `up`"),
    ("controlMode", "the mode of task `control`"),
    ("ctlOver", "the overruns of task `control`"),
    ("ctlWorst", "the worst_us of task `control`"),
    ("cause", "the reset cause"),
    ("state", "`S` of machine `rig`"),
    ("time", "`G` of machine `rig`"),
])
def test_executor_elements_are_refused(fsw, tmp_path, element, owner):
    p = project(tmp_path, uplink=f"heater\n{element}")
    r = fsw("check", str(p))
    assert r.code != 0
    assert f"application config error @ {p}:19:1:" in r.err, r.err
    assert f"element `{element}` is {owner}: it cannot be written over the uplink" in r.err, r.err
    assert "Traceback" not in r.err


# ---- the firmware, end to end: a writable table that lists them anyway ---------

@pytest.fixture(scope="module")
def target(tmp_path_factory):
    if shutil.which("g++") is None:
        pytest.skip("no host C++ compiler")
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.emit.app import emit_app
    from fswkit.target.build import load, make, write_files
    from fswkit.link.layout import from_app

    folder = tmp_path_factory.mktemp("forged")
    project(folder, board="native")
    app = load(str(folder), Diagnostics())
    assert app is not None
    sv = app.sv
    # what a hand-written table, or a checker that let them through, would hold
    app = dataclasses.replace(app, writable=app.writable + tuple(
        sv.find(n) for n in ("upMode", "controlMode", "ctlOver", "ctlWorst", "cause")))
    out = folder / "build"
    write_files(emit_app(app), str(out / "gen"))
    exe, proc = make(app, str(out))
    assert proc.returncode == 0, proc.stderr
    master, slave = pty.openpty()
    tty.setraw(slave)
    proc = subprocess.Popen([exe], stdin=master, stdout=master, stderr=subprocess.DEVNULL)
    os.close(master)
    try:
        time.sleep(0.3)
        yield os.ttyname(slave), from_app(app)
    finally:
        proc.kill()
        proc.wait(timeout=5)
        os.close(slave)


def test_firmware_refuses_set_of_executor_elements(target):
    from fswkit.link import wire
    from fswkit.link.client import Ground
    from fswkit.link.port import open_port
    from fswkit.link.session import Session

    tty_path, layout = target
    port = open_port(tty_path, 115200)
    try:
        s = Session(layout)
        g = Ground(port, s)
        g.handshake()
        for name, value in (("upMode", b"\x00"), ("controlMode", b"\x07"), ("ctlOver", b"\x01\x00"),
                            ("ctlWorst", b"\x01\x00\x00\x00"), ("cause", b"\x09")):
            ack = g.command(wire.OP_SET, struct.pack("<H", layout.element(name).index) + value)
            assert wire.STATUS[ack["status"]][0] == "LOCKED", (name, ack)
        up = layout.task_index("up")
        for mode in (0, 1):
            ack = g.command(wire.OP_MODE, bytes((up, mode)))
            assert wire.STATUS[ack["status"]][0] == "LOCKED", (mode, ack)
        # the ground is not locked out: an ordinary SET still applies
        ack = g.command(wire.OP_SET, struct.pack("<Hf", layout.element("heater").index, 2.5))
        assert ack["status"] == 0, ack
        s.values["upMode"] = None
        deadline = time.monotonic() + 2
        while (s.values["upMode"] is None or s.values["heater"] != 2.5) and time.monotonic() < deadline:
            g.read()
        assert (s.values["upMode"], s.values["controlMode"]) == (2, 2)
        assert s.values["cause"] != 9
        assert s.values["heater"] == 2.5
    finally:
        port.close()
