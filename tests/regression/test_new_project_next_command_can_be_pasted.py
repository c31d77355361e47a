"""`fsw new "my projects/rocket"` ended with `next: cd my projects/rocket
&& fsw check . ...`: pasted into a shell, `cd` went to `my` with a stray
argument. The folder is quoted as a shell needs it."""

from __future__ import annotations

import shlex
import subprocess

from conftest import run_fsw


def test_the_next_line_runs_as_printed(tmp_path):
    (tmp_path / "my projects").mkdir()
    r = run_fsw("new", "my projects/rk", cwd=tmp_path)
    assert r.code == 0, r.err
    line = r.out.splitlines()[-1]
    assert line == "next: cd 'my projects/rk' && fsw check . && fsw test rk.ss && fsw build ."
    cd = line.removeprefix("next: ").split(" && ")[0]
    assert shlex.split(cd) == ["cd", "my projects/rk"]
    assert subprocess.run(["sh", "-c", f"{cd} && pwd"], cwd=tmp_path, capture_output=True, text=True).stdout \
        .strip().endswith("my projects/rk")
