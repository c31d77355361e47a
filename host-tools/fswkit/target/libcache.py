"""What every build for a board compiles alike, compiled once: the Arduino
core and the fswkit runtime as archives for an AVR board (`core.a`,
`libfswkit.a`), the runtime's objects for `native`. `fsw build` links a
project's generated code against them instead of compiling them again in
each build folder (examples/rocket: 0.8 s of CPU instead of 2.1 for the
Uno, 0.5 s instead of 2.6 natively).

They are kept in the user's cache beside `fsw test --native`'s runners
(~/.cache/fswkit, or $FSW_CACHE_DIR), keyed by the hash of everything that
goes into them: mk/build.mk (the flags), the board's MCU, clock, variant
and define, the compilers' and the C library's identity, the runtime's
folder (the archives' debug information names their sources), and the
contents of the runtime's and the Arduino core's sources and headers. An entry is
built in a private temporary folder (fswkit.run.native's) and moved into
place whole, so concurrent builds never see each other's half-written
files. A build folder keeps its own links (or copies) of the entry it uses
(`fsw-libs/`, with the archives' compile output in `fsw-libs/build.log`)
and hands its key to make, which takes it as part of the build's
configuration: another entry relinks the firmware.

Anything that keeps the cache from working (a cache folder that cannot be
written, a path make cannot take, a compile that fails there) leaves the
build as it was without it: everything compiled in the build folder, where
a failure is reported as usual."""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import os
import re
import shutil
import subprocess
import time

from fswkit.autocode.diagnostics import read_head
from fswkit.autocode.kit import BUILD_MK, RUNTIME

LINKED = "fsw-libs"  # the build folder's links to the entry it uses
ARCHIVES = ("core.a", "libfswkit.a")
_MAKE_SAFE = re.compile(r"^[A-Za-z0-9_./+-]+$")  # a path make takes as a prerequisite
_libc: dict[tuple, str] = {}  # {(the compiler's identity, mcu): the C library's path}


def _tree_hash(h, folder: str) -> None:
    """Every file of `folder` (not its subfolders), by name and content."""
    try:
        listed = sorted(os.listdir(folder))
    except OSError:
        h.update(f"{folder}: absent\0".encode())
        return
    for name in listed:
        path = os.path.join(folder, name)
        if not os.path.isfile(path):
            continue
        with open(path, "rb") as f:
            h.update(name.encode() + b"\0" + f.read() + b"\0")


def _libc_identity(cc: str, mcu: str) -> str:
    """The C library the compiler links for `mcu` (its headers come with
    it): path, size and date. The compiler is asked for its path once per
    compiler (its identity: path, size, date, version), the file looked at
    on every call."""
    from fswkit.run.native import compiler_identity

    key = (compiler_identity(cc), mcu)
    if key not in _libc:
        try:
            r = subprocess.run([cc, f"-mmcu={mcu}", "-print-file-name=libc.a"], capture_output=True, text=True,
                               timeout=60)
            _libc[key] = r.stdout.strip()
        except (OSError, subprocess.TimeoutExpired):
            return ""
    try:
        st = os.stat(_libc[key])
    except OSError:
        return ""
    return f"{_libc[key]} {st.st_size} {st.st_mtime_ns}"


AVR_TOOLS = ("avr-gcc", "avr-g++", "avr-gcc-ar", "avr-objcopy")  # mk/build.mk's AVR_CC, AVR_CXX, AVR_AR, AVR_OBJCOPY


def avr_tools_key(mcu: str) -> str:
    """mk/build.mk's AVR_TOOLS_KEY for its default tools: the hash of each
    one's identity (path, size, date, version) and of the C library's
    (path, size, date) for `mcu`. A tool replaced or upgraded is another
    key, and make rebuilds as it would have found by asking the tools
    itself."""
    from fswkit.run.native import compiler_identity

    h = hashlib.sha256(b"fswkit avr tools 1\0")
    for tool in AVR_TOOLS:
        h.update(compiler_identity(tool).encode() + b"\0")
    h.update(_libc_identity("avr-gcc", mcu).encode() + b"\0")
    return h.hexdigest()[:20]


def avr_key(mcu: str, f_cpu: int, variant: str, define: str, arduino: str) -> str:
    from fswkit.run.native import compiler_identity

    h = hashlib.sha256(b"fswkit avr archives 1\0")
    # (the folders too: the archives' debug information names their sources)
    h.update(f"{mcu} {f_cpu} {variant} {define} {os.path.realpath(arduino)} {os.path.realpath(RUNTIME)}\0".encode())
    for tool in ("avr-gcc", "avr-g++", "avr-gcc-ar"):
        h.update(compiler_identity(tool).encode() + b"\0")
    h.update(_libc_identity("avr-gcc", mcu).encode() + b"\0")
    with open(BUILD_MK, "rb") as f:
        h.update(f.read())
    _tree_hash(h, RUNTIME)
    _tree_hash(h, os.path.join(arduino, "cores", "arduino"))
    _tree_hash(h, os.path.join(arduino, "variants", variant))
    return h.hexdigest()[:20]


def _entry_ready(entry: str) -> bool:
    return all(os.path.isfile(os.path.join(entry, n)) for n in ARCHIVES)


UNUSED_S = 30 * 24 * 3600.0  # an entry no build used for this long is removed (another runtime, board, tools)


def _prune(cache: str) -> None:
    """Removes the entries no build used for UNUSED_S (each is about
    1.7 MB; a runtime edited and built again leaves its old ones)."""
    now = time.time()
    for name in os.listdir(cache):
        path = os.path.join(cache, name)
        if re.fullmatch(r"[0-9a-f]{20}(\.lock)?", name):
            with contextlib.suppress(OSError):
                if now - os.stat(path).st_mtime > UNUSED_S:
                    if os.path.isdir(path):
                        shutil.rmtree(path, ignore_errors=True)
                    else:  # its lock: at worst a build that holds it compiles beside another one
                        os.remove(path)


def avr_archives(mcu: str, f_cpu: int, variant: str, define: str, arduino: str, jobs: int) -> tuple[str, str] | None:
    """(the cache entry holding this configuration's core.a and
    libfswkit.a, its key), compiled now if no build compiled them before;
    None when the cache cannot be used."""
    from fswkit.run.native import cache_root

    try:
        key = avr_key(mcu, f_cpu, variant, define, arduino)
        cache = os.path.join(cache_root(), "avr")
        entry = os.path.join(cache, key)
        if _entry_ready(entry):
            with contextlib.suppress(OSError):
                os.utime(entry)  # used: kept by _prune
            return entry, key
        os.makedirs(cache, exist_ok=True)
        # one compile of an entry at a time: the builds that start together on a fresh machine (make
        # test's workers, a study's first runs) wait for the first instead of compiling it each
        fd = os.open(entry + ".lock", os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
            if _entry_ready(entry):
                return entry, key
            return _compile_entry(cache, entry, key, mcu, f_cpu, variant, define, arduino, jobs)
        finally:
            os.close(fd)  # and with it the lock
    except OSError:
        return None


def _compile_entry(cache: str, entry: str, key: str, mcu: str, f_cpu: int, variant: str, define: str,
                   arduino: str, jobs: int) -> tuple[str, str] | None:
    """Compiles the entry's archives in a private folder and moves it
    into place (the caller holds the entry's lock)."""
    from fswkit.run.native import private_tmp, removed_when_done, sweep

    sweep(cache)
    _prune(cache)
    tmp = private_tmp(entry)
    with removed_when_done(tmp):
        work = os.path.join(tmp, "work")
        os.makedirs(os.path.join(work, "gen"))
        cmd = ["make", "--no-print-directory", f"-j{jobs}", "-f", BUILD_MK, "GEN=gen", "OUT=.", "NAME=libs",
               f"RUNTIME={RUNTIME}", f"ARDUINO={arduino}", f"MCU={mcu}", f"F_CPU={f_cpu}", f"VARIANT={variant}",
               f"BOARD_DEFINE={define}"] + list(ARCHIVES)
        r = subprocess.run(cmd, capture_output=True, text=True, cwd=work)
        if r.returncode != 0:
            return None  # the build folder's own compile reports it
        for name in ARCHIVES:
            os.replace(os.path.join(work, name), os.path.join(tmp, name))
        with open(os.path.join(tmp, "build.log"), "w") as f:  # the compile's output, as a build folder keeps
            f.write(" ".join(cmd) + "\n" + r.stdout + r.stderr)
        shutil.rmtree(work)
        try:
            os.replace(tmp, entry)
        except OSError:  # another build compiled the same entry first
            pass
    return (entry, key) if _entry_ready(entry) else None


def native_objects() -> tuple[str, str] | None:
    """(the cache folder of the runtime's objects for a native build, its
    key): `fsw test --native`'s, compiled with the same compiler and
    flags (binary64, as a native build evaluates); None when the cache
    cannot be used."""
    from fswkit.autocode.numeric import F64MODE
    from fswkit.run.native import NativeError, runtime_objects

    try:
        objs = runtime_objects(F64MODE)
    except (NativeError, OSError):
        return None
    entry = os.path.dirname(objs[0])
    return entry, os.path.basename(entry)


def link_into(out: str, entry: str, key: str) -> str | None:
    """The build folder's `fsw-libs/` made the entry's files (hard links,
    else copies), unless it is already; the folder's name relative to
    `out`, or None if that fails."""
    here = os.path.join(out, LINKED)
    stamp = os.path.join(here, ".key")
    try:  # a FIFO or a device there is not waited on or read: the folder is made again
        if read_head(stamp, len(key.encode()) + 1) == key.encode():
            return LINKED
    except OSError:
        pass
    try:
        shutil.rmtree(here, ignore_errors=True)
        os.makedirs(here)
        for name in sorted(os.listdir(entry)):
            src, dst = os.path.join(entry, name), os.path.join(here, name)
            if not os.path.isfile(src):
                continue
            try:
                os.link(src, dst)
            except OSError:
                shutil.copyfile(src, dst)
        with open(stamp, "w") as f:
            f.write(key)
    except OSError:
        shutil.rmtree(here, ignore_errors=True)
        return None
    return LINKED


def make_vars(out: str, avr: dict | None, jobs: int) -> list[str]:
    """The make variables that link a build in `out` against the cache:
    `avr` the board's MCU, F_CPU, VARIANT, BOARD_DEFINE and ARDUINO (None:
    a native build). Empty when the cache cannot be used (the build then
    compiles everything itself), or when FSW_NO_LIB_CACHE is set."""
    if os.environ.get("FSW_NO_LIB_CACHE"):
        return []
    if avr is not None:
        got = avr_archives(avr["MCU"], avr["F_CPU"], avr["VARIANT"], avr["BOARD_DEFINE"], avr["ARDUINO"], jobs)
    else:
        got = native_objects()
    if got is None:
        return []
    folder = link_into(out, *got)
    if folder is None:
        return []
    if avr is not None:
        return [f"LIBS={folder}", f"LIBS_KEY={got[1]}"]
    from fswkit.run.native import CXX

    if not _MAKE_SAFE.match(CXX):
        return []
    return [f"NATIVE_RT={folder}", f"NATIVE_RT_KEY={got[1]}", f"HOST_CXX={CXX}"]
