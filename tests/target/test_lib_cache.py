"""The Arduino core and the runtime compiled once for every build of a
board (fswkit.target.libcache, docs/cli.md "fsw build"): a second
project links the archives (native: the runtime's objects) the first one's
build compiled into the cache, and its firmware is byte for byte the one a
build compiling everything itself makes; another runtime, board or
makefile is another entry and relinks the firmware; a cache that cannot be
written leaves the build as it was."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import EXAMPLES

pytestmark = [pytest.mark.skipif(shutil.which("avr-g++") is None
                                 or not os.path.isdir("/usr/share/arduino/hardware/arduino/avr/cores/arduino"),
                                 reason="gcc-avr or the Arduino core not installed (make setup)"),
              pytest.mark.costly(12)]

TANK, ROCKET = EXAMPLES / "tank", EXAMPLES / "rocket"


def _entries(cache: Path) -> list[Path]:
    """The cache's AVR entries (each beside its lock file)."""
    return sorted(p for p in (cache / "avr").iterdir() if p.is_dir())


def _compiles(log: Path) -> list[str]:
    """The compile commands of a build's log that compile the runtime or the Arduino core."""
    return [line for line in log.read_text().splitlines()
            if " -c " in line and ("firmware/src/" in line or "cores/arduino/" in line)]


@pytest.fixture(scope="module")
def first(tmp_path_factory):
    """A cache of this file's own, and the Uno's entry the first build into
    it compiled (the tank's): (the cache, the tank's build folder)."""
    from conftest import run_fsw

    root = tmp_path_factory.mktemp("libcache")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("FSW_CACHE_DIR", str(root / "cache"))
        mp.delenv("FSW_NO_LIB_CACHE", raising=False)
        r = run_fsw("build", str(TANK), "--out", str(root / "tank"))
    assert r.code == 0, r.err
    return root / "cache", root / "tank"


@pytest.fixture
def cache(first, monkeypatch):
    """The module's cache, for the test's builds."""
    monkeypatch.setenv("FSW_CACHE_DIR", str(first[0]))
    monkeypatch.delenv("FSW_NO_LIB_CACHE", raising=False)
    return first[0]


@pytest.fixture
def empty_cache(tmp_path, monkeypatch):
    folder = tmp_path / "cache"
    monkeypatch.setenv("FSW_CACHE_DIR", str(folder))
    monkeypatch.delenv("FSW_NO_LIB_CACHE", raising=False)
    return folder


def test_a_second_project_links_the_archives_the_first_compiled(fsw, first, cache, tmp_path, monkeypatch):
    entries = _entries(cache)
    entry = cache / "avr" / (first[1] / "fsw-libs" / ".key").read_text()  # the Uno's, the tank compiled
    assert _compiles(first[1] / "build.log") == [] and entry in entries
    assert {p.name for p in entry.iterdir()} == {"core.a", "libfswkit.a", "build.log"}
    assert _compiles(entry / "build.log"), "the entry's log shows its compile"
    r = fsw("build", str(ROCKET), "--out", str(tmp_path / "rocket"))
    assert r.code == 0, r.err
    log = tmp_path / "rocket" / "build.log"
    assert _compiles(log) == [], "the runtime or the core compiled again"
    assert "fsw-libs/libfswkit.a fsw-libs/core.a" in log.read_text()
    assert (tmp_path / "rocket" / "fsw-libs" / "build.log").read_text() == (entry / "build.log").read_text()
    assert _entries(cache) == entries
    # the same firmware as a build that compiles everything in its folder
    monkeypatch.setenv("FSW_NO_LIB_CACHE", "1")
    assert fsw("build", str(ROCKET), "--out", str(tmp_path / "rocket-alone")).code == 0
    assert _compiles(tmp_path / "rocket-alone" / "build.log")
    assert (tmp_path / "rocket" / "rocket.hex").read_bytes() == (tmp_path / "rocket-alone" / "rocket.hex").read_bytes()


def test_another_board_is_another_entry(fsw, cache, tmp_path):
    out = tmp_path / "out"
    assert fsw("build", str(TANK), "--out", str(out)).code == 0
    uno = (out / "fsw-libs" / ".key").read_text()
    r = fsw("build", str(TANK), "--board", "mega2560", "--out", str(out))
    assert r.code == 0, r.err
    mega = (out / "fsw-libs" / ".key").read_text()
    assert mega != uno and {uno, mega} <= {p.name for p in _entries(cache)}
    # the Mega's archives, not the Uno's: e_flags' architecture 6 (ATmega2560), not 5
    for name in ("tank.elf", "fsw-libs/core.a"):
        data = (out / name).read_bytes()
        at = data.index(b"\x7fELF")  # an archive's first member
        assert int.from_bytes(data[at + 36:at + 40], "little") & 0x7F == 6, name


def test_another_entry_relinks_the_firmware(fsw, cache, tmp_path, monkeypatch):
    """The entry's key is part of the build's configuration (mk/build.mk's
    stamp): archives of another runtime relink the firmware even when
    their files are older than it."""
    from fswkit.target import libcache

    out = tmp_path / "out"
    assert fsw("build", str(TANK), "--out", str(out)).code == 0
    before = (out / "tank.elf").stat().st_mtime_ns
    key = (out / "fsw-libs" / ".key").read_text()
    other = "f" * 20 if key != "f" * 20 else "e" * 20
    shutil.copytree(cache / "avr" / key, cache / "avr" / other)
    old = 1_000_000_000
    for p in (cache / "avr" / other).iterdir():
        os.utime(p, (old, old))
    monkeypatch.setattr(libcache, "avr_key", lambda *a: other)
    assert fsw("build", str(TANK), "--out", str(out)).code == 0
    assert (out / "fsw-libs" / ".key").read_text() == other
    assert (out / "tank.elf").stat().st_mtime_ns != before


def test_the_key_follows_the_runtime_and_the_makefile(cache, tmp_path, monkeypatch):
    from fswkit.target import libcache

    args = ("atmega328p", 16000000, "standard", "ARDUINO_AVR_UNO", "/usr/share/arduino/hardware/arduino/avr")
    key = libcache.avr_key(*args)
    assert libcache.avr_key(*args) == key
    runtime = tmp_path / "runtime"
    shutil.copytree(libcache.RUNTIME, runtime)
    monkeypatch.setattr(libcache, "RUNTIME", str(runtime))
    moved = libcache.avr_key(*args)
    assert moved != key  # the same files elsewhere: the archives' debug information names them there
    with open(runtime / "fsw_config.h", "a") as f:
        f.write("\n// edited\n")
    edited = libcache.avr_key(*args)
    assert edited not in (key, moved)
    mk = tmp_path / "build.mk"
    mk.write_text(Path(libcache.BUILD_MK).read_text() + "\n# edited\n")
    monkeypatch.setattr(libcache, "BUILD_MK", str(mk))
    assert libcache.avr_key(*args) not in (key, edited)
    assert libcache.avr_key("atmega2560", 16000000, "mega", "ARDUINO_AVR_MEGA2560", args[-1]) != key


def test_a_cache_that_cannot_be_written_leaves_the_build_as_it_was(fsw, tmp_path, monkeypatch):
    blocked = tmp_path / "not-a-folder"
    blocked.write_text("")
    monkeypatch.setenv("FSW_CACHE_DIR", str(blocked))
    monkeypatch.delenv("FSW_NO_LIB_CACHE", raising=False)
    for board in ("uno", "native"):
        out = tmp_path / board
        r = fsw("build", str(TANK), "--board", board, "--out", str(out))
        assert r.code == 0, r.err
        assert not (out / "fsw-libs").exists()
        assert "LIBS=" not in (out / "build.log").read_text().splitlines()[0]
        assert "NATIVE_RT=" not in (out / "build.log").read_text().splitlines()[0]


@pytest.mark.skipif(shutil.which("g++") is None, reason="no host C++ compiler")
def test_a_native_build_links_the_runtimes_objects(fsw, tmp_path, monkeypatch):
    # the user's cache (the runtime's objects `fsw test --native` keeps, as likely there already)
    monkeypatch.delenv("FSW_NO_LIB_CACHE", raising=False)
    out = tmp_path / "native"
    r = fsw("build", str(TANK), "--board", "native", "--out", str(out))
    assert r.code == 0, r.err
    log = (out / "build.log").read_text()
    assert "NATIVE_RT=fsw-libs" in log and "fsw-libs/fsw_machine.o" in log
    assert not any(" -c " in line or "firmware/src/fsw_machine.cpp" in line for line in log.splitlines()[1:])
    monkeypatch.setenv("FSW_NO_LIB_CACHE", "1")
    alone = tmp_path / "alone"
    assert fsw("build", str(TANK), "--board", "native", "--out", str(alone)).code == 0
    assert "firmware/src/fsw_machine.cpp" in (alone / "build.log").read_text()
    # both run the tank the same: 500 cycles, the state vector in hex
    runs = [subprocess.run([str(folder / "tank"), "500"], capture_output=True, text=True, timeout=60)
            for folder in (out, alone)]
    assert runs[0].returncode == 0 and runs[0].stdout and runs[0].stdout == runs[1].stdout, runs


def test_concurrent_first_builds_share_one_entry(empty_cache, tmp_path):
    cache = empty_cache
    fsw_exe = os.path.join(os.path.dirname(sys.executable), "fsw")
    env = dict(os.environ, FSW_CACHE_DIR=str(cache))
    env.pop("FSW_NO_LIB_CACHE", None)
    procs = [subprocess.Popen([fsw_exe, "build", str(p), "--out", str(tmp_path / p.name)], env=env,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for p in (TANK, ROCKET)]
    for p in procs:
        out, err = p.communicate(timeout=600)
        assert p.returncode == 0, out + err
    assert [p.name for p in _entries(cache)] == [(tmp_path / "tank" / "fsw-libs" / ".key").read_text()]
    assert (tmp_path / "rocket" / "fsw-libs" / ".key").read_text() == (tmp_path / "tank" / "fsw-libs" / ".key").read_text()


def test_entries_no_build_used_for_30_days_are_removed(tmp_path):
    from fswkit.target import libcache

    old, recent = tmp_path / ("a" * 20), tmp_path / ("b" * 20)
    for entry in (old, recent):
        entry.mkdir()
        (entry / "core.a").write_bytes(b"!<arch>\n")
        Path(str(entry) + ".lock").write_text("")
    other = tmp_path / "notes.txt"  # not the cache's: left alone however old
    other.write_text("")
    then = libcache.time.time() - libcache.UNUSED_S - 60
    for p in (old, Path(str(old) + ".lock"), other):
        os.utime(p, (then, then))
    libcache._prune(str(tmp_path))
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([recent.name, recent.name + ".lock", "notes.txt"])
