"""The Arduino core and the runtime compiled once for every build of a
board (fswkit.target.libcache, docs/cli.md "fsw build"): a second
project links the archives (native: the runtime's objects) the first one's
build compiled into the cache, and its firmware is byte for byte the one a
build compiling everything itself makes; another runtime, board or
makefile is another entry and relinks the firmware; a cache that cannot be
written leaves the build as it was; FSW_NO_LIB_CACHE=1 leaves it alone."""

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
              pytest.mark.costly(10)]

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
    """A cache of this file's own, filled by two first builds at once (the
    tank's and the rocket's, two `fsw build` processes) into it while empty:
    (the cache, the tank's build folder, the rocket's, the cache's entries
    right after them: later tests add others)."""
    root = tmp_path_factory.mktemp("libcache")
    fsw_exe = os.path.join(os.path.dirname(sys.executable), "fsw")
    env = dict(os.environ, FSW_CACHE_DIR=str(root / "cache"))
    env.pop("FSW_NO_LIB_CACHE", None)
    procs = [subprocess.Popen([fsw_exe, "build", str(p), "--out", str(root / p.name)], env=env,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for p in (TANK, ROCKET)]
    for p in procs:
        out, err = p.communicate(timeout=600)
        assert p.returncode == 0, out + err
    return root / "cache", root / "tank", root / "rocket", _entries(root / "cache")


@pytest.fixture
def cache(first, monkeypatch):
    """The module's cache, for the test's builds."""
    monkeypatch.setenv("FSW_CACHE_DIR", str(first[0]))
    monkeypatch.delenv("FSW_NO_LIB_CACHE", raising=False)
    return first[0]


def test_concurrent_first_builds_share_one_entry(first):
    """Both first builds link the one entry for the Uno, which one of them
    compiled (its log shows the compile) while the other waited for it:
    neither build's own log compiles the runtime or the core."""
    cache, tank, rocket, entries = first
    key = (tank / "fsw-libs" / ".key").read_text()
    assert [p.name for p in entries] == [key]
    assert (rocket / "fsw-libs" / ".key").read_text() == key
    entry = cache / "avr" / key
    assert {p.name for p in entry.iterdir()} == {"core.a", "libfswkit.a", "build.log"}
    assert _compiles(entry / "build.log"), "the entry's log shows its compile"
    for folder in (tank, rocket):
        log = (folder / "build.log").read_text()
        assert _compiles(folder / "build.log") == [], f"{folder.name}: the runtime or the core compiled again"
        assert "fsw-libs/libfswkit.a fsw-libs/core.a" in log
        assert (folder / "fsw-libs" / "build.log").read_text() == (entry / "build.log").read_text()


def test_a_later_build_links_the_archives(fsw, first, cache, tmp_path):
    entries = _entries(cache)
    r = fsw("build", str(ROCKET), "--out", str(tmp_path / "rocket"))
    assert r.code == 0, r.err
    assert _compiles(tmp_path / "rocket" / "build.log") == [], "the runtime or the core compiled again"
    assert _entries(cache) == entries
    assert (tmp_path / "rocket" / "rocket.hex").read_bytes() == (first[2] / "rocket.hex").read_bytes()


def test_another_board_is_another_entry(fsw, tmp_path, monkeypatch):
    """In the user's cache (as `make test`'s other Mega builds fill it): the
    Mega's entry is compiled once, not in every run of this file."""
    from fswkit.run.native import cache_root

    monkeypatch.delenv("FSW_NO_LIB_CACHE", raising=False)
    out = tmp_path / "out"
    assert fsw("build", str(TANK), "--out", str(out)).code == 0
    uno = (out / "fsw-libs" / ".key").read_text()
    r = fsw("build", str(TANK), "--board", "mega2560", "--out", str(out))
    assert r.code == 0, r.err
    mega = (out / "fsw-libs" / ".key").read_text()
    assert mega != uno and {uno, mega} <= {p.name for p in _entries(Path(cache_root()))}
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


def test_the_tools_key_follows_the_tools(tmp_path, monkeypatch):
    """mk/build.mk's AVR_TOOLS_KEY, which `fsw build` passes in place of
    make asking the tools: another compiler first on PATH (the same one
    behind a wrapper) is another key, and so a rebuild."""
    from fswkit.target import libcache

    key = libcache.avr_tools_key("atmega328p")
    assert libcache.avr_tools_key("atmega328p") == key and len(key) == 20
    assert libcache.avr_tools_key("atmega2560") != key  # another MCU's C library
    wrapper = tmp_path / "bin" / "avr-objcopy"
    wrapper.parent.mkdir()
    wrapper.write_text(f"#!/bin/sh\nexec {shutil.which('avr-objcopy')} \"$@\"\n")
    wrapper.chmod(0o755)
    monkeypatch.setenv("PATH", f"{wrapper.parent}{os.pathsep}{os.environ['PATH']}")
    assert libcache.avr_tools_key("atmega328p") != key


def _blocked(tmp_path, monkeypatch) -> None:
    """A cache folder that cannot be made: a file is in its place."""
    blocked = tmp_path / "not-a-folder"
    blocked.write_text("")
    monkeypatch.setenv("FSW_CACHE_DIR", str(blocked))
    monkeypatch.delenv("FSW_NO_LIB_CACHE", raising=False)


def test_a_cache_that_cannot_be_written_leaves_the_build_as_it_was(fsw, first, tmp_path, monkeypatch):
    """The build compiles the core and the runtime in its own folder, and
    its firmware is byte for byte the one linked from the cache's archives."""
    _blocked(tmp_path, monkeypatch)
    out = tmp_path / "uno"
    r = fsw("build", str(TANK), "--out", str(out))
    assert r.code == 0, r.err
    assert not (out / "fsw-libs").exists()
    assert "LIBS=" not in (out / "build.log").read_text().splitlines()[0]
    assert _compiles(out / "build.log")
    assert (out / "tank.hex").read_bytes() == (first[1] / "tank.hex").read_bytes()


def test_no_lib_cache_builds_without_the_cache(monkeypatch, tmp_path):
    """FSW_NO_LIB_CACHE=1: no make variables for the cache, and the cache
    is not even looked at (its folder stays unmade)."""
    from fswkit.target import libcache

    monkeypatch.setenv("FSW_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setenv("FSW_NO_LIB_CACHE", "1")
    avr = {"MCU": "atmega328p", "F_CPU": 16000000, "VARIANT": "standard", "BOARD_DEFINE": "ARDUINO_AVR_UNO",
           "ARDUINO": "/usr/share/arduino/hardware/arduino/avr"}
    assert libcache.make_vars(str(tmp_path / "out"), avr, 1) == []
    assert libcache.make_vars(str(tmp_path / "out"), None, 1) == []
    assert not (tmp_path / "cache").exists()


@pytest.mark.skipif(shutil.which("g++") is None, reason="no host C++ compiler")
def test_a_native_build_links_the_runtimes_objects(fsw, tmp_path, monkeypatch):
    # the user's cache (the runtime's objects `fsw test --native` keeps, as likely there already)
    monkeypatch.delenv("FSW_NO_LIB_CACHE", raising=False)
    out = tmp_path / "native"
    r = fsw("build", str(TANK), "--board", "native", "--out", str(out))
    assert r.code == 0, r.err
    log = (out / "build.log").read_text()
    assert "NATIVE_RT=fsw-libs" in log and "fsw-libs/fsw_machine.o" in log
    # only the generated sources are compiled (one object each), no runtime source
    compiles = [line for line in log.splitlines()[1:] if " -c " in line]
    assert compiles and all(" -c gen/" in line for line in compiles), compiles
    assert not any("firmware/src/fsw_machine.cpp" in line for line in log.splitlines()[1:])
    # an object per source, then the link: the executable byte for byte the
    # one a single command of the same flags makes of the sources and objects
    link = log.splitlines()[-1].split()
    assert link[-1] == "-pthread" and "-o" in link, link
    flags = link[1:link.index("-o")]
    runtime = log.splitlines()[0].split("RUNTIME=", 1)[1].split()[0]
    one = subprocess.run([link[0], *flags, f"-I{runtime}", "-Igen", "-o", "tank.one",
                          *sorted(f"gen/{p.name}" for p in (out / "gen").glob("*.cpp")),
                          *sorted(f"fsw-libs/{p.name}" for p in (out / "fsw-libs").glob("*.o")), "-pthread"],
                         capture_output=True, text=True, cwd=out)
    assert one.returncode == 0, one.stderr
    assert (out / "tank.one").read_bytes() == (out / "tank").read_bytes()
    # with a cache it cannot write, the build compiles the runtime itself
    _blocked(tmp_path, monkeypatch)
    alone = tmp_path / "alone"
    assert fsw("build", str(TANK), "--board", "native", "--out", str(alone)).code == 0
    assert not (alone / "fsw-libs").exists()
    log = (alone / "build.log").read_text()
    assert "NATIVE_RT=" not in log.splitlines()[0] and "firmware/src/fsw_machine.cpp" in log
    # both run the tank the same: 500 cycles, the state vector in hex
    runs = [subprocess.run([str(folder / "tank"), "500"], capture_output=True, text=True, timeout=60)
            for folder in (out, alone)]
    assert runs[0].returncode == 0 and runs[0].stdout and runs[0].stdout == runs[1].stdout, runs


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
