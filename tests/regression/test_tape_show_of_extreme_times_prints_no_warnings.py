"""`fsw tape show` of a tape the reader takes, with times at binary64's
ends (-1e308 and 1e308, or 0 and 1e-320), printed numpy's RuntimeWarnings
(`overflow encountered in subtract`, with the kit's source file and line)
among its report, as an internal fault would look. The rates are said
without them. Such times are now beyond a tape's range (-3,600 to 3,600 s,
rows 1 µs to 60 s apart) and `fsw tape show` refuses them at their line,
without a warning; a tape made in memory still gives its rates without
one."""

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
    assert r.returncode == 1, r.stdout
    assert r.stderr.startswith(f"fsw tape show: {tape}:") and "Warning" not in r.stderr, r.stderr
    assert r.stdout == ""


@pytest.mark.parametrize("times", [(-1e308, 1e308), (0.0, 1e-320)])
def test_extreme_times_give_rates_without_warnings(times):
    import warnings

    import numpy as np

    from fswkit.tape import Tape

    tape = Tape("mem", np.array(times), np.full(2, 90000.0), np.ones(2))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert tape.rate_hz("pressure_pa") >= 0
