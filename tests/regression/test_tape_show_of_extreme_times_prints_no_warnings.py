"""`fsw tape show` of a tape the reader takes, with times at binary64's
ends (-1e308 and 1e308, or 0 and 1e-320), printed numpy's RuntimeWarnings
(`overflow encountered in subtract`, with the kit's source file and line)
among its report, as an internal fault would look. The rates are said
without them."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

FSW = str(Path(sys.executable).parent / "fsw")


@pytest.mark.parametrize("times", [("-1e308", "1e308"), ("0", "1e-320")])
def test_extreme_times_are_shown_without_warnings(tmp_path, times):
    tape = tmp_path / "t.csv"
    tape.write_text("# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n"
                    f"{times[0]},90000,1\n{times[1]},90000,1\n")
    r = subprocess.run([FSW, "tape", "show", str(tape)], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""
    assert "pressure_pa: 2 values" in r.stdout
