"""An interrupted `fsw test --native` (or the first `fsw sim`, which
compiles the simulated board) left its `.tmpPID` compile folder in the
cache for good, as did a compile that failed (which also printed up to
4 KB of raw compiler output). A compile's temporary folder is now removed
however the compile ends (an error, Ctrl-C, SIGTERM, SIGHUP), those of
processes that died mid-compile are swept away by the next compile, and a
failed compile is an internal error naming its log."""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import time

import pytest

from conftest import EXAMPLES
from support.caches import seeded

SCRIPT = str(EXAMPLES / "tank" / "tank.ss")
needs_cxx = pytest.mark.skipif(shutil.which("g++") is None, reason="no host C++ compiler")


def _leftovers(cache, kind: str = "native") -> list[str]:
    folder = cache / kind
    return sorted(n for n in os.listdir(folder) if ".tmp" in n) if folder.is_dir() else []


def _slow_compiler(tmp_path) -> str:
    """A compiler that takes its time: long enough to be interrupted."""
    cxx = tmp_path / "slow-cc"
    cxx.write_text('#!/bin/sh\n[ "$1" = --version ] && { echo "slow-cc 1.0"; exit 0; }\nsleep 60\n')
    cxx.chmod(0o755)
    return str(cxx)


# The two compiles the kit caches: `fsw test --native`'s runner, and the
# simulated board's harness (`fsw sim`).
COMPILES = {
    "native": (["-m", "fswkit.cli", "test", "--native", SCRIPT], "CXX"),
    "sim": (["-c", "from fswkit.sim.board import harness; harness()"], "CC"),
}


@pytest.mark.parametrize("kind", sorted(COMPILES))
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_an_interrupted_compile_leaves_no_temporary_folder(tmp_path, sig, kind):
    if kind == "sim" and not os.path.exists("/usr/include/simavr/sim_avr.h"):
        pytest.skip("simavr's development files are not installed")
    cache = tmp_path / "cache"
    argv, compiler = COMPILES[kind]
    env = dict(os.environ, FSW_CACHE_DIR=str(cache), **{compiler: _slow_compiler(tmp_path)})
    p = subprocess.Popen([sys.executable, *argv], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 30
        while not _leftovers(cache, kind):
            assert p.poll() is None and time.monotonic() < deadline, "the compile never started"
            time.sleep(0.02)
        time.sleep(0.2)  # the compiler runs
        p.send_signal(sig)
        p.wait(timeout=20)
    finally:
        p.kill()
        p.communicate()
    assert p.returncode != 0
    assert _leftovers(cache, kind) == []


@needs_cxx
def test_a_failed_compile_leaves_no_temporary_folder(fsw, tmp_path, monkeypatch):
    from fswkit.run import native

    monkeypatch.setenv("FSW_CACHE_DIR", seeded(tmp_path))
    real = native.script_files

    def script_files(*a):  # generated code the compiler refuses
        files = real(*a)
        name = next(n for n in sorted(files) if n.endswith(".cpp"))
        files[name] += "int broken = ;\n"
        return files

    monkeypatch.setattr(native, "script_files", script_files)
    r = fsw("test", "--native", SCRIPT)
    assert r.code == 3 and "internal error: the generated code did not compile" in r.err
    assert "expected primary-expression" in r.err and len(r.err.splitlines()) <= 8, r.err
    log = re.search(r"please report it with (\S+\.log)", r.err).group(1)
    assert "int broken = ;" in open(log).read()
    assert _leftovers(tmp_path) == []


@needs_cxx
def test_the_folders_of_dead_compiles_are_swept_and_live_ones_kept(fsw, tmp_path, monkeypatch):
    monkeypatch.setenv("FSW_CACHE_DIR", seeded(tmp_path))
    gone = subprocess.Popen(["true"])
    gone.wait()
    live = subprocess.Popen(["sleep", "60"])
    try:
        native = tmp_path / "native"
        dead_tmp = native / f"{'0' * 20}.tmp{gone.pid}"
        live_tmp = native / f"{'1' * 20}.tmp{live.pid}"
        for d in (dead_tmp, live_tmp):
            d.mkdir(parents=True)
            (d / "runner.gen.cpp").write_text("// half written\n")
        r = fsw("test", "--native", SCRIPT)
        assert r.code == 0, r.err
        assert _leftovers(tmp_path) == [live_tmp.name]
    finally:
        live.kill()
        live.wait()
