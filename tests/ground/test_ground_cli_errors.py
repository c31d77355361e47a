"""Bad input to the link commands: a clear message and a non-zero exit,
never a traceback. None of these needs a target."""

from __future__ import annotations

import shutil

from conftest import run_fsw
from fswkit.autocode.protocol import HELLO_PAYLOAD
from fswkit.link import wire
from fswkit.link.layout import from_dict
from fswkit.link.log import LogWriter
from support.linkfw import TANK, tank_layout


def clean(r):
    assert "Traceback" not in r.err and "internal error" not in r.err, r.err
    return r


def test_port_that_does_not_exist():
    r = clean(run_fsw("monitor", str(TANK), "--port", "/dev/no-such-port", "--headless"))
    assert r.code == 1 and "cannot open /dev/no-such-port" in r.err


def test_commands_are_checked_before_the_port_is_opened():
    cases = [
        (("set", "valveOpn", "1"), "unknown element `valveOpn`"),
        (("set", "valveOpen", "maybe"), "`valveOpen` is bool"),
        (("set", "valveOpen"), "usage: fsw cmd set ELEMENT VALUE"),
        (("mode", "contrl", "safed"), "unknown task `contrl`"),
        (("mode", "control", "asleep"), "unknown mode `asleep`"),
        (("ping", "now"), "takes no arguments"),
    ]
    for argv, msg in cases:
        r = clean(run_fsw("cmd", *argv, "--port", "/dev/no-such-port", "-p", str(TANK)))
        assert r.code == 2 and msg in r.err, (argv, r.err)  # a wrong command line


def test_values_out_of_range_for_the_type():
    from fswkit.link.layout import Element, LayoutError, encode_value
    import pytest

    u8 = Element(0, "x", "U8", 0, "R")
    assert encode_value(u8, "255") == b"\xff"
    with pytest.raises(LayoutError, match="outside 0..255"):
        encode_value(u8, "256")
    with pytest.raises(LayoutError, match="not a whole number"):
        encode_value(u8, "1.5")
    f32 = Element(0, "y", "F32", 0, "R")
    with pytest.raises(LayoutError, match="out of its range"):
        encode_value(f32, "1e39")
    assert encode_value(Element(0, "z", "I16", 0, "R"), "-2") == b"\xfe\xff"


def test_project_without_uplink(tmp_path):
    other = tmp_path / "tank"
    shutil.copytree(TANK, other, ignore=shutil.ignore_patterns("build"))
    app = (other / "tank.app").read_text().replace("uplink   uplink        rate=100\n", "")
    (other / "tank.app").write_text(app)
    r = clean(run_fsw("cmd", "ping", "--port", "/dev/null", "-p", str(other)))
    # a project missing the section a command needs is status 2, as for fsw param, dump and machine
    assert r.code == 2 and "has no `uplink` task" in r.err


def test_project_that_is_not_one(tmp_path):
    r = clean(run_fsw("monitor", str(tmp_path), "--port", "/dev/null"))
    assert r.code == 2 and "expected one application config" in r.err


def test_logs_that_are_not_logs(tmp_path):
    junk = tmp_path / "junk.bin"
    junk.write_bytes(b"\x00\x01garbage")
    for cmd in (("log2csv", str(junk)), ("replay", str(junk), "--headless"),
                ("plot", str(junk), "-e", "x", "-o", str(tmp_path / "x.png"))):
        r = clean(run_fsw(*cmd))
        assert r.code == 1 and "not an fswkit link log" in r.err
    r = clean(run_fsw("log2csv", str(tmp_path / "missing.fswlog")))
    assert r.code == 1 and "cannot read" in r.err


def test_truncated_log_and_unknown_plot_element(tmp_path):
    lay = tank_layout()
    path = tmp_path / "cut.fswlog"
    w = LogWriter(str(path), lay)
    hello = HELLO_PAYLOAD.pack(wire.PROTOCOL, lay.schema, 0, 0, 0, 1, 0, 0, 0, 0)
    w.record(0, 1, wire.downlink(wire.HELLO, 0, 0, hello))
    sensors = (7).to_bytes(8, "little") + (1).to_bytes(4, "little") + bytes(8)
    w.record(0, 2, wire.downlink(0x80, 1, 10, sensors))
    w.close()
    data = path.read_bytes()
    path.write_bytes(data + b"\x00\x01\x02")  # a record cut short
    r = clean(run_fsw("log2csv", str(path)))
    assert r.code == 0 and "cut short" in r.err
    assert r.out.splitlines()[1].startswith("0.010,0.000000,1,Sensors,7,")  # 10 ms; the element `time` is 7
    r = clean(run_fsw("plot", str(path), "-e", "pressure", "-o", str(tmp_path / "p.png")))
    assert r.code == 2 and "-e: unknown element `pressure`" in r.err
    r = clean(run_fsw("plot", str(path), "-e", "tankPressure", "-o", str(tmp_path / "no" / "p.png")))
    assert r.code == 1 and "cannot write" in r.err


def test_layout_round_trips_through_json():
    lay = tank_layout()
    again = from_dict(lay.raw)
    assert again.schema == lay.schema and again.streams[0].batch == lay.streams[0].batch
    assert again.states == lay.states


def test_live_view_renders_every_element_and_the_link():
    from rich.console import Console

    from fswkit.link.session import Session
    from fswkit.ground.view import render

    lay = tank_layout()
    s = Session(lay)
    hello = HELLO_PAYLOAD.pack(wire.PROTOCOL, lay.schema, 0, 0, 0, 1, 0, 0, 0, 0)
    import struct
    sensors = struct.pack("<QId", 20, 2, 815.5)
    s.feed(wire.downlink(wire.HELLO, 0, 0, hello) + wire.downlink(0x80, 1, 20, sensors), 1.0)
    con = Console(width=120, height=40, record=True)
    con.print(render(s, 1.0, "tank", (120, 40)))
    text = con.export_text()
    for name in ("time", "state", "tankPressure", "valveOpen", "frames/s", "CRC errors", "schema"):
        assert name in text
    assert "2 (Abort)" in text and "815.5" in text and "pin A0" in text
