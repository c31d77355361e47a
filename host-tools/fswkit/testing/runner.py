"""`fsw` run in this process with its output captured: the tests' way to
run a command without a subprocess (tests/conftest.py hands it out as
`run_fsw` and the `fsw` fixture)."""

from __future__ import annotations

import contextlib
import io
import os


class Ran:
    def __init__(self, code: int, out: str, err: str):
        self.code, self.out, self.err = code, out, err


def run_fsw(*argv: str, cwd: str | os.PathLike | None = None) -> Ran:
    """Runs `fsw ARGV...` in this process and captures its output."""
    from fswkit.cli import main

    out, err = io.StringIO(), io.StringIO()
    old = os.getcwd()
    try:
        if cwd is not None:
            os.chdir(cwd)
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(list(argv))
            except SystemExit as e:  # argparse usage errors
                code = e.code if isinstance(e.code, int) else 2
    finally:
        os.chdir(old)
    return Ran(code, out.getvalue(), err.getvalue())
