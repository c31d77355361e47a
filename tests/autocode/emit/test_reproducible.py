"""Generation is a pure function of the configs: `fsw gen` (the C++ of an
application, for its board and natively), `fsw gen --sketch` and
`fsw graph`, each run in two separate processes with different
PYTHONHASHSEED values (so set and dict orders built from str hashes
differ), write the same files byte for byte. The in-process checks of the
same outputs are tests/target/test_gen_build.py and emit/test_graph.py."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import EXAMPLES, ROOT

HASH_SEEDS = ("1", "4242")
PROJECTS = ("tank", "rocket")


def fsw_in_a_process(hash_seed: str, *argv: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONHASHSEED=hash_seed)
    return subprocess.run([sys.executable, "-m", "fswkit.cli", *argv], capture_output=True, env=env, cwd=ROOT,
                          timeout=120)


def files_of(folder: Path) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def assert_same_files(a: Path, b: Path) -> None:
    fa, fb = files_of(a), files_of(b)
    assert sorted(fa) == sorted(fb)
    assert fa, f"nothing written in {a}"
    for name in fa:
        assert fa[name] == fb[name], f"{name} differs between PYTHONHASHSEED={HASH_SEEDS[0]} and {HASH_SEEDS[1]}"


@pytest.mark.parametrize("board", [None, "native"], ids=["own-board", "native"])
@pytest.mark.parametrize("project", PROJECTS)
def test_gen_is_byte_identical_across_hash_seeds(tmp_path, project, board):
    outs = []
    for seed in HASH_SEEDS:
        out = tmp_path / f"seed{seed}"
        extra = ("--board", board) if board else ()
        r = fsw_in_a_process(seed, "gen", str(EXAMPLES / project), *extra, "--out", str(out))
        assert r.returncode == 0, r.stderr.decode()
        outs.append(out)
    assert_same_files(*outs)


def test_sketch_is_byte_identical_across_hash_seeds(tmp_path):
    outs = []
    for seed in HASH_SEEDS:
        out = tmp_path / f"seed{seed}" / "tank"
        r = fsw_in_a_process(seed, "gen", str(EXAMPLES / "tank"), "--sketch", str(out))
        assert r.returncode == 0, r.stderr.decode()
        outs.append(out)
    assert_same_files(*outs)


@pytest.mark.parametrize("fmt", ["dot", "mermaid"])
def test_graph_is_byte_identical_across_hash_seeds(fmt):
    machine = EXAMPLES / "rocket" / "mission.sm"
    runs = [fsw_in_a_process(seed, "graph", str(machine), "--format", fmt) for seed in HASH_SEEDS]
    assert runs[0].returncode == runs[1].returncode == 0, runs[0].stderr.decode() + runs[1].stderr.decode()
    assert runs[0].stdout and runs[0].stdout == runs[1].stdout
