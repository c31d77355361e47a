"""A log whose header is valid JSON but holds a field of the wrong type or
value is refused by every log tool with `not a valid log: field X ...`,
before decoding: never a traceback from deep inside the decoder."""

from __future__ import annotations

import copy
import json
import struct

import pytest
from conftest import run_fsw
from support.linkstream import write_log

from fswkit.link.log import MAGIC


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    path = write_log(tmp_path_factory.mktemp("header") / "good.log", 100)
    data = path.read_bytes()
    (n,) = struct.unpack_from("<I", data, len(MAGIC))
    start = len(MAGIC) + 4
    return json.loads(data[start:start + n]), data[start + n:]


def _set(d, path, value):
    keys = path.split(".")
    for k in keys[:-1]:
        d = d[int(k)] if isinstance(d, list) else d[k]
    last = keys[-1]
    if value is KeyError:
        del d[last]
    elif isinstance(d, list):
        d[int(last)] = value
    else:
        d[last] = value


CASES = [
    ("layout.sv_size", "21", "layout.sv_size"),
    ("layout.time_unit", 5, "layout.time_unit"),
    ("layout.rate", 0, "layout.rate"),
    ("layout.schema", -1, "layout.schema"),
    ("layout.health_payload", None, "layout.health_payload"),
    ("layout.elements.0.type", "U9", "layout.elements[0].type"),
    ("layout.elements.0.type", [], "layout.elements[0].type"),  # not looked up in the table of types
    ("layout.elements.1.type", {"U8": 1}, "layout.elements[1].type"),
    ("layout.elements.1.offset", 1.5, "layout.elements[1].offset"),
    ("layout.regions.0", [], "layout.regions[0]"),
    ("layout.streams.0.batch", 0, "layout.streams[0].batch"),
    ("layout.streams.0.period", "0", "layout.streams[0].period"),
    ("layout.streams.0.rate", True, "layout.streams[0].rate"),
    ("layout.tasks", {"a": 1}, "layout.tasks"),
    ("layout.states", [1], "layout.states"),
    ("layout.analog.tankPressure.scale", "250", "layout.analog.tankPressure.scale"),
    ("layout.writable", [3], "layout.writable"),
    ("layout.name", KeyError, "layout.name"),
    ("format", "1", "format"),
    ("layout", "x", "layout"),
]


@pytest.mark.parametrize("field,value,named", CASES, ids=[c[0] for c in CASES])
def test_wrongly_typed_field_is_named(good, tmp_path, field, value, named):
    head, records = good
    head = copy.deepcopy(head)
    _set(head, field, value)
    text = json.dumps(head).encode()
    log = tmp_path / "bad.log"
    log.write_bytes(MAGIC + struct.pack("<I", len(text)) + text + records)
    for argv in (("log2csv", str(log)), ("replay", str(log), "--headless", "--speed", "0"),
                 ("plot", str(log), "-e", "tankPressure", "-o", str(tmp_path / "p.png"))):
        r = run_fsw(*argv)
        assert r.code == 1, (argv, r.err)
        assert "not a valid log" in r.err and f"`{named}`" in r.err, (argv, r.err)
        assert "Traceback" not in r.err and "internal error" not in r.err
