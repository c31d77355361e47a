"""A parameter file (`fsw param load|diff`, `fsw sim --fw-params`) is read
as every file a user names is: a FIFO or a device is refused without
reading (`/dev/zero` was read until memory ran out, a FIFO waited for a
writer forever), and a whole-number parameter given a number beyond the
float range (`HOLD_MS = 1e400`, `inf`) is a located error, not an
OverflowError. Everything here is checked before the port is opened."""

from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import run_fsw

from fswkit.autocode.params import check_value

RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"
FSW = str(Path(sys.executable).parent / "fsw")


def _memory_limit():
    resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))


def fsw_child(*argv) -> subprocess.CompletedProcess:
    # a child process with a timeout and a memory limit: a reader that blocks, or
    # reads without end, fails the test instead of hanging it or exhausting memory
    return subprocess.run([FSW, *argv], capture_output=True, text=True, timeout=30, preexec_fn=_memory_limit)


def load(path):
    return run_fsw("param", str(RIG), "load", str(path), "--port", "/dev/no-such-port")


@pytest.mark.parametrize("value", ["1e400", "-1e400", "inf", "-inf"])
def test_a_whole_number_beyond_the_float_range_is_located(tmp_path, value):
    f = tmp_path / "p.toml"
    f.write_text(f"TRIM = -3\nHOLD_MS = {value}\n")
    r = load(f)
    assert r.code == 2 and f"{f}:2:11: `HOLD_MS` is U16: give a whole number" in r.err, r.err
    assert "internal error" not in r.err


def test_check_value_takes_an_infinity_for_an_integer():
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.params import app_parameters
    from fswkit.target.build import load as load_app

    params = {p.name: p for p in app_parameters(load_app(str(RIG), Diagnostics()))}
    for v in (float("inf"), float("-inf"), 1e300):
        value, why = check_value(params["HOLD_MS"], v)
        assert value is None and "HOLD_MS" in why


def test_a_device_is_not_read():
    r = fsw_child("param", str(RIG), "load", "/dev/zero", "--port", "/dev/no-such-port")
    assert r.returncode == 2 and "/dev/zero" in r.stderr and "not a regular file (a device)" in r.stderr, r.stderr


def test_a_fifo_is_not_waited_on(tmp_path):
    fifo = tmp_path / "p.toml"
    os.mkfifo(fifo)
    r = fsw_child("param", str(RIG), "diff", str(fifo), "--port", "/dev/no-such-port")
    assert r.returncode == 2 and "not a regular file (a FIFO)" in r.stderr, r.stderr


def test_a_huge_file_is_refused(tmp_path):
    f = tmp_path / "p.toml"
    with open(f, "wb") as out:
        out.truncate(2 << 20)  # 2 MiB of NULs
    r = load(f)
    assert r.code == 2 and "file too large" in r.err, r.err


def test_sim_params_that_are_a_device_or_a_fifo(tmp_path):
    # `fsw sim --params` looks into the file to tell the firmware's parameters from a plant's
    fifo = tmp_path / "plant.toml"
    os.mkfifo(fifo)
    tank = str(RIG.parent.parent.parent / "examples" / "tank")
    for path, kind in (("/dev/zero", "a device"), (str(fifo), "a FIFO")):
        r = fsw_child("sim", tank, "--plant", "tank", "--params", path)
        assert r.returncode == 2 and f"not a regular file ({kind})" in r.stderr, r.stderr


def test_the_command_line_takes_a_whole_number_as_a_file_does():
    """`fsw param set HOLD_MS=1e3` was refused (`is not a whole number`)
    where a file's `HOLD_MS = 1e3` was taken: both take a number that is
    whole, and both refuse one that is not, or is beyond the float range."""
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.params import app_parameters
    from fswkit.target.build import load as load_app

    p = {q.name: q for q in app_parameters(load_app(str(RIG), Diagnostics()))}["HOLD_MS"]
    for text, file_value in (("1e3", 1e3), ("250.0", 250.0), (" 0x20 ", 32)):
        assert check_value(p, text) == check_value(p, file_value) and check_value(p, text)[1] is None, text
    for text in ("1.5", "1e400", "inf", "nan", "ten", ""):
        value, why = check_value(p, text)
        assert value is None and "HOLD_MS" in why, (text, why)
