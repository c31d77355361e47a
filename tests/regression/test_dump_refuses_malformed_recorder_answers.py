"""`fsw dump` took the target's LOG_INFO and LOG_READ answers as they
came: one shorter than its fields (a firmware of another kit version, a
link that garbles) was `fsw: internal error: error: unpack_from requires a
buffer of at least 15 bytes`, and a LOG_READ answer carrying more bytes
than asked was appended as it was, every later record shifted (decoded
as torn, or refused many records later by chance). Each answer is now
checked: one shorter than its fields, or with more bytes than asked, is
said, naming the record and byte, with status 1."""

from __future__ import annotations

import struct
import sys
from pathlib import Path

import pytest

from conftest import run_fsw

from fswkit.autocode.app import load_app
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.protocol import OP_LOG_INFO, OP_LOG_READ
from fswkit.autocode.recorder import plan

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from support.recorder_image import FakeGround, data_record, fake_target, image, start_record  # noqa: E402

RIG = Path(__file__).resolve().parent.parent / "recorder" / "logged"


class Garbled(FakeGround):
    def __init__(self, p, store, how: str, **kw):
        super().__init__(p, store, **kw)
        self.how = how

    def command(self, op, a, tries=5, timeout=0.5):
        ack = super().command(op, a)
        if op == OP_LOG_INFO and self.how == "short info":
            ack["data"] = ack["data"][:5]
        if op == OP_LOG_READ and self.how == "short read":
            ack["data"] = ack["data"][:2]
        if op == OP_LOG_READ and self.how == "long read":
            slot, off, n = struct.unpack("<HBB", a)
            at = slot * self.p.record + off
            ack["data"] = struct.pack("<HBB", slot, off, n + 3) + bytes(self.store[at:at + n + 3])
        return ack


@pytest.mark.parametrize("how, said", [("short info", "LOG_INFO"), ("short read", "record 0 at byte 0"),
                                       ("long read", "record 0 at byte 0")])
def test_a_malformed_answer_is_said(tmp_path, monkeypatch, how, said):
    p = plan(load_app(str(RIG / "logged.app"), Diagnostics()))
    recs = {0: start_record(p, 0, 1, 100),
            1: data_record(p, 1, 1, 100, 20,
                           [[b"\x02", (k * 20).to_bytes(4, "little"), b"\x00\x00"] for k in range(3)])}
    with fake_target(monkeypatch, Garbled(p, image(p, recs), how, head=2, seq=2)):
        r = run_fsw("dump", str(RIG), "--port", "fake", "-o", str(tmp_path / "d"))
    assert r.code == 1 and "internal error" not in r.err, r.out + r.err
    assert said in r.err, r.err
    assert not (tmp_path / "d").exists() or not any((tmp_path / "d").iterdir())
