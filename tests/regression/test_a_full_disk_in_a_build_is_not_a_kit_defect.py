"""A build into a folder on a full (or read-only) disk failed in the
compiler's assembler ("can't close gen/app.gen.o: No space left on
device"), and `fsw build` (`flash`, `sim`) said "internal error: the
generated code did not build ... a defect of fswkit, please report it",
with exit 3. Now it says the build folder cannot be written, and why, with
exit 1; a real compile error is still reported as the kit's defect. `fsw
test --native`, whose runner is compiled into the cache (FSW_CACHE_DIR),
said the same "internal error" (exit 3) for a full cache disk, or, when the
compiler's output could not be written there either, "fsw test: : No space
left on device" with no file named; now it names the cache folder, exit 1.
libfswsm (fswkit.sm, compiled into the same cache on first use) said "did
not compile (a defect of fswkit, or an unusual compiler)"; now it says the
cache cannot be written."""

from __future__ import annotations

import subprocess

import pytest
from conftest import EXAMPLES, run_fsw

from fswkit.run import native

from fswkit.autocode.diagnostics import Diagnostics
from fswkit.target.build import explain_failure, load

TANK = EXAMPLES / "tank"


def _app():
    app = load(str(TANK), Diagnostics())
    assert app is not None
    return app


def test_a_full_disk_is_said_as_such(tmp_path):
    out = str(tmp_path / "b")
    proc = subprocess.CompletedProcess([], 2, "", "/tmp/ccX.s: Assembler messages:\n"
                                       "/tmp/ccX.s: Fatal error: can't close gen/app.gen.o: No space left on device\n"
                                       "make: *** [build.mk:80: gen/app.gen.o] Error 1\n")
    users_side, message = explain_failure(_app(), out, proc)
    assert users_side
    assert message == (f"cannot write the build folder {out}: No space left on device "
                       f"(the compiler's output: {out}/build.log)")


def test_a_read_only_folder_is_said_as_such(tmp_path):
    out = str(tmp_path / "b")
    proc = subprocess.CompletedProcess([], 2, "", "cc1plus: fatal error: opening output file gen/app.gen.o: "
                                       "Read-only file system\n")
    users_side, message = explain_failure(_app(), out, proc)
    assert users_side and "Read-only file system" in message and "internal error" not in message


def test_a_compile_error_is_still_the_kits_defect(tmp_path):
    out = str(tmp_path / "b")
    proc = subprocess.CompletedProcess([], 2, "", "gen/app.gen.cpp:12:3: error: 'x' was not declared\n")
    users_side, message = explain_failure(_app(), out, proc)
    assert not users_side and message.startswith("internal error: the generated code did not build")


def test_the_native_runners_full_cache_is_said_as_such(tmp_path, monkeypatch):
    def full(cmd, **kw):
        return subprocess.CompletedProcess(cmd, 1, "", "/tmp/ccY.s: Fatal error: can't write 512 bytes to "
                                           "section .text of fsw_vm.o: 'No space left on device'\n")

    monkeypatch.setattr(native.subprocess, "run", full)
    out = tmp_path / "cache" / "0123"
    out.parent.mkdir()
    with pytest.raises(OSError) as e:
        native._compile(["g++"], str(out))
    assert e.value.filename == str(out.parent)
    assert "No space left on device" in e.value.strerror and "FSW_CACHE_DIR" in e.value.strerror
    with pytest.raises(OSError) as e:  # not even the compiler's output can be written there
        native._compile(["g++"], str(tmp_path / "gone" / "0123"))
    assert e.value.filename == str(tmp_path / "gone")


def test_fsw_test_native_names_the_cache_it_cannot_write(tmp_path, monkeypatch):
    cache = tmp_path / "cache"
    cache.write_text("a file where the cache folder goes\n")
    monkeypatch.setenv("FSW_CACHE_DIR", str(cache))
    r = run_fsw("test", str(TANK / "tank.ss"), "--native")
    assert r.code == 1, r.out + r.err
    assert "Traceback" not in r.err and "internal error" not in r.err and "fsw test: : " not in r.err, r.err
    assert str(cache) in r.err, r.err


def test_libfswsm_on_a_full_cache_says_so(tmp_path, monkeypatch):
    from fswkit import sm

    def full(cmd, **kw):
        return subprocess.CompletedProcess(cmd, 1, "", "/usr/bin/ld: final link failed: No space left on device\n")

    monkeypatch.setenv("FSW_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(sm.subprocess, "run", full)
    with pytest.raises(sm.BuildError) as e:
        sm.library_path("f64")
    assert str(e.value).startswith(f"cannot write libfswsm64 into the kit's cache {tmp_path / 'cache' / 'native'}: "
                                   "No space left on device"), e.value
