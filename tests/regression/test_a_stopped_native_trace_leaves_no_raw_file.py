"""`fsw test --native --trace T.csv` has the runner write its rows in binary
to a file beside the trace, converted to the CSV when the run ends. Stopped
while the runner ran (Ctrl-C, SIGTERM), the command left that file behind,
`.T.csv.XXXX.part.raw`, as large as the run had made it; and a trace on a
device (`--trace /dev/stdout`) put it in /dev. The binary rows are now a
temporary file of their own (beside a file trace, in the system's
temporary folder for a device) removed however the run ends."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import EXAMPLES

FSW = str(Path(sys.executable).parent / "fsw")

LONG = """[options]
delta_t 10
init_state TankVentControl
max_steps 5000000

[all_states]
G == 0 {
    tankPressure = 600
    valveOpen = false
}
G == 40000000: @stop
"""


@pytest.mark.skipif(shutil.which("g++") is None, reason="no host C++ compiler")
def test_stopped_while_the_runner_runs(tmp_path):
    for name in ("tank.sm", "tank.sv"):
        shutil.copy(EXAMPLES / "tank" / name, tmp_path / name)
    (tmp_path / "tank.ss").write_text(LONG)
    before = set(os.listdir(tmp_path))
    p = subprocess.Popen([FSW, "test", "tank.ss", "--native", "--trace", "t.csv"], cwd=tmp_path,
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120  # a first compile of the runtime takes a while
        while time.monotonic() < deadline and p.poll() is None:
            extra = set(os.listdir(tmp_path)) - before
            if any(n.endswith(".raw") and (tmp_path / n).stat().st_size > 0 for n in extra):
                break
            time.sleep(0.005)
        else:
            pytest.fail(f"the runner's rows never appeared beside the trace: {sorted(os.listdir(tmp_path))}")
        p.send_signal(signal.SIGTERM)
        err = p.communicate(timeout=60)[1]
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode == 143, err
    assert set(os.listdir(tmp_path)) == before, sorted(os.listdir(tmp_path))


@pytest.mark.skipif(shutil.which("g++") is None, reason="no host C++ compiler")
def test_a_trace_on_a_device_keeps_its_rows_out_of_dev(tmp_path, monkeypatch):
    from fswkit.run import native

    seen = []
    real_run = subprocess.run

    def spy(args, *a, **kw):
        seen.extend(args[1:])
        return real_run(args, *a, **kw)

    monkeypatch.setattr(native.subprocess, "run", spy)
    from conftest import run_fsw

    shutil.copy(EXAMPLES / "tank" / "tank.sm", tmp_path / "tank.sm")
    shutil.copy(EXAMPLES / "tank" / "tank.sv", tmp_path / "tank.sv")
    shutil.copy(EXAMPLES / "tank" / "tank.ss", tmp_path / "tank.ss")
    r = run_fsw("test", str(tmp_path / "tank.ss"), "--native", "--trace", "/dev/null")
    assert r.code == 0, r.err
    raws = [a for a in seen if a.endswith(".raw")]
    assert raws and not any(a.startswith("/dev/") for a in raws), seen
    assert not any(os.path.exists(a) for a in raws)
