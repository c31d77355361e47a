"""The monitor and the web page show each sensor part's health from the
health frames (docs/sensor-table.md): `sensor bmp280@0x76 ok`, a fault
in words (`NO ANSWER`) and marked. No target needed."""

from __future__ import annotations

import io

from rich.console import Console

from fswkit.autocode.app import load_app
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.protocol import HEALTH_PAYLOAD, HEALTH_TASK, HELLO_PAYLOAD
from fswkit.ground.view import render
from fswkit.link import wire
from fswkit.link.layout import from_app
from fswkit.link.session import Session
from fswkit.web.source import _message

SV = "[Data]\nU64 time\nU32 state\nF32 baroP\nF32 accelZ\nbool high\n"
SM = "[state_vector]\nU64 time @alias G\nU32 state @alias S\nF32 baroP @read_only\nbool high\n\n[Run]\n.step\n" \
     "    high = baroP > 100000\n"
APP = """\
[application]
board native
rate 100
[configs]
state_vector p.sv
machine p.sm
io p.sns
[tasks]
sense inputs rate=100
control machine p rate=100
down telemetry rate=50
[telemetry]
Data rate=10
"""


def session(tmp_path) -> tuple[Session, list]:
    (tmp_path / "p.sv").write_text(SV)
    (tmp_path / "p.sm").write_text(SM)
    (tmp_path / "p.sns").write_text("bmp280 i2c:0x76 pressure=baroP\nadxl345 spi:7 z=accelZ\n")
    (tmp_path / "p.app").write_text(APP)
    d = Diagnostics()
    app = load_app(str(tmp_path / "p.app"), d)
    assert app is not None, d.render()
    lay = from_app(app)
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
