"""Two `fsw build` of one project into one folder at the same time failed
one of them with raw linker errors (each deleted and rewrote the other's
archives). A build now holds its folder: a second build of it waits,
saying for whom, then finds everything built; both succeed with the same
firmware. `fsw sim` and `fsw flash` build through the same lock."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import time

import pytest

from conftest import EXAMPLES

TANK = EXAMPLES / "tank"


def _start(*args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "fswkit.cli", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def _hold(out) -> subprocess.Popen:
    """A process that holds the build folder `out` until its input closes."""
    holder = subprocess.Popen([sys.executable, "-c", (
        "import sys, fswkit.target.build as b\n"
        f"with b.build_lock({str(out)!r}, 'test'):\n"
        "    print('held', flush=True)\n"
        "    sys.stdin.read()\n")], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    assert holder.stdout.readline().strip() == "held"
    return holder


@pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")
def test_two_builds_into_one_folder_both_succeed_with_the_same_firmware(tmp_path):
    out = tmp_path / "build"
    holder = _hold(out)  # both builds start while the folder is held, so they run into each other
    try:
        first = _start("build", str(TANK), "--out", str(out))
        second = _start("build", str(TANK), "--out", str(out))
        time.sleep(0.5)
    finally:
        holder.stdin.close()
        holder.wait()
    results = [(p.wait(timeout=300), *p.communicate()) for p in (first, second)]
    for code, stdout, err in results:
        assert code == 0, err
        assert str(out / "tank.hex") in stdout
    waited = [err for _, _, err in results if "waiting for another build of" in err]
    assert waited, "neither build waited for the folder"
    for err in waited:
        assert re.search(r"waiting for another build of \S+ \(pid (\d+)\)", err)
    fresh = tmp_path / "fresh"
    assert subprocess.run([sys.executable, "-m", "fswkit.cli", "build", str(TANK), "--out", str(fresh)],
                          capture_output=True).returncode == 0
    assert (out / "tank.hex").read_bytes() == (fresh / "tank.hex").read_bytes()


def test_a_held_folder_is_waited_for_then_given_up_with_a_message(tmp_path, monkeypatch, capsys):
    """A build that cannot get its folder within the time limit says who
    holds it and exits non-zero; it never builds into it meanwhile."""
    import fswkit.target.build as build

    out = tmp_path / "build"
    holder = _hold(out)
    try:
        monkeypatch.setattr(build, "LOCK_TIMEOUT_S", 0.5)
        with pytest.raises(build.BuildError) as e:
            with build.build_lock(str(out), "build"):
                pytest.fail("built into a folder another build holds")
        assert f"pid {holder.pid}" in str(e.value) and str(out) in str(e.value)
        assert f"fsw build: waiting for another build of {out} (pid {holder.pid})" in capsys.readouterr().err
    finally:
        holder.stdin.close()
        holder.wait()
    with build.build_lock(str(out), "build"):  # free again once its holder is gone
        pass
