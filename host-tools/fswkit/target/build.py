"""The build service: an application's configs to generated C++
(`generate`), and to firmware (`firmware`: generate, make, size, budget)
for `fsw gen`, `fsw build`, `fsw flash` and `fsw sim` alike. The firmware
is an `.elf`/`.hex` for a board, an executable for `native`, with its
flash and RAM against the application's `[budget]` (else the board's
memory). A build holds its folder (`build_lock`), keeps the compiler's
output in `build.log` there, and explains a failure: firmware that does
not fit says what uses the memory, line by line of the configs; anything
else the compiler refuses is an internal error to report."""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import re
import shutil
import stat
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass

from fswkit.autocode.app import Application, load_app
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.kit import BUILD_MK, RUNTIME

ARDUINO = "/usr/share/arduino/hardware/arduino/avr"  # mk/build.mk's default, Debian's arduino-core-avr
EXIT_FAIL, EXIT_INTERNAL = 1, 3  # a build's failures: the user's to fix, or a defect of the kit


class BuildError(Exception):
    """A build that cannot go on: the message for the user, and the exit
    status it stands for (EXIT_FAIL, or EXIT_INTERNAL for a defect of the
    kit: generated code the compiler refuses)."""

    def __init__(self, message: str, code: int = EXIT_FAIL):
        super().__init__(message)
        self.code = code


def find_app(project: str) -> str:
    """The application config of a project: the `.app` file itself, or the
    only `.app` in the folder."""
    if os.path.isfile(project):
        if not project.endswith(".app"):
            raise BuildError(f"{project}: not an application config (.app)")
        return project
    if not os.path.isdir(project):
        try:
            mode = os.stat(project).st_mode
        except OSError:
            raise BuildError(f"{project}: no such file or folder") from None
        kind = "a FIFO" if stat.S_ISFIFO(mode) else "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) \
            else "a socket" if stat.S_ISSOCK(mode) else "not a file or folder"
        raise BuildError(f"{project}: not a regular file ({kind}): name the project's folder or its .app file")
    apps = sorted(n for n in os.listdir(project) if n.endswith(".app"))
    if len(apps) != 1:
        found = ", ".join(apps) if apps else "none"
        raise BuildError(f"{project}: expected one application config (.app) in the folder, found {found}")
    return os.path.join(project, apps[0])


def load(project: str, diags: Diagnostics, board: str | None = None) -> Application | None:
    return load_app(find_app(project), diags, board_override=board)


def default_out(app: Application) -> str:
    return os.path.join(os.path.dirname(app.path) or ".", "build", app.board.name)


def _write_whole(path: str, data: bytes) -> None:
    """Writes `data` to a temporary file beside `path` that takes its name
    once whole: a write that fails partway (a full disk, Ctrl-C) leaves the
    old file, or none, never a truncated one that a later compile of the
    folder (arduino-cli on a sketch) would take for whole. OSError naming
    `path` on failure."""
    from fswkit.outputs import _new_file_mode

    folder = os.path.dirname(path) or "."
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{os.path.basename(path)}.", suffix=".part", dir=folder)
    except OSError as e:
        raise OSError(e.errno, e.strerror, path) from None
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        _new_file_mode(tmp, path)
        os.replace(tmp, path)
    except BaseException as e:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(e, OSError):
            raise OSError(e.errno, e.strerror, path) from None
        raise


def write_files(files: dict[str, str], out: str) -> list[str]:
    """Writes generated files, each whole or not at all (`_write_whole`),
    leaving unchanged ones untouched (so Make rebuilds only what changed),
    and removes stale generated files."""
    from fswkit.autocode.diagnostics import InputError, read_head

    os.makedirs(out, exist_ok=True)
    written = []
    for name in sorted(files):
        path = os.path.join(out, name)
        text = files[name]
        data = text.encode()
        try:  # never opened for long: a FIFO there would wait for a writer, /dev/zero never end
            if read_head(path, len(data) + 1) == data:
                continue
        except InputError as e:
            if e.strerror != "is a folder, not a file":  # a folder: open() below says so
                raise OSError(errno.EEXIST, e.strerror.split(":")[0] + ": a generated file replaces only "
                              "a regular file; move it away", path) from None
        except OSError:
            pass
        _write_whole(path, data)
        written.append(path)
    for name in os.listdir(out):
        if name.endswith((".gen.cpp", ".gen.h")) and name not in files:
            os.remove(os.path.join(out, name))
    return written


@dataclass
class Size:
    flash: int  # .text + .data
    ram: int  # .data + .bss
    flash_budget: int
    ram_budget: int
    owner: str = ""  # whose budget: the board's name, or "the application's"

    @property
    def fits(self) -> bool:
        return self.flash <= self.flash_budget and self.ram <= self.ram_budget

    def table(self) -> str:
        def row(name, used, budget, note=""):
            pct = 100.0 * used / budget if budget else 0.0
            return f"  {name:<6}{used:>8,} / {budget:>8,} B  {pct:5.1f} %{note}"
        note = f"  ({self.owner} budget)" if self.owner else ""
        ram_note = ("  (data + bss + noinit; the budget counts the stack too: fsw sim measures it)" if self.owner
                    else "  (data + bss + noinit; the stack uses the rest)")
        return "\n".join([row("flash", self.flash, self.flash_budget, note),
                          row("RAM", self.ram, self.ram_budget, ram_note)])


def budget(app: Application) -> dict[str, tuple[int, str]]:
    """{"flash": (bytes, whose), "RAM": (bytes, whose)}: what the firmware
    may use of each memory, the application's `[budget]` where it sets one,
    else the board's memory (RAM: data + bss + noinit + the stack)."""
    b = app.board

    def one(mine: int | None, board: int) -> tuple[int, str]:
        return (mine, "the application's [budget]") if mine is not None else (board, f"the {b.name}'s memory")

    return {"flash": one(app.flash_budget, b.flash), "RAM": one(app.ram_budget, b.ram)}


def size_of(app, flash: int, ram: int) -> Size:
    """The firmware's size against its budget (`budget`)."""
    limits = budget(app)
    mine = app.flash_budget is not None or app.ram_budget is not None
    return Size(flash, ram, limits["flash"][0], limits["RAM"][0], "the application's" if mine else "")


def elf_size(elf: str) -> tuple[int, int]:
    """(flash, RAM) bytes of an AVR ELF: .text + .data, and .data + .bss +
    .noinit (RAM the C runtime leaves as it was at a reset: the banks a
    flight resumes from, docs/safety.md)."""
    r = subprocess.run(["avr-size", "-A", elf], capture_output=True, text=True)
    if r.returncode != 0:
        raise BuildError(f"avr-size failed: {r.stderr.strip()}")
    sec = {}
    for line in r.stdout.splitlines():
        parts = line.split()
        if len(parts) >= 2 and parts[0].startswith(".") and parts[1].isdigit():
            sec[parts[0]] = int(parts[1])
    return sec.get(".text", 0) + sec.get(".data", 0), sec.get(".data", 0) + sec.get(".bss", 0) + sec.get(".noinit", 0)


# ---- the service ------------------------------------------------------------------------

def generate(app: Application, out: str) -> dict[str, str]:
    """Generates the application's C++ into `out` (`write_files`); returns
    {file name: text}. BuildError when the generator refuses it or the
    folder cannot be written."""
    import fswkit.autocode.emit.app as emit  # looked up per call: a test stands in a generator

    try:
        files = emit.emit_app(app)
    except emit.GenError as e:
        raise BuildError(str(e)) from None
    try:
        write_files(files, out)
    except OSError as e:
        raise BuildError(f"cannot write {e.filename or out}: {e.strerror or e}") from None
    return files


@dataclass
class Built:
    """A finished build: the firmware and, for a board, its size against the
    budget. Firmware that does not fit is built all the same (`fits` is
    False, `report` says what uses the memory): the caller refuses it."""
    app: Application
    out: str
    artifact: str  # the ELF for a board, the executable for `native`
    size: Size | None = None  # None for `native`: the host's memory is not limited
    report: str | None = None  # what does not fit and what uses it (size_report), when it does not fit

    @property
    def elf(self) -> str | None:
        return self.artifact if self.app.board.is_avr else None

    @property
    def hex(self) -> str | None:
        return self.artifact[:-4] + ".hex" if self.app.board.is_avr else None

    @property
    def fits(self) -> bool:
        return self.size is None or self.size.fits


def firmware(app: Application, out: str, *, command: str = "build", jobs: int = 2) -> Built:
    """Builds the application's firmware in `out`, holding the folder:
    generate (into out/gen), make, size, budget. BuildError (with its exit
    status) when it cannot be built; a firmware that does not fit its
    budget is returned with `fits` False and its `report`. `command` names
    who waits in the message of a folder another build holds."""
    try:
        with build_lock(out, command):
            generate(app, os.path.join(out, "gen"))
            artifact, proc = make(app, out, jobs)
            if proc.returncode != 0:
                too_big, message = explain_failure(app, out, proc)
                raise BuildError(message, EXIT_FAIL if too_big else EXIT_INTERNAL)
            if not app.board.is_avr:
                return Built(app, out, artifact)
            size = size_of(app, *elf_size(artifact))
            return Built(app, out, artifact, size, None if size.fits else size_report(app, artifact, size))
    except OSError as e:
        raise BuildError(f"cannot write {e.filename or out}: {e.strerror or e}") from None


# ---- one build of a folder at a time ---------------------------------------------------

LOCK_TIMEOUT_S = 600.0  # how long a build waits for another build of its folder
_held: dict[str, int] = {}  # folders this process holds: {real path: depth}


@contextlib.contextmanager
def build_lock(out: str, command: str = "build"):
    """Holds the build folder `out` (an exclusive lock on `out/.lock`, which
    the system drops when its holder exits, however it exits). A second
    build of the folder waits, saying for which process, and gives up after
    LOCK_TIMEOUT_S. Reentrant within a process (`fsw flash` builds, then
    uploads, under one hold)."""
    os.makedirs(out, exist_ok=True)
    key = os.path.realpath(out)
    if key in _held:
        _held[key] += 1
        try:
            yield
        finally:
            _held[key] -= 1
        return
    fd = os.open(os.path.join(out, ".lock"), os.O_RDWR | os.O_CREAT, 0o644)
    try:
        if not _try_lock(fd):
            holder = _holder(fd)
            sys.stderr.write(f"fsw {command}: waiting for another build of {out} (pid {holder})\n")
            sys.stderr.flush()
            deadline = time.monotonic() + LOCK_TIMEOUT_S
            while not _try_lock(fd):
                if time.monotonic() > deadline:
                    raise BuildError(f"another build of {out} (pid {_holder(fd)}) has held it for over "
                                     f"{LOCK_TIMEOUT_S:g} s: let it finish, or build into another folder (--out)")
                time.sleep(0.05)
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        _held[key] = 0
        try:
            yield
        finally:
            del _held[key]
    finally:
        os.close(fd)  # and with it the lock


def _try_lock(fd: int) -> bool:
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    return True


def _holder(fd: int) -> str:
    """The process id the holder of a lock file wrote into it."""
    for _ in range(20):  # the holder writes it right after taking the lock
        text = os.pread(fd, 32, 0).decode(errors="replace").strip()
        if text.isdigit():
            return text
        time.sleep(0.01)
    return "unknown"


# ---- make ------------------------------------------------------------------------------

def firmware_name(app: Application) -> str:
    """The firmware's file name without extension: the application file's
    name, with any character Make cannot take in a file name (spaces, `$`,
    `%`, `:`, quotes...) replaced by `_`."""
    return re.sub(r"[^A-Za-z0-9_.+-]", "_", os.path.splitext(os.path.basename(app.path))[0])


def make_args(app: Application, out: str, jobs: int = 2, cached: bool = False) -> tuple[str, list[str]]:
    """(artifact, command) of mk/build.mk for the application. The command
    runs in `out` and names the build's own files relative to it, so a
    folder whose path Make cannot take (a space, `:`) builds all the same.
    `cached`: linked against the Arduino core and the runtime compiled
    once for every build of the board (fswkit.target.libcache), made
    ready now; the caller holds the folder."""
    b = app.board
    name = firmware_name(app)
    args = ["make", "--no-print-directory", f"-j{jobs}", "-f", BUILD_MK, "GEN=gen", "OUT=.", f"NAME={name}",
            f"RUNTIME={RUNTIME}"]
    if b.is_avr:
        ard = b.raw.get("arduino", {})
        for tool in ("avr-g++", "avr-gcc", "avr-size", "avr-nm", "make"):
            if shutil.which(tool) is None:
                raise BuildError(f"`{tool}` is not installed: run `make setup` (or tools/bootstrap.sh)")
        if not os.path.isfile(os.path.join(ARDUINO, "cores", "arduino", "Arduino.h")):
            raise BuildError(f"the Arduino core is not installed ({ARDUINO}, Debian package arduino-core-avr): "
                             "run `make setup` (or tools/bootstrap.sh)")
        board = {"MCU": b.mcu, "F_CPU": b.f_cpu, "VARIANT": ard.get("variant", "standard"),
                 "BOARD_DEFINE": ard.get("board_define", "ARDUINO_AVR_UNO")}
        args += ["avr"] + [f"{k}={v}" for k, v in board.items()]
        avr = dict(board, ARDUINO=ARDUINO)
        artifact = os.path.join(out, name + ".elf")
    else:
        if shutil.which("g++") is None or shutil.which("make") is None:
            raise BuildError("`g++` and `make` are needed for native builds: run `make setup`")
        args += ["native"]
        avr = None
        artifact = os.path.join(out, name)
    if cached:
        from fswkit.target.libcache import make_vars

        args += make_vars(out, avr, jobs)
    return artifact, args


def make(app: Application, out: str, jobs: int = 2) -> tuple[str, subprocess.CompletedProcess]:
    """Runs mk/build.mk for the application, holding its folder; returns
    (artifact, process). The compiler's whole output goes to `out/build.log`."""
    with build_lock(out):
        artifact, args = make_args(app, out, jobs, cached=True)
        proc = _run_make(args, out)
        with open(log_path(out), "w") as f:
            f.write(" ".join(args) + "\n" + proc.stdout + proc.stderr)
    return artifact, proc


def _is_step(line: str) -> bool:
    """A command of make's output that is a build step (a compile, an
    archive, the link, the hex): not the folders it makes, nor make's own words."""
    line = line.strip()
    return bool(line) and not line.startswith(("mkdir ", "make:", "make["))


def _run_make(args: list[str], out: str) -> subprocess.CompletedProcess:
    """make in `out`, its output captured (as `subprocess.run` captures it).
    On a terminal, a bar counts its steps: a dry run (`make -n`) counts
    those to do, then each command make prints is one done."""
    from fswkit.progress import active, progress

    if not active():
        return subprocess.run(args, capture_output=True, text=True, cwd=out)
    dry = subprocess.run(args + ["-n"], capture_output=True, text=True, cwd=out)
    total = sum(map(_is_step, dry.stdout.splitlines())) if dry.returncode == 0 else None
    with progress("build", total=total or None, unit="steps") as bar, \
            subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=out) as p:
        try:
            errors: list[str] = []
            reader = threading.Thread(target=lambda: errors.append(p.stderr.read()), daemon=True)
            reader.start()
            lines, done = [], 0
            for line in p.stdout:
                lines.append(line)
                if _is_step(line):
                    done += 1
                    bar.update(min(done, total) if total else done)
            reader.join()
            p.wait()
        except BaseException:
            p.kill()
            raise
    return subprocess.CompletedProcess(args, p.returncode, "".join(lines), "".join(errors))


def log_path(out: str) -> str:
    return os.path.join(out, "build.log")


# ---- why a build failed -----------------------------------------------------------------

# The linker's words for memory that is too small (GNU ld).
OVERFLOW = re.compile(r"region [`']?(\w+)'? overflowed by (\d+) bytes|will not fit in region|"
                      r"is not within region")
OVERFLOW_BY = re.compile(r"region [`']?\w+'? overflowed by \d+ bytes")
ERROR_LINE = re.compile(r"error:|static assertion failed|undefined reference")


def overflows(proc: subprocess.CompletedProcess) -> bool:
    return OVERFLOW.search(proc.stdout + proc.stderr) is not None


def explain_failure(app: Application, out: str, proc: subprocess.CompletedProcess) -> tuple[bool, str]:
    """Why a build failed: (the firmware does not fit, the message). A
    linker that runs out of the MCU's memory is answered with what uses it
    (`size_report`); anything else that fails on a checked configuration is
    a defect of the kit, reported with the build log."""
    log = log_path(out)
    output = (proc.stdout + proc.stderr).splitlines()
    if app.board.is_avr and overflows(proc):
        report = overflow_report(app, out)
        if report is not None:
            return True, report
        said = sorted({m.group(0) for line in output for m in [OVERFLOW_BY.search(line)] if m})
        return True, (f"the firmware does not fit the {app.board.name} ({app.board.mcu}): "
                      + ("; ".join(said) if said else "the linker ran out of memory")
                      + f" (the linker's output: {log})")
    lines = [line.strip() for line in output if ERROR_LINE.search(line)] or [line.strip() for line in output[-3:]]
    shown = [("  " + line[:300] + (" ..." if len(line) > 300 else "")) for line in lines[:6]]
    more = f"\n  ... and {len(lines) - 6} more" if len(lines) > 6 else ""
    return False, ("internal error: the generated code did not build for the "
                   f"{app.board.name}, although the configuration is valid: a defect of fswkit, please report "
                   f"it with {log}" + ("\n" + "\n".join(shown) + more if shown else ""))


def overflow_report(app: Application, out: str) -> str | None:
    """Links the firmware although it does not fit (`NAME.overflow.elf`,
    removed after) and says what uses the memory; None when that fails."""
    elf = None
    try:
        with build_lock(out):
            artifact, args = make_args(app, out, cached=True)
            elf = artifact[:-4] + ".overflow.elf"
            args = [a for a in args if a != "avr"] + [os.path.basename(elf)]
            r = subprocess.run(args, capture_output=True, text=True, cwd=out)
            if r.returncode != 0 or not os.path.exists(elf):
                return None
            flash, ram = elf_size(elf)
            return size_report(app, elf, size_of(app, flash, ram))
    except BuildError:
        return None
    finally:
        if elf is not None and os.path.exists(elf):
            os.remove(elf)


# ---- what uses the memory ------------------------------------------------------------------

RAM_BASE, EEPROM_BASE = 0x800000, 0x810000  # avr-gcc's address spaces
CLONE = re.compile(r" \[clone [^\]]*\]|\.(?:lto_priv|constprop|isra|part)\.\d+")


def elf_symbols(elf: str) -> list[tuple[int, int, str, str]]:
    """(address, size, nm type, demangled name) of an ELF's sized symbols.
    A name LTO gave a suffix (`_ZN7fsw_gen12_GLOBAL__N_13recE.lto_priv.45`)
    is left mangled by `avr-nm -C`: without the suffix, avr-c++filt
    demangles it (fsw_gen::(anonymous namespace)::rec)."""
    r = subprocess.run(["avr-nm", "-S", "-C", elf], capture_output=True, text=True)
    if r.returncode != 0:
        raise BuildError(f"avr-nm failed: {r.stderr.strip()}")
    out = []
    for line in r.stdout.splitlines():
        parts = line.split(" ", 3)
        if len(parts) == 4:
            try:
                out.append((int(parts[0], 16), int(parts[1], 16), parts[2], CLONE.sub("", parts[3])))
            except ValueError:
                continue
    mangled = sorted({name for *_, name in out if name.startswith("_Z")})
    if mangled:
        f = subprocess.run(["avr-c++filt"], input="\n".join(mangled) + "\n", capture_output=True, text=True)
        plain = f.stdout.splitlines()
        if f.returncode == 0 and len(plain) == len(mangled):
            names = dict(zip(mangled, plain))
            out = [(a, n, k, names.get(name, name)) for a, n, k, name in out]
    return out


@dataclass
class Use:
    """A part of the firmware's flash or RAM, named by what in the configs it
    comes from; `detail` breaks it down further."""
    label: str
    size: int = 0
    detail: list[tuple[int, str]] | None = None


def memory_users(app: Application, elf: str) -> dict[str, list[Use]]:
    """{"flash": [...], "RAM": [...]}, largest first: every generated symbol
    of the ELF attributed to the config line it comes from (the state
    vector's regions from the model), the rest as the runtime's."""
    from fswkit.autocode.emit.common import basename, c_ident

    a = basename(app.path)
    sv = basename(app.sv.path)
    machines = {c_ident(m.name): m for m in app.machines}
    tele = next((t for t in app.tasks if t.kind == "telemetry"), None)
    uses: dict[tuple[str, str], Use] = {}

    def add(space: str, key: str, label: str, size: int, detail=None) -> None:
        u = uses.setdefault((space, key), Use(label, 0, detail))
        u.size += size

    def owner(name: str, data: bool) -> tuple[str, str] | None:
        """(key, label) of a generated symbol."""
        m = re.match(r"fsw_gen::(?:\(anonymous namespace\)::)?(.*)", name)
        if not m:
            return None
        rest = m.group(1)
        if rest == "sv":
            return "sv", f"the state vector, {sv} ({len(app.sv.elements)} elements)"
        head, sep, inner = rest.partition("::")
        if sep and head in machines:
            mach = machines[head]
            src = basename(mach.path)
            inner = inner.removeprefix("(anonymous namespace)::")
            w = re.fullmatch(r"w(\d+)", inner)
            if w and int(w.group(1)) < len(mach.windows):
                win = mach.windows[int(w.group(1))]
                return (f"w:{head}:{win.index}",
                        f"roll_{win.func} window of {win.size}, {src}:{win.line} (machine {mach.name})")
            if inner in ("loc", "kLocInit"):
                return f"loc:{head}", f"the locals of machine {mach.name}, {src} [local]"
            if data:
                return f"m:{head}", f"machine {mach.name}, {src}: its state"
            return f"m:{head}", f"machine {mach.name}, {src}: its states' code"
        task = re.match(r"task_(\w+)", rest)
        if task:
            t = next((t for t in app.tasks if t.name == task.group(1)), None)
            if t is not None and t.kind == "machine":
                mach = app.machines[t.machine]
                return f"m:{c_ident(mach.name)}", f"machine {mach.name}, {basename(mach.path)}: its states' code"
            if t is not None:
                return f"t:{t.name}", f"task {t.name} ({t.kind}), {a}:{t.line}"
        if rest.startswith(("reload", "kReload")) and app.reload is not None:
            return "reload", f"the machine replaced at run time: its image, windows and locals, and store, " \
                             f"{a}:{app.reload.line} [reload]"
        store = re.fullmatch(r"link_store_(\d+)", rest)
        if store and int(store.group(1)) < len(app.telemetry):
            s = app.telemetry[int(store.group(1))]
            return f"store:{s.region.name}", f"samples of stream {s.region.name} batched per frame, {a}:{s.line}"
        if rest == "link_tx":
            where = f"{a}:{tele.line}" if tele is not None else a
            return "link_tx", f"the telemetry transmit buffer (the longest frame), {where}"
        if rest.startswith(("link", "kLink")):
            return "link", f"the serial link's state and tables, {a} [telemetry] [uplink]"
        if rest in ("stats", "kTasks", "kConfig", "ex"):
            n = len(app.tasks)
            return "tasks", f"the executor and its {n} task{'' if n == 1 else 's'}, {a} [tasks]"
        if re.match(r"k(Analog|Digital)(In|Out)", rest):
            files = ", ".join(sorted({basename(c.path) for c in app.channels}))
            return "io", f"the I/O channel tables, {files}"
        return "gen", "other generated code and data"

    for addr, size, kind, name in elf_symbols(elf):
        if size == 0 or kind in "aAuUN" or addr >= EEPROM_BASE:
            continue
        data = addr >= RAM_BASE
        who = owner(name, data)
        key, label = who if who is not None else ("", "")
        if data:
            if who is not None:
                add("RAM", key, label, size)
            if kind in "dD":  # initialised data: its initial value is in flash too
                add("flash", key, label, size) if who is not None else None
        elif who is not None:
            add("flash", key, label, size)
    if any(space == "flash" and key.startswith("m:") for space, key in uses):
        lines = config_lines_code(elf)
        for m in app.machines:
            u = uses.get(("flash", f"m:{c_ident(m.name)}"))
            src = basename(m.path)
            rows = sorted(((n, line) for (f, line), n in lines.items() if f == src), key=lambda x: (-x[0], x[1]))
            if u is not None and rows:
                u.detail = [(n, f"{src}:{line}  {_source_line(m.path, line)}") for n, line in rows]
    regions = sorted(app.sv.regions, key=lambda r: -r.size)
    sv_detail = [(r.size, f"region {r.name}, {basename(app.sv.path)}:{r.line} "
                          f"({len(r.elements)} element{'' if len(r.elements) == 1 else 's'})") for r in regions]
    if ("RAM", "sv") in uses:
        uses[("RAM", "sv")].detail = sv_detail
    return {space: sorted((u for (s, _), u in uses.items() if s == space), key=lambda u: -u.size)
            for space in ("flash", "RAM")}


MARKER = re.compile(r"^(/.*\.gen\.cpp):(\d+)(?: \(discriminator \d+\))?$|^/.*:\d+(?: \(discriminator \d+\))?$")
INSN = re.compile(r"^\s+[0-9a-f]+:\t((?:[0-9a-f]{2} )+)")
CONFIG_LINE = re.compile(r"// ([^\s:]+):(\d+)\b")


def config_lines_code(elf: str) -> dict[tuple[str, int], int]:
    """Bytes of machine code per config line: {(config file, line): bytes}.
    The disassembly's line table places each instruction on a line of the
    generated C++, whose comment names the config line it comes from."""
    r = subprocess.run(["avr-objdump", "-d", "-l", elf], capture_output=True, text=True)
    if r.returncode != 0:
        return {}
    by_gen: dict[tuple[str, int], int] = {}
    where = None
    for line in r.stdout.splitlines():
        m = MARKER.match(line)
        if m:
            where = (m.group(1), int(m.group(2))) if m.group(1) else None
            continue
        m = INSN.match(line)
        if m and where is not None:
            by_gen[where] = by_gen.get(where, 0) + len(m.group(1).split())
    out: dict[tuple[str, int], int] = {}
    texts: dict[str, list[str]] = {}
    for (path, n), size in by_gen.items():
        if path not in texts:
            try:
                with open(path) as f:
                    texts[path] = f.read().splitlines()
            except OSError:
                texts[path] = []
        text = texts[path][n - 1] if 0 < n <= len(texts[path]) else ""
        c = CONFIG_LINE.search(text)
        if c:
            key = (c.group(1), int(c.group(2)))
            out[key] = out.get(key, 0) + size
    return out


def _source_line(path: str, n: int, width: int = 60) -> str:
    try:
        with open(path, errors="replace") as f:
            for i, text in enumerate(f, 1):
                if i == n:
                    text = " ".join(text.split())
                    return text if len(text) <= width else text[:width - 3] + "..."
    except OSError:
        pass
    return ""


def size_report(app: Application, elf: str, size: Size, top: int = 8) -> str:
    """What does not fit, by how much, and what uses that memory: the
    largest parts first, each named by the config line it comes from."""
    b = app.board
    whose = "the application's [budget]" if size.owner else f"the {b.name} ({b.mcu})"
    over = [(what, used, budget) for what, used, budget in (("flash", size.flash, size.flash_budget),
                                                            ("RAM", size.ram, size.ram_budget)) if used > budget]
    lines = [f"the firmware does not fit {whose}: " +
             ("; ".join(f"{what} {used:,} B of {budget:,} B, {used - budget:,} B over" for what, used, budget in over)
              or "the linker ran out of one of its memories"),
             size.table()]
    try:
        users = memory_users(app, elf)
    except BuildError:
        return "\n".join(lines)
    for what, used, _ in over:
        parts = users[what]
        runtime = used - sum(u.size for u in parts)
        lines.append(f"what uses {what}, largest first:")
        for u in parts[:top]:
            lines.append(f"  {u.size:>9,} B  {u.label}" + (", the costliest lines:" if what == "flash" and u.detail
                                                             else ""))
            for n, text in (u.detail or [])[:5]:
                lines.append(f"  {'':>11}  {n:>7,} B  {text}")
            if what == "flash" and u.detail and len(u.detail) > 5:
                lines.append(f"  {'':>11}  {sum(n for n, _ in u.detail):>7,} B  in all {len(u.detail)} lines with code")
        rest = sum(u.size for u in parts[top:])
        if rest:
            lines.append(f"  {rest:>9,} B  {len(parts) - top} smaller part(s) of the generated code")
        if runtime > 0:
            lines.append(f"  {runtime:>9,} B  the fswkit runtime, the Arduino core and the C library"
                         + (" (serial buffers, the clock)" if what == "RAM" else ""))
    if any(what == "RAM" for what, _, _ in over):
        lines.append("(RAM must also leave room for the stack)")
    return "\n".join(lines)
