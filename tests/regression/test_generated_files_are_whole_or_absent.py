"""`fsw gen --out DIR`, `fsw gen --sketch DIR` and `fsw build` wrote each
generated file in place: a write that failed partway (a full disk, a file
size limit, Ctrl-C) left a truncated `app.gen.cpp` under its own name, a
sketch folder that arduino-cli would then compile as if whole. Each file
now goes to a temporary file beside it that takes its name once whole: what
a failed export leaves is every file either whole or as it was."""

from __future__ import annotations

import os
import resource
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import EXAMPLES

FSW = str(Path(sys.executable).parent / "fsw")
LIMIT = 4000  # bytes: smaller than the largest generated file of the tank


def limited():
    resource.setrlimit(resource.RLIMIT_FSIZE, (LIMIT, LIMIT))


# and no compiled bytecode written under the limit: importlib ignores a short
# write, and a cut .pyc would fail every later import of its module
LIMITED_ENV = os.environ | {"PYTHONDONTWRITEBYTECODE": "1"}


@pytest.fixture
def tank(tmp_path):
    for name in ("tank.sv", "tank.sm", "tank.app", "tank.aio", "tank.dio"):
        shutil.copy(EXAMPLES / "tank" / name, tmp_path / name)
    return tmp_path


@pytest.mark.parametrize("option,folder", [("--out", "g"), ("--sketch", "sk")])
def test_a_write_that_fails_partway_leaves_no_truncated_file(tank, option, folder):
    ok = subprocess.run([FSW, "gen", ".", option, "whole"], cwd=tank, capture_output=True, text=True, timeout=120)
    assert ok.returncode == 0, ok.stderr
    whole = {p.name: p.read_bytes() for p in (tank / "whole").iterdir()}
    assert max(len(b) for b in whole.values()) > LIMIT  # the limit falls inside a file
    r = subprocess.run([FSW, "gen", ".", option, folder], cwd=tank, capture_output=True, text=True, timeout=120,
                       preexec_fn=limited, env=LIMITED_ENV)
    assert r.returncode == 1, r.stderr
    assert "File too large" in r.stderr and "Traceback" not in r.stderr
    left = {p.name: p.read_bytes() for p in (tank / folder).iterdir()} if (tank / folder).exists() else {}
    for name, data in left.items():
        if option == "--sketch" and name.startswith(folder + "."):
            name = name.replace(folder, "whole", 1)
        assert name in whole, f"{name} left behind"
        expected = whole[name].replace(b"whole", folder.encode()) if option == "--sketch" else whole[name]
        assert data == expected, f"{name} left truncated ({len(data)} of {len(expected)} bytes)"
