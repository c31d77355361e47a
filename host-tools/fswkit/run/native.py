"""`fsw test --native`: the generated C++ of a machine and its state script,
compiled with the host compiler against the runtime and run. Builds are
cached by the hash of everything that goes into them, the compiler's
identity included. A compile happens in a temporary folder beside the
cache entry, moved into place when complete and removed however the
compile ends; those of processes that died mid-compile are swept away."""

from __future__ import annotations

import atexit
import contextlib
import errno
import hashlib
import os
import re
import shutil
import signal
import struct
import subprocess
import tempfile
import threading
import time

from fswkit.autocode import model as M
from fswkit.autocode.emit.script import script_files
from fswkit.autocode.numeric import Real

from fswkit.autocode.kit import RUNTIME
CXX = os.environ.get("CXX", "g++")
# binary32 builds mirror an AVR: float R and software binary64 conversion.
FLAGS = {32: ["-DFSW_REAL_IS_FLOAT=1", "-DFSW_F64_SOFT=1"], 64: ["-DFSW_REAL_IS_FLOAT=0", "-DFSW_F64_SOFT=0"]}
CXXFLAGS = ["-std=gnu++11", "-O2", "-ffp-contract=off", "-fno-exceptions", "-fno-rtti",
            "-Wall", "-Wextra", "-Werror", "-Wno-unused-function"]


def compiler_flags(cxx: str) -> list[str]:
    """Per compiler: clang's -Wall also judges the user's own logic
    (`T > 20 and T == 20` is always false), which is no defect of the
    generated code, so that warning must not fail the build."""
    return ["-Wno-tautological-overlap-compare"] if "clang" in os.path.basename(cxx) else []


class NativeError(Exception):
    """The host compiler is missing or failed."""


def cache_root() -> str:
    """The kit's cache: $FSW_CACHE_DIR, else fswkit in the user's cache
    folder. `native` holds these runners and the runtime's objects,
    `avr` the boards' archives (fswkit.target.libcache)."""
    return os.environ.get("FSW_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "fswkit")


def cache_dir() -> str:
    return os.path.join(cache_root(), "native")


def runtime_sources() -> list[str]:
    return sorted(os.path.join(RUNTIME, n) for n in os.listdir(RUNTIME)
                  if n.endswith(".cpp") and n != "psl_arduino.cpp")


_versions: dict[tuple, str] = {}


def compiler_identity(cxx: str) -> str:
    """The compiler's path, its size and date, and its version: another
    compiler, or the same one upgraded, is another build."""
    path = shutil.which(cxx) or cxx
    real = os.path.realpath(path)
    try:
        st = os.stat(real)
    except OSError:
        return real
    key = (path, real, st.st_size, st.st_mtime_ns)
    if key not in _versions:
        try:
            r = subprocess.run([path, "--version"], capture_output=True, text=True, timeout=60)
            _versions[key] = r.stdout.split("\n", 1)[0]
        except (OSError, subprocess.TimeoutExpired):
            _versions[key] = ""
    return f"{path}={real} {st.st_size} {st.st_mtime_ns} {_versions[key]}"


def _key(files: dict[str, str], real: Real) -> str:
    """The hash of everything a build reads: the compiler, the runtime's
    sources and headers, `files` (generated), the flags."""
    h = hashlib.sha256()
    h.update(compiler_identity(CXX).encode() + b"\0")
    for path in runtime_sources() + sorted(os.path.join(RUNTIME, n) for n in os.listdir(RUNTIME) if n.endswith(".h")):
        with open(path, "rb") as f:
            h.update(path.encode() + b"\0" + f.read())
    for name in sorted(files):
        h.update(name.encode() + b"\0" + files[name].encode())
    h.update(" ".join([CXX] + CXXFLAGS + compiler_flags(CXX) + FLAGS[real.bits]).encode())
    return h.hexdigest()[:20]


def objects_then_link(run, compile_cmd: list[str], link_cmd: list[str], sources: list[str], exe: str,
                      cwd: str, libraries: list[str] = ()) -> None:
    """Each of `sources` compiled by `compile_cmd` to an object of its own
    (in `cwd`/obj, removed once linked), then the objects and `libraries`
    linked by `link_cmd` into `exe`; `run(cmd)` runs each command in `cwd`
    (and raises on a failure). A compiler cache (ccache) keeps every object,
    which it cannot for one command of several sources; a source named
    relative to `cwd` is the same command wherever the folder is."""
    obj = os.path.join(cwd, "obj")
    os.makedirs(obj)
    objs = []
    for src in sources:
        objs.append(os.path.join("obj", os.path.splitext(os.path.basename(src))[0] + ".o"))
        run(compile_cmd + ["-c", src, "-o", objs[-1]])
    run(link_cmd + objs + list(libraries) + ["-o", exe])
    shutil.rmtree(obj)


def _compile(cmd: list[str], out: str, cwd: str | None = None) -> None:
    """Runs the compiler: a failure is NativeError (the kit's defect), or
    OSError naming the cache folder when the disk there is full or
    read-only (the machine's: said as such)."""
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=cwd)
    if r.returncode != 0:
        from fswkit.outputs import host_write_faults

        log = out + ".log"
        folder = os.path.dirname(out)
        try:
            with open(log, "w") as f:
                f.write(" ".join(cmd) + "\n" + r.stdout + r.stderr)
        except OSError as e:
            raise OSError(e.errno, f"cannot write the native runner's build there: {e.strerror or e} "
                          "(FSW_CACHE_DIR names another folder)", folder) from None
        full = host_write_faults((r.stdout + r.stderr).splitlines())
        if full:  # the disk, not the kit
            raise OSError(errno.ENOSPC, f"cannot write the native runner's build there: {'; '.join(full)} "
                          f"(the compiler's output: {log}; FSW_CACHE_DIR names another folder)", folder)
        errors = [line.strip()[:300] for line in r.stderr.splitlines() if "error:" in line]
        raise NativeError("internal error: the generated code did not compile, although the script and "
                          f"its machine are valid: a defect of fswkit, please report it with {log}" +
                          "".join("\n  " + e for e in errors[:6]))


def runtime_objects(real: Real) -> list[str]:
    """The runtime compiled once for this compiler and evaluation type and
    kept in the cache: nine tenths of a runner's compile, the same for
    every script (each source is its own translation unit either way)."""
    key = _key({"(the runtime alone)": ""}, real)
    out = os.path.join(cache_dir(), key)
    objs = [os.path.join(out, os.path.basename(src)[:-4] + ".o") for src in runtime_sources()]
    if all(os.path.exists(o) for o in objs):
        return objs
    sweep(cache_dir())
    tmp = private_tmp(out)
    with removed_when_done(tmp):
        os.makedirs(tmp, exist_ok=True)
        for src in runtime_sources():  # one object a command: a compiler cache (ccache) can keep each
            _compile([CXX] + CXXFLAGS + compiler_flags(CXX) + FLAGS[real.bits] + ["-I", RUNTIME, "-c", src,
                     "-o", os.path.basename(src)[:-4] + ".o"], out, cwd=tmp)
        try:
            os.replace(tmp, out)
        except OSError:  # another process compiled the same runtime first
            pass
    return objs


def compile_script(script: M.Script, real: Real, source_line) -> str:
    """Generates and compiles the runner; returns the executable's path."""
    if shutil.which(CXX) is None:
        raise NativeError(f"no host C++ compiler `{CXX}` (install g++, or set CXX)")
    files = script_files(script, real, source_line)
    key = _key(files, real)
    out = os.path.join(cache_dir(), key)
    exe = os.path.join(out, "runner")
    if os.path.exists(exe):
        return exe
    sweep(cache_dir())
    tmp = private_tmp(out)
    with removed_when_done(tmp):
        os.makedirs(tmp, exist_ok=True)
        for name, text in files.items():
            with open(os.path.join(tmp, name), "w") as f:
                f.write(text)
        # the generated sources named relative to the temporary folder, so
        # that ccache finds the same commands wherever the folder is
        flags = [CXX] + CXXFLAGS + compiler_flags(CXX) + FLAGS[real.bits]
        objects_then_link(lambda cmd: _compile(cmd, out, cwd=tmp), flags + ["-I", RUNTIME, "-I", "."], flags,
                          sorted(n for n in files if n.endswith(".cpp")), "runner", tmp, runtime_objects(real))
        try:
            os.replace(tmp, out)
        except OSError:  # another process built the same runner first
            pass
    return exe


# ---- temporary folders ----------------------------------------------------------------

TMP_NAME = re.compile(r"^[0-9a-f]{20}\.tmp(\d+)(?:\.\d+)?$")


def private_tmp(out: str) -> str:
    """The temporary folder a compile into `out` works in: its process's and
    its thread's own (two threads of a pool may build the same thing at
    once), named so that `sweep` knows the process."""
    return out + f".tmp{os.getpid()}.{threading.get_ident()}"
STALE_S = 24 * 3600.0  # no compile takes a day: older temporary folders are leftovers
_mine: set[str] = set()  # this process's temporary folders, removed at exit at the latest


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


def sweep(cache: str) -> None:
    """Removes the temporary folders of compiles whose process is gone
    (killed mid-compile), and any older than a day."""
    try:
        names = os.listdir(cache)
    except OSError:
        return
    now = time.time()
    for name in names:
        m = TMP_NAME.match(name)
        if not m or int(m.group(1)) == os.getpid():
            continue
        path = os.path.join(cache, name)
        try:
            old = now - os.stat(path).st_mtime > STALE_S
        except OSError:
            continue
        if old or not _alive(int(m.group(1))):
            shutil.rmtree(path, ignore_errors=True)


def _exit_on_signal(signum, frame):
    raise SystemExit(128 + signum)


@contextlib.contextmanager
def removed_when_done(tmp: str):
    """Removes `tmp` however the block ends: an error, Ctrl-C, SIGTERM or
    SIGHUP (made an exit meanwhile, where no one else handles them), or
    the interpreter's exit."""
    _mine.add(tmp)
    restore = {}
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGTERM, signal.SIGHUP):
            if signal.getsignal(sig) == signal.SIG_DFL:
                restore[sig] = signal.signal(sig, _exit_on_signal)
    try:
        yield
    finally:
        for sig, handler in restore.items():
            signal.signal(sig, handler)
        shutil.rmtree(tmp, ignore_errors=True)
        _mine.discard(tmp)


@atexit.register
def _remove_mine() -> None:
    for tmp in list(_mine):
        shutil.rmtree(tmp, ignore_errors=True)


def run(script: M.Script, real: Real, source_line, trace_path: str | None = None) -> tuple[int, str]:
    """Runs the native runner: (exit status, report). With `trace_path`,
    writes the same CSV trace as the interpreter."""
    exe = compile_script(script, real, source_line)
    raw = None
    args = [exe]
    if trace_path:  # the runner's binary rows: a temporary file of their own, removed however the run ends
        from fswkit.outputs import is_direct

        folder = None if is_direct(trace_path) else os.path.dirname(os.path.abspath(trace_path))  # not in /dev
        fd, raw = tempfile.mkstemp(prefix=".fsw-trace.", suffix=".raw", dir=folder)
        os.close(fd)
        args.append(raw)
    try:
        r = subprocess.run(args, capture_output=True, text=True)
        if r.returncode not in (0, 1):
            raise NativeError(f"the native runner failed (status {r.returncode}): {r.stderr.strip()}")
        if raw:
            _raw_to_csv(script.machine, raw, trace_path)
    finally:
        if raw:
            with contextlib.suppress(OSError):
                os.remove(raw)
    return r.returncode, r.stdout


def _raw_to_csv(m: M.Machine, raw: str, path: str) -> None:
    from fswkit.run.script import _Tracer

    order = sorted(m.vars, key=lambda v: v.display.encode())
    fmt = "<" + "".join("q" if (v.type.is_int and v.type.signed) else "d" if v.type.is_float else "Q"
                        for v in order)
    size = 8 * len(order)
    tracer = _Tracer(path, m)
    try:
        with open(raw, "rb") as f:
            step = 1
            while True:
                chunk = f.read(size * 4096)  # whole rows; a partial last row (the runner stopped) is left
                whole = len(chunk) - len(chunk) % size if size else 0
                if not whole:
                    break
                tracer.rows_ordered(step, struct.iter_unpack(fmt, chunk[:whole]))
                step += whole // size
                if whole < len(chunk):
                    break
    finally:
        tracer.close()
