"""Differential: every example script gives the same report and the same
per-step trace from the interpreter and from the generated C++ compiled for
this host, in binary64 and in binary32."""

from __future__ import annotations

import os
import shutil

import pytest

from conftest import EXAMPLES, ROOT

SCRIPTS = sorted(p for p in EXAMPLES.rglob("*.ss"))
needs_cxx = pytest.mark.skipif(shutil.which("g++") is None, reason="no host C++ compiler")


CACHE = ROOT / "build" / "differential" / "fsw-cache"


@pytest.fixture(scope="module", autouse=True)
def _runtime_objects():
    """The runtime's objects for both evaluation types taken from the run's
    own cache, where the other tests compile them too (same compiler,
    flags and sources: the same key), rather than compiled again into
    this file's (on a fresh clone, about 5 s of CPU)."""
    from fswkit.autocode.numeric import REALS
    from fswkit.run import native

    for real in REALS.values():
        entry = os.path.dirname(native.runtime_objects(real)[0])
        kept = CACHE / "native" / os.path.basename(entry)
        if not kept.exists():
            tmp = CACHE / "native" / f"{kept.name}.tmp{os.getpid()}"  # moved into place whole
            shutil.copytree(entry, tmp)
            try:
                os.replace(tmp, kept)
            except OSError:  # another run put it there first
                shutil.rmtree(tmp, ignore_errors=True)


@pytest.fixture(autouse=True)
def _cache(monkeypatch):
    """`fsw test --native`'s builds kept in build/differential/fsw-cache,
    not the user's ~/.cache: a build is keyed by the hash of all it reads
    (the compiler, the runtime, the generated code, the flags), so a warm
    run compiles only what changed (fswkit.run.native)."""
    monkeypatch.setenv("FSW_CACHE_DIR", str(CACHE))


@needs_cxx
@pytest.mark.parametrize("real", ["f64", "f32"])
@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: str(p.relative_to(EXAMPLES)))
def test_native_matches_interpreter(fsw, tmp_path, script, real):
    a, b = tmp_path / "interp.csv", tmp_path / "native.csv"
    interp = fsw("test", script.name, "--real", real, "--trace", str(a), cwd=script.parent)
    native = fsw("test", script.name, "--real", real, "--native", "--trace", str(b), cwd=script.parent)
    assert interp.code in (0, 1), interp.err
    assert native.code == interp.code, native.err
    assert native.out == interp.out
    rows = a.read_text()
    assert rows.count("\n") > 1
    assert b.read_text() == rows
