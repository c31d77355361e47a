"""A 40 KB line of `$a` printed 1.2 GB of diagnostics (every one of its
20,000 errors echoed the whole line) and took 2.4 GB of memory; a 50 MB
random file never finished. Diagnostics are now capped per line and per
file, with a closing "N more errors not shown" line, the echoed source line
is cut around the caret, and time and memory grow with the input only."""

from __future__ import annotations

import random
import re
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

from conftest import EXAMPLES

from fswkit.autocode.diagnostics import MAX_INPUT, PER_FILE, PER_LINE, SHOWN

FSW = str(Path(sys.executable).parent / "fsw")
MEMORY = 512 << 20  # address space allowed to one `fsw check` run


def hostile() -> str:
    """20 lines of 2 KB and one of 40 KB, all `$a`: more errors than a line
    and than a file show."""
    return "\n".join(["$a" * 1000] * 20 + ["$a" * 20000]) + "\n"


def fsw_check(*paths, cwd) -> tuple[int, str, float]:
    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (MEMORY, MEMORY))

    t = time.monotonic()
    r = subprocess.run([FSW, "check", *map(str, paths)], cwd=cwd, capture_output=True, text=True,
                       errors="replace", timeout=120, preexec_fn=limit)
    return r.returncode, r.stderr, time.monotonic() - t


def diagnostics(err: str) -> list[tuple[str, int, str]]:
    """(file, line, source line as shown) of every diagnostic in `err`."""
    return [(f, int(n), shown) for f, n, shown in re.findall(r" @ ([^:\n]+):(\d+):\d+:\n  \| ([^\n]*)\n", err)]


def test_long_lines_in_every_language_give_bounded_diagnostics(tmp_path):
    tank = EXAMPLES / "tank"
    for sub in ("sv", "sm", "ss", "io", "app"):
        shutil.copytree(tank, tmp_path / sub)
    (tmp_path / "sv" / "tank.sv").write_text(hostile())
    (tmp_path / "sm" / "tank.sm").write_text(hostile())
    (tmp_path / "ss" / "tank.ss").write_text(hostile())
    (tmp_path / "io" / "tank.aio").write_text(hostile())
    (tmp_path / "app" / "tank.app").write_text(hostile())
    files = ["sv/tank.sv", "sm/tank.sm", "ss/tank.ss", "io/tank.app", "app/tank.app"]
    code, err, seconds = fsw_check(*files, cwd=tmp_path)
    assert code == 1 and "Traceback" not in err, err[-2000:]
    found = diagnostics(err)
    dollars = hostile().count("$")
    for path in ("sv/tank.sv", "sm/tank.sm", "ss/tank.ss", "io/tank.aio", "app/tank.app"):
        mine = [d for d in found if d[0] == path]
        assert 0 < len(mine) <= PER_FILE, (path, len(mine))
        per_line = {}
        for _, n, _ in mine:
            per_line[n] = per_line.get(n, 0) + 1
        assert max(per_line.values()) <= PER_LINE, (path, per_line)
        hidden = re.search(rf"^{re.escape(path)}: (\d+) more errors not shown", err, re.M)
        assert hidden, path
        assert len(mine) + int(hidden.group(1)) >= dollars  # every error counted, shown or not
    for _, _, shown in found:
        assert len(shown) <= SHOWN + 6  # cut to SHOWN columns and two `...`
    total = int(re.search(r"fsw check: 5 files, (\d+) errors", err).group(1))
    assert total >= 5 * dollars
    assert len(err) < 5 * (PER_FILE + 1) * 400  # about 300 bytes a diagnostic
    assert seconds < 60


def test_the_caret_stays_under_the_column_in_a_cut_line(tmp_path):
    (tmp_path / "p.sv").write_text("[R]\nbool " + "x" * 5000 + " $ " + "y" * 5000 + "\n")
    code, err, _ = fsw_check("p.sv", cwd=tmp_path)
    assert code == 1
    m = re.search(r"p\.sv:2:(\d+):\n  \| ([^\n]*)\n  \| ( *)\^ unexpected character `\$`", err)
    assert m, err
    shown, caret = m.group(2), len(m.group(3))
    assert int(m.group(1)) == 5 + 5000 + 2
    assert shown.startswith("...") and shown.endswith("...") and shown[caret] == "$"


def test_a_random_file_of_the_largest_size_read_is_fast_and_bounded(tmp_path):
    data = random.Random(10).randbytes(MAX_INPUT)
    (tmp_path / "r.sv").write_text("[R]\nbool a\n")
    (tmp_path / "r.sm").write_bytes(data)
    code, err, seconds = fsw_check("r.sm", cwd=tmp_path)
    assert code == 1 and "Traceback" not in err, err[-2000:]
    assert 0 < len(diagnostics(err)) <= PER_FILE
    assert re.search(r"^r\.sm: \d+ more errors not shown", err, re.M)
    assert len(err) < (PER_FILE + 1) * 400
    assert seconds < 60


def test_a_file_reported_twice_is_counted_once(tmp_path):
    """A machine is checked on its own and again beside its script: the
    diagnostics not shown must not be counted twice."""
    from conftest import run_fsw

    for name in ("tank.sv", "tank.ss"):
        shutil.copy(EXAMPLES / "tank" / name, tmp_path / name)
    (tmp_path / "tank.sm").write_text(hostile())
    dollars = hostile().count("$")
    r = run_fsw("check", "tank.sm", "tank.ss", cwd=tmp_path)
    assert r.code == 1
    shown = len(diagnostics(r.err))
    hidden = int(re.search(r"^tank\.sm: (\d+) more errors not shown", r.err, re.M).group(1))
    assert shown + hidden == dollars
    assert r.err.endswith(f"fsw check: 2 files, {dollars} errors, 0 warnings\n")


def test_a_40_kb_name_is_cut_in_the_message_too(tmp_path):
    from conftest import run_fsw

    (tmp_path / "p.sv").write_text("[R]\nU64 time\nU32 state\n")
    (tmp_path / "p.sm").write_text("[state_vector]\nU64 time @alias G\nU32 state @alias S\n[A]\n.step\n    "
                                   + "a" * 40000 + " = 1\n")
    r = run_fsw("check", "p.sm", cwd=tmp_path)
    assert r.code == 1
    assert "^ unknown element `" + "a" * 30 + "..." + "a" * 30 + "`\n" in r.err
    assert len(r.err) < 1000
