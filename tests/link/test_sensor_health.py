"""Sensor parts in health frames (docs/telemetry.md, docs/sensor-table.md):
after the pyro status bytes, one health code per part in table order. The
ground's layout names the parts (`bmp280@0x76`), the schema covers them,
the session decodes the codes into words, and a native build of an
application whose barometer never answers reports it so on its link."""

from __future__ import annotations

import re

import pytest

from conftest import ROOT, run_fsw
from fswkit.autocode import protocol as P
from fswkit.autocode.app import load_app
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.protocol import HEALTH_PAYLOAD, HEALTH_TASK
from fswkit.autocode.schema import app_schema_hash, link_plan, link_text
from fswkit.link import wire
from fswkit.link.layout import LayoutError, from_app, from_dict
from fswkit.link.session import Session, describe, sensor_status
from support.linkfw import needs_cxx, simulated_link
from support.sensor_project import SNS, load, write_project


def project(tmp, sns: str | None = SNS):
    return load(write_project(tmp, sns, baud=115200, telemetry=True))


def test_the_health_codes_are_the_firmwares():
    h = (ROOT / "firmware" / "src" / "fsw_sensor.h").read_text()
    body = re.search(r"enum SensorHealth : uint8_t \{(.*?)\};", h, re.S).group(1)
    codes = {k: int(v) for k, v in re.findall(r"(kSensor\w+) = (\d+)", body)}
    assert codes == {"kSensorInit": P.SENSOR_INIT, "kSensorOk": P.SENSOR_OK, "kSensorNoAnswer": P.SENSOR_NO_ANSWER,
                     "kSensorBadId": P.SENSOR_BAD_ID, "kSensorBadCalib": P.SENSOR_BAD_CALIB,
                     "kSensorStuck": P.SENSOR_STUCK}
    assert sorted(P.SENSOR_HEALTH) == sorted(codes.values())
    assert P.HEALTH_SENSOR == 1


def test_the_layout_and_the_schema_name_the_parts(tmp_path):
    app = project(tmp_path)
    lay = from_app(app)
    assert lay.sensors == ("bmp280@0x76", "adxl345@spi:7")
    assert from_dict(lay.raw).sensors == lay.sensors  # as a log header keeps it
    plan = link_plan(app)
    assert plan.health_payload == HEALTH_PAYLOAD.size + HEALTH_TASK.size * len(app.tasks) + 2
    assert "sensor bmp280@0x76\nsensor adxl345@spi:7\n" in link_text(app)
    (tmp_path / "p.sns").write_text("bmp280 i2c:0x77 pressure=baroP fault=baroFault\nadxl345 spi:7 -z=accelZ\n")
    other = load_app(str(tmp_path / "p.app"), Diagnostics())
    assert app_schema_hash(other) != app_schema_hash(app)  # another part: another schema


def test_a_layout_without_parts_has_no_sensors_field(tmp_path):
    lay = from_app(project(tmp_path, sns=None))
    assert lay.sensors == () and "sensors" not in lay.raw


def test_a_bad_sensors_field_is_named(tmp_path):
    lay = from_app(project(tmp_path))
    with pytest.raises(LayoutError, match="layout.sensors"):
        from_dict(dict(lay.raw, sensors=[1]))


def health_frame(lay, codes: bytes, seq: int = 1) -> bytes:
    head = HEALTH_PAYLOAD.pack(0, seq, 0, 100, 0, 0x01, 0, 0, 0, 0, 0, 0, 0, 0)
    tasks = b"".join(HEALTH_TASK.pack(2, 0, 0, 100) for _ in lay.tasks)
    pyro = bytes([0x01] * len(lay.pyro))
    return wire.downlink(wire.HEALTH, seq, 1000, head + tasks + pyro + codes)


def test_the_session_reads_a_code_per_part_after_the_pyro_bytes(tmp_path):
    lay = from_app(project(tmp_path))
    raw = dict(lay.raw, pyro=["drogue"], health_payload=lay.health_payload + 1)
    lay = from_dict(raw)  # a pyro byte before the codes
    s = Session(lay, ignore_schema=True)
    ev = [e for e in s.feed(health_frame(lay, bytes([1, 2]))) if e.kind == "health"][0]
    assert ev.info["pyro"][0]["name"] == "drogue" and ev.info["pyro"][0]["armed"]
    assert ev.info["sensors"] == [
        {"name": "bmp280@0x76", "code": 1, "fault": False, "words": "ok"},
        {"name": "adxl345@spi:7", "code": 2, "fault": True, "words": "NO ANSWER"}]
    line = describe(ev, lay)
    assert line.endswith(f" pyro drogue: {ev.info['pyro'][0]['words']}"
                         " sensor bmp280@0x76: ok sensor adxl345@spi:7: NO ANSWER"), line


@pytest.mark.parametrize("code,words,fault", [(0, "init", False), (1, "ok", False), (2, "NO ANSWER", True),
                                              (3, "BAD ID", True), (4, "BAD CALIBRATION", True),
                                              (5, "STUCK", True), (9, "UNKNOWN CODE 9", True)])
def test_each_code_in_words(code, words, fault):
    assert sensor_status("ms5611@0x77", code) == {"name": "ms5611@0x77", "code": code, "fault": fault,
                                                  "words": words}


@needs_cxx()
def test_a_native_app_whose_parts_never_answer_says_so(tmp_path):
    """The native board's TWI answers nobody unless a test scripts it, and its
    SPI reads 0xFF: both parts fail their first transaction and are faults
    in every health frame after it."""
    app = project(tmp_path)
    r = run_fsw("build", str(tmp_path), "--board", "native", "--out", str(tmp_path / "build"))
    assert r.code == 0, r.err
    data = simulated_link(tmp_path / "build" / "p", 500, "--uart", "115200")  # 5 simulated seconds
    s = Session(from_app(app))
    healths = [e for e in s.feed(data) if e.kind == "health"]
    assert s.stats.lost == 0 and s.deframer.stats.crc_errors == 0
    assert len(healths) >= 4
    last = healths[-1].info["sensors"]
    assert [(x["name"], x["words"], x["fault"]) for x in last] == [("bmp280@0x76", "NO ANSWER", True),
                                                                   ("adxl345@spi:7", "NO ANSWER", True)]
