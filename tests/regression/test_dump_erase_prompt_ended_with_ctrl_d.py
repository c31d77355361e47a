"""`fsw dump --erase` at a terminal asks before erasing; answering with
Ctrl-D (the end of input) was `fsw: internal error: EOFError`. No answer
is no: nothing is erased."""

from __future__ import annotations

import io
import sys
import time
from pathlib import Path

from conftest import run_fsw
from support.linkfw import PtyTarget, needs_cxx
from support.simfw import kept_native

pytestmark = needs_cxx()
LOGGED = Path(__file__).resolve().parent.parent / "recorder" / "logged"


class EndedTerminal(io.StringIO):
    """A terminal whose user pressed Ctrl-D."""

    def isatty(self) -> bool:
        return True


def test_ctrl_d_at_the_erase_prompt_erases_nothing(tmp_path, monkeypatch):
    exe = kept_native(LOGGED) / "logged"
    with PtyTarget(exe, "--eeprom", str(tmp_path / "e.bin"), "d2=1") as t:
        time.sleep(1.6)  # Idle -> Run (the flight, 1 s) -> Done: erasing is allowed
        monkeypatch.setattr(sys, "stdin", EndedTerminal(""))
        r = run_fsw("dump", str(LOGGED), "--port", t.port, "-o", str(tmp_path / "d"), "--erase")
        assert r.code == 0 and "not erased" in r.out and "internal error" not in r.err, r.out + r.err
        monkeypatch.undo()
        r = run_fsw("dump", str(LOGGED), "--port", t.port, "-o", str(tmp_path / "again"))
        assert r.code == 0 and "1 flight(s)" in r.out, r.out + r.err
