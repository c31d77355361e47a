"""`make test`'s compiles go through ccache, in the kit's cache folder,
unless FSW_CCACHE=0 (Makefile; README.md says so)."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _database(**env) -> str:
    """make's database for `make test` (-p), nothing run (-n, -q)."""
    e = dict(os.environ, **env)
    e.pop("MAKEFLAGS", None)
    r = subprocess.run(["make", "-pnq", "--no-print-directory", "test"], cwd=ROOT, env=e,
                       capture_output=True, text=True, timeout=60)
    return r.stdout


def test_make_test_puts_ccache_first_on_path_with_its_cache_in_the_kits(tmp_path):
    db = _database(FSW_CACHE_DIR=str(tmp_path / "cache"))
    for target in ("test", "test-python", "test-firmware", "setup-and-build-ahead"):
        assert f"{target}: CCACHE_DIR := {tmp_path / 'cache'}/ccache" in db, target
        assert f"{target}: PATH := /usr/lib/ccache:" in db, target
        assert f"{target}: CCACHE_NOHASHDIR := 1" in db, target


def test_fsw_ccache_0_runs_the_compilers_themselves(tmp_path):
    db = _database(FSW_CACHE_DIR=str(tmp_path / "cache"), FSW_CCACHE="0")
    assert "CCACHE_DIR :=" not in db
    assert ": PATH := /usr/lib/ccache:" not in db


def test_the_setup_installs_ccache():
    assert "ccache" in (ROOT / "tools" / "bootstrap.sh").read_text().split("APT_PACKAGES=(", 1)[1].split(")", 1)[0]
