"""A short run of the bytecode VM's libFuzzer target (ASan + UBSan,
tests/fuzz/vm/fuzz_vm.cpp): no image the verifier accepts makes the VM read
or write outside the state vector, and the loader's EEPROM verifier agrees
with the RAM one (docs/reload.md); `make fuzz` runs 10,000,000 inputs.
The inputs of tests/fuzz/vm/regressions (past findings) run first, once each."""

from __future__ import annotations

import shutil
import subprocess

import pytest

from conftest import ROOT


@pytest.mark.skipif(shutil.which("clang++") is None, reason="clang is not installed (make setup installs it)")
def test_vm_fuzz_short_run():
    # 20,000 inputs from the compiled seeds, or 90 s on a busy machine, whichever comes first
    r = subprocess.run(["make", "--no-print-directory", "-C", str(ROOT), "fuzz-vm", "FUZZ_RUNS=20000",
                        "FUZZ_SECONDS=90"], capture_output=True, text=True, timeout=900)
    assert r.returncode == 0 and "vm fuzz: 1 passed, 0 failed" in r.stdout, r.stdout[-3000:] + r.stderr[-3000:]
    runs = int(r.stdout.split("stat::number_of_executed_units:")[1].split()[0])
    assert runs >= 5000, r.stdout
    seeds = sorted(p.name for p in (ROOT / "build" / "fuzz" / "vm" / "corpus").glob("seed-*.fsm"))
    assert seeds == ["seed-counter.fsm", "seed-typed.fsm", "seed-windows.fsm"]  # the seeds that pass the verifier
