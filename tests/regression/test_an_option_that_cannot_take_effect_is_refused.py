"""Options that could do nothing were taken without a word: `--force`
without the output it lets replace a file (`fsw test` without `--trace`,
`fsw graph`, `fsw skeleton` and `fsw log2csv` without `-o FILE` or with
`-o -`, `fsw compile -o -` without `--layout`, `fsw tape import -o -`,
`fsw monitor` without `--log`, `fsw param` without `list -o FILE`), and
`fsw dump --yes` without `--erase`. A user who typed one believed it did
something.

Now each is refused before any work, as `fsw machine` refuses an option
given to an action it means nothing to: status 2, naming the option and
what it goes with (`fsw graph: --force goes with -o FILE: ...`). With what
it needs, the option is taken as before."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES, run_fsw
from support.linkfw import TANK

ROCKET = EXAMPLES / "rocket"
SM = str(TANK / "tank.sm")
NO_PORT = "/dev/no-such-port"


def refused(r, msg):
    assert "Traceback" not in r.err and "internal error" not in r.err, r.err
    assert r.code == 2, (r.code, r.err)
    assert msg in r.err, r.err
    assert "cannot open" not in r.err and r.out == "", (r.out, r.err)  # before any work


@pytest.mark.parametrize("argv, msg", [
    (("test", str(TANK / "tank.ss"), "--force"), "fsw test: --force goes with --trace FILE"),
    (("graph", SM, "--force"), "fsw graph: --force goes with -o FILE"),
    (("graph", SM, "-o", "-", "--force"), "fsw graph: --force goes with -o FILE"),
    (("skeleton", SM, "--force"), "fsw skeleton: --force goes with -o FILE"),
    (("compile", SM, "-o", "-", "--force"), "fsw compile: --force goes with -o FILE or --layout FILE"),
    (("monitor", str(TANK), "--port", NO_PORT, "--force"), "fsw monitor: --force goes with --log FILE"),
    (("param", str(ROCKET), "get", "MAIN_ALT", "--port", NO_PORT, "--force"),
     "fsw param: --force goes with `list -o FILE`"),
    (("param", str(ROCKET), "list", "--port", NO_PORT, "--force"), "fsw param: --force goes with `list -o FILE`"),
    (("dump", str(ROCKET), "--port", NO_PORT, "-o", "flights", "--yes"), "fsw dump: --yes goes with --erase"),
])
def test_refused(argv, msg, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    refused(run_fsw(*argv), msg)
    assert not (tmp_path / "flights").exists()


def test_log2csv_and_tape_import(tmp_path):
    log = tmp_path / "x.fswlog"
    log.write_bytes(b"")
    refused(run_fsw("log2csv", str(log), "--force"), "fsw log2csv: --force goes with -o FILE")
    refused(run_fsw("log2csv", str(log), "-o", "-", "--force"), "fsw log2csv: --force goes with -o FILE")
    alt = tmp_path / "log.csv"
    alt.write_text("ts,filtered_altitude_AGL,filtered_acceleration\n-0.1,0,0\n0,0.5,30\n0.1,3,30\n")
    refused(run_fsw("tape", "import", "cats", str(alt), "-o", "-", "--force"),
            "fsw tape import: --force goes with -o FILE")


def test_with_what_it_needs_it_is_taken(tmp_path):
    out = tmp_path / "g.dot"
    out.write_text("my notes\n")
    r = run_fsw("graph", SM, "-o", str(out), "--force")
    assert r.code == 0 and out.read_text().startswith("// state machine"), r.err
    layout = tmp_path / "l.txt"
    layout.write_text("mine\n")
    r = run_fsw("compile", SM, "-o", str(tmp_path / "t.fsm"), "--layout", str(layout), "--force")
    assert r.code == 0 and layout.read_text() != "mine\n", r.err
    trace = tmp_path / "t.csv"
    trace.write_text("mine\n")
    r = run_fsw("test", str(TANK / "tank.ss"), "--trace", str(trace), "--force")
    assert r.code == 0 and trace.read_text().startswith("step,"), r.err
