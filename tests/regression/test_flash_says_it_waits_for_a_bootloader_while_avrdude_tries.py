"""`fsw flash` on a port where no bootloader answers (the wrong port, an
old-bootloader Nano, a board held in reset) printed avrdude's command line
and then nothing for about a minute: avrdude 7.1 tries ten times, 5 s each
(56 s on a pseudo-terminal here), and its output was shown only at the
end. A newcomer takes that for a hang. Each attempt avrdude reports is now
a line on standard error as it happens (`no answer from a bootloader on
PORT yet (attempt 3 of 10; Ctrl-C stops it)`), in avrdude 7's words and
older ones alike; the final message is as before."""

from __future__ import annotations

import os
import pty
import shutil
import stat

import pytest

from conftest import EXAMPLES
from fswkit.target import ports

TANK = EXAMPLES / "tank"

# avrdude 7.1 (Debian 12) and avrdude 6 say each attempt so
ATTEMPTS = {
    "7": "avrdude error: programmer is not responding\navrdude warning: attempt {n} of 10: not in sync: resp=0x00\n",
    "6": "avrdude: stk500_recv(): programmer is not responding\n"
         "avrdude: stk500_getsync() attempt {n} of 10: not in sync: resp=0x00\n",
}


@pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")
@pytest.mark.parametrize("version", sorted(ATTEMPTS))
def test_each_attempt_is_said_as_it_happens(fsw, tmp_path, monkeypatch, version):
    master, slave = pty.openpty()
    port = os.ttyname(slave)
    monkeypatch.setattr(ports, "list_ports", lambda include_all=False: [])
    bindir = tmp_path / "bin"
    bindir.mkdir()
    tool = bindir / "avrdude"
    body = "".join(f"printf '%s' '{ATTEMPTS[version].format(n=n)}' >&2\n" for n in (1, 2, 3))
    tool.write_text("#!/bin/sh\n" + body + "exit 1\n")
    tool.chmod(tool.stat().st_mode | stat.S_IEXEC)
    monkeypatch.setenv("PATH", f"{bindir}{os.pathsep}{os.environ['PATH']}")
    try:
        r = fsw("flash", str(TANK), "--port", port, "--out", str(tmp_path / "build"))
    finally:
        os.close(slave)
        os.close(master)
    assert r.code == 1, r.err
    lines = r.err.splitlines()
    waits = [i for i, line in enumerate(lines)
             if line.startswith(f"fsw flash: no answer from a bootloader on {port} yet (attempt ")]
    assert len(waits) == 3, r.err
    assert "(attempt 3 of 10; Ctrl-C stops it)" in lines[waits[-1]]
    final = [i for i, line in enumerate(lines)
             if line.startswith(f"fsw flash: no answer from a bootloader on {port} (")]
    assert final and final[0] > waits[-1], r.err
