"""A short run of the uplink parser's libFuzzer target (ASan + UBSan) with
the invariants of docs/security.md; `make fuzz` runs 10,000,000 inputs."""

from __future__ import annotations

import shutil
import subprocess

import pytest

from conftest import ROOT

pytestmark = pytest.mark.costly(7)


@pytest.mark.skipif(shutil.which("clang++") is None, reason="clang is not installed (make setup installs it)")
def test_uplink_fuzz_short_run():
    # 20,000 inputs (about 5 s), or 120 s on a busy machine, whichever comes first
    r = subprocess.run(["make", "--no-print-directory", "-C", str(ROOT), "fuzz-uplink", "FUZZ_RUNS=20000",
                        "FUZZ_SECONDS=120"], capture_output=True, text=True, timeout=900)
    assert r.returncode == 0 and "uplink fuzz: 1 passed, 0 failed" in r.stdout, r.stdout[-3000:] + r.stderr[-3000:]
    runs = int(r.stdout.split("stat::number_of_executed_units:")[1].split()[0])
    assert runs >= 20000, r.stdout
