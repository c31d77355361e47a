"""A load the ground left open (`fsw param load` stopped by Ctrl-C, a crash
or a link gone between PARAM_BEGIN and PARAM_COMMIT) kept the store
"writing" until the next reset: every SET and SAVE answered BUSY, so
`fsw param set` waited its 30 s and failed, and nothing could be saved,
on the stand or on the pad. An open load that is not committed holds
nothing the live values depend on: now a SET changes the live values (a
late COMMIT of that load finds its block changed: MISMATCH), and a SAVE
ends the load (its STAGE and COMMIT answer NO_LOAD) and writes the live
values to the bank, the staged ones never taking effect."""

from __future__ import annotations

import struct
import time
from pathlib import Path

import pytest

from conftest import run_fsw
from support.linkfw import PtyTarget, needs_cxx
from support.simfw import kept_native

pytestmark = needs_cxx()
RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"


@pytest.fixture(scope="module")
def exe():
    return kept_native(RIG) / "tuned"


class Raw:
    """One ground's own commands, by hand (the part of a load it sent)."""

    def __init__(self, port: str):
        from fswkit.autocode.diagnostics import Diagnostics
        from fswkit.link.client import Ground
        from fswkit.link.layout import from_app
        from fswkit.link.port import open_port
        from fswkit.link.session import Session
        from fswkit.target.build import load

        app = load(str(RIG), Diagnostics())
        from fswkit.autocode.params import app_parameters

        self.params = {p.name: p for p in app_parameters(app)}
        self.port = open_port(port, 115200)
        self.g = Ground(self.port, Session(from_app(app)))
        self.g.handshake()

    def cmd(self, op: int, args: bytes = b"") -> int:
        return self.g.command(op, args)["status"]

    def stage(self, name: str, value) -> int:
        from fswkit.autocode.protocol import OP_PARAM_STAGE

        p = self.params[name]
        return self.cmd(OP_PARAM_STAGE, bytes((p.id,)) + p.pack(value))

    def close(self):
        self.port.close()


def param(port, *args):
    return run_fsw("param", str(RIG), *args, "--port", port)


def test_set_and_save_after_a_load_left_open(exe, tmp_path):
    from fswkit.autocode.protocol import OP_PARAM_BEGIN, OP_PARAM_COMMIT

    eeprom = str(tmp_path / "e.bin")
    with PtyTarget(exe, "--eeprom", eeprom) as t:
        time.sleep(0.2)
        raw = Raw(t.port)
        try:
            assert raw.cmd(OP_PARAM_BEGIN) == 0
            assert raw.stage("TRIM", 9) == 0
        finally:
            raw.close()  # the loader is gone: no COMMIT
        start = time.monotonic()
        r = param(t.port, "set", "OPEN_AT=700")
        assert r.code == 0, r.err
        assert time.monotonic() - start < 10
        r = param(t.port, "save")
        assert r.code == 0 and "saved in bank A (sequence 1)" in r.out, r.out + r.err
        r = param(t.port, "list")
        assert "(bank A, sequence 1;" in r.out and "writing" not in r.out and "unsaved" not in r.out, r.out
        raw = Raw(t.port)
        try:  # the load was ended by the save: what is left of it is refused
            assert raw.stage("TRIM", 9) == 12  # NO_LOAD
            assert raw.cmd(OP_PARAM_COMMIT, struct.pack("<H", 0)) == 12
        finally:
            raw.close()
    with PtyTarget(exe, "--eeprom", eeprom) as t:  # the saved set, without the staged value
        time.sleep(0.2)
        r = param(t.port, "get", "OPEN_AT", "TRIM")
        assert r.out.splitlines() == ["OPEN_AT = 700", "TRIM = -3"], r.out + r.err


def test_a_late_commit_of_a_load_a_set_went_between_is_refused(exe, tmp_path):
    from fswkit.autocode.params import app_parameters, value_block
    from fswkit.autocode.protocol import OP_PARAM_BEGIN, OP_PARAM_COMMIT, crc16
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import load

    params = app_parameters(load(str(RIG), Diagnostics()))
    with PtyTarget(exe, "--eeprom", str(tmp_path / "e.bin")) as t:
        time.sleep(0.2)
        raw = Raw(t.port)
        try:
            assert raw.cmd(OP_PARAM_BEGIN) == 0
            assert raw.stage("TRIM", 9) == 0
            crc = crc16(value_block(params, {"TRIM": 9}))  # the block the loader expects: the defaults but TRIM
        finally:
            raw.close()
        assert param(t.port, "set", "OPEN_AT=700").code == 0
        raw = Raw(t.port)
        try:
            assert raw.cmd(OP_PARAM_COMMIT, struct.pack("<H", crc)) == 13  # MISMATCH: OPEN_AT changed meanwhile
        finally:
            raw.close()
        r = param(t.port, "get", "OPEN_AT", "TRIM")
        assert r.out.splitlines() == ["OPEN_AT = 700", "TRIM = -3"], r.out + r.err
