"""docs/recorder.md's worked example is a record the tests/recorder/logged
rig writes, and decodes to what the document says it holds."""

from __future__ import annotations

import os
import re
import shutil

import pytest

from conftest import ROOT, run_fsw

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
    assert (r.kind, r.seq, r.flight, r.t0, r.period, raw[p.record - 3]) == (0xF1, 1, 1, 200, 20, 57)
    assert [t for t, _ in r.samples] == list(range(200, 461, 20))
    assert [v["state"] for _, v in r.samples] == [1] * 6 + [2] * 8
    assert [v["level"] for _, v in r.samples] == [t / 4 for t in range(200, 461, 20)]
    assert [v["count"] for _, v in r.samples] == [0] * 6 + list(range(2, 17, 2))
    assert int.from_bytes(raw[-2:], "little") == 0x5A86
    assert [f.name for f in p.fields] == ["state", "level", "count"]  # held, delta, raw: the document's order


@pytest.mark.skipif(shutil.which("avr-g++") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                    reason="gcc-avr and libsimavr-dev are needed (make setup)")
def test_the_rig_writes_the_worked_example(tmp_path):
    """The example is the second record of the rig's first flight on the
    simulated Uno, pin 2 raised 0.3 s after boot."""
    from fswkit.sim.board import SimBoard

    rig = ROOT / "tests" / "recorder" / "logged"
    r = run_fsw("build", str(rig), "--out", str(tmp_path))
    assert r.code == 0, r.err
    p = plan(load_app(str(rig / "logged.app"), Diagnostics()))
    with SimBoard(str(tmp_path / "logged.elf"), "uno", uart="none") as b:
        b.eeprom_write(p.base, bytes(p.size))
        b.run_for(0.3)
        b.set_digital(2, True)
        b.run_for(1.0)
        assert b.eeprom_read(p.base + p.record, p.record) == example()
