"""docs/recorder.md's worked example is a record the tests/recorder/logged
rig writes, and decodes to what the document says it holds."""

from __future__ import annotations

import re

from conftest import ROOT

from fswkit.autocode.app import load_app
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.recorder import decode_slot, plan, valid

DOC = ROOT / "docs" / "recorder.md"


def example() -> bytes:
    text = DOC.read_text()
    m = re.search(r"<!-- worked-example[^>]*-->\n```\n(.*?)```", text, re.S)
    assert m, "the worked example's block"
    return bytes.fromhex(m.group(1).replace("\n", " "))


def test_the_worked_example_decodes_as_the_document_says():
    p = plan(load_app(str(ROOT / "tests" / "recorder" / "logged" / "logged.app"), Diagnostics()))
    raw = example()
    assert len(raw) == p.record == 64 and valid(p, raw)
    r = decode_slot(p, 1, raw)
    assert (r.kind, r.seq, r.flight, r.t0, r.period, raw[p.record - 3]) == (0xF1, 1, 1, 200, 20, 42)
    assert [t for t, _ in r.samples] == list(range(200, 361, 20))
    assert [v["state"] for _, v in r.samples] == [1] * 6 + [2] * 3
    assert [v["level"] for _, v in r.samples] == [t / 4 for t in range(200, 361, 20)]
    assert [v["count"] for _, v in r.samples] == [0] * 6 + [2, 4, 6]
    assert int.from_bytes(raw[-2:], "little") == 0xAB8E
    assert [f.name for f in p.fields] == ["state", "level", "count"]  # held, delta, raw: the document's order
