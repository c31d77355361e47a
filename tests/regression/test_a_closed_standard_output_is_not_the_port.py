"""`fsw machine PROJECT list --port P | true` (or `| head -1` of an upload's
report) said `fsw machine: P: the port went away ([Errno 32] Broken pipe)`
and exited 1: the commands that talk to a target (`fsw machine`, `fsw
param`, `fsw dump`) took every OSError in their talk for the port's, and
the reader of their standard output going away is one. As everywhere else
(docs/cli.md, "Output files") a reader that goes away is not a failure:
nothing said, status 0. The target is stubbed: the link opened, its
MACHINE_INFO answered."""

from __future__ import annotations

import contextlib
import io

from conftest import EXAMPLES

from fswkit.reload.client import NONE, Info, MachineClient, Slot


class Gone(io.StringIO):
    """A standard output whose reader has gone away."""

    def write(self, text):
        raise BrokenPipeError(32, "Broken pipe")


class Link:
    session = None

    def close(self):
        pass


def test_a_reader_that_goes_away_is_not_the_port_going_away(monkeypatch):
    from fswkit.cli import common
    from fswkit.cli.main import main

    monkeypatch.setattr(common, "open_link", lambda *a: Link())
    info = Info(0, NONE, 0, 0, False, 384, 64, 0, 0, 0, 0, 0, (Slot(1, 0, 0, 0, 0, 0), Slot(2, 0, 0, 0, 0, 0)))
    monkeypatch.setattr(MachineClient, "info", lambda self: info)
    err = io.StringIO()
    with contextlib.redirect_stdout(Gone()), contextlib.redirect_stderr(err):
        code = main(["machine", str(EXAMPLES / "stand"), "list", "--port", "/dev/ttyNOPE"])
    assert "went away" not in err.getvalue() and code == 0, err.getvalue()
