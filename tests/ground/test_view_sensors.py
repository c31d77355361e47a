"""The monitor and the web page show each sensor part's health from the
health frames (docs/sensor-table.md): `sensor bmp280@0x76 ok`, a fault
in words (`NO ANSWER`) and marked. No target needed."""

from __future__ import annotations

import io

from rich.console import Console

from fswkit.autocode.protocol import HEALTH_PAYLOAD, HEALTH_TASK, HELLO_PAYLOAD
from fswkit.ground.view import render
from fswkit.link import wire
from fswkit.link.layout import from_app
from fswkit.link.session import Session
from fswkit.web.source import _message
from support.sensor_project import load, write_project


def session(tmp_path) -> tuple[Session, list]:
    lay = from_app(load(write_project(tmp_path, "bmp280 i2c:0x76 pressure=baroP\nadxl345 spi:7 z=accelZ\n",
                                      telemetry=True)))
    s = Session(lay)
    events = s.feed(wire.downlink(wire.HELLO, 0, 0, HELLO_PAYLOAD.pack(wire.PROTOCOL, lay.schema, 0, 0, 1, 0, 0,
                                                                        0x01, 0, 0)), 100.0)
    head = HEALTH_PAYLOAD.pack(0, 1, 0, 100, 0, 0x01, 0, 0, 0, 0, 0, 0, 0, 0)
    tasks = b"".join(HEALTH_TASK.pack(2, 0, 0, 50) for _ in lay.tasks)
    events += s.feed(wire.downlink(wire.HEALTH, 1, 1000, head + tasks + bytes([1, 2])), 100.5)
    return s, events


def test_the_monitor_shows_each_parts_health(tmp_path):
    s, _ = session(tmp_path)
    con = Console(record=True, width=120, height=40, file=io.StringIO())
    con.print(render(s, 100.6, "p on /dev/ttyACM0", (120, 40), [], 100.5, "", 100.0))
    text = con.export_text()
    assert "sensor bmp280@0x76 ok" in text
    assert "sensor adxl345@spi:7 NO ANSWER" in text


def test_the_web_page_gets_each_parts_health(tmp_path):
    s, events = session(tmp_path)
    msg = _message(next(e for e in events if e.kind == "health"), s.layout)
    assert msg["info"]["sensors"] == [{"name": "bmp280@0x76", "code": 1, "fault": False, "words": "ok"},
                                      {"name": "adxl345@spi:7", "code": 2, "fault": True, "words": "NO ANSWER"}]
