"""Where a command's output goes: standard output, or a file that appears
whole or not at all. Every command that writes a file goes through `output`:
the path is checked before any work (not one of the command's inputs, not a
recording — a link log, replaced only by a new link log when asked, or an
archive, never —, not a file there when the command asks first, a folder
that exists), the text goes to a temporary file beside it that replaces the path
only once everything is written, and a failed write — a full disk, a closed
pipe, /dev/full — is an OutputError naming the file, never a traceback or a
half-written file where the old one was."""

from __future__ import annotations

import contextlib
import hashlib
import io
import os
import re
import signal
import stat
import sys
import tempfile
import threading


# The head of a link recording (`fsw monitor --log`, `fsw sim --plant`):
# fswkit.link.log writes it; recordings are never overwritten unasked.
RECORDING_MAGIC = b"FSWLOG1\n"
ARCHIVE_ID = 0x46535741  # "FSWA": a ground station archive's PRAGMA application_id (fswkit.ground.archive)


# A compiler, assembler or linker that could not write a file says one of
# these: the disk's fault (full, over quota, read-only), not the code's.
HOST_WRITE = re.compile(r"No space left on device|Disk quota exceeded|Read-only file system")


def host_write_faults(lines) -> list[str]:
    """What a tool's output lines say of a disk it could not write
    (HOST_WRITE: each line's first, each once, sorted); empty when none."""
    return sorted({m.group(0) for m in map(HOST_WRITE.search, lines) if m})


class OutputError(Exception):
    """An output that cannot be written: message printed, exit 1."""


def same_file(a: str, b: str) -> bool:
    """Whether two paths name one file (links followed)."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)


def in_the_way(folder: str) -> str | None:
    """What stands where the output folder `folder` (or a folder above it)
    must be: the path, as the user wrote it, of the first of them that
    exists and is not a folder (a file, a FIFO, a device, a link to none);
    None when nothing does. `notes.txt/gen` names `notes.txt`, not a path
    under it that cannot exist."""
    parts = os.path.normpath(folder).split(os.sep)
    for i in range(1, len(parts) + 1):
        path = os.sep.join(parts[:i]) or os.sep
        if os.path.lexists(path) and not os.path.isdir(path):
            return path
    return None


def not_a_folder(folder: str) -> str | None:
    """Words for `in_the_way(folder)` (`notes.txt is a file, not a folder`),
    or None when nothing is in the way."""
    path = in_the_way(folder)
    return None if path is None else f"{path} is {what_is(path)}, not a folder"


def what_is(path: str) -> str:
    """What stands at `path`, which is no folder, in words: `a file`, `a
    symbolic link to nothing`, `a FIFO`, `a device`, `a socket`."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return "a symbolic link to nothing"
    if stat.S_ISREG(mode):
        return "a file"
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "a device"


def file_head(path: str, n: int) -> bytes | None:
    """The first `n` bytes of the regular file at `path`; None for no file,
    one that cannot be read, or one that is not regular (a FIFO or a device
    is never opened: that would wait for a writer)."""
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):
            return None
        with open(path, "rb") as f:
            return f.read(n)
    except OSError:
        return None


def recording(path: str) -> str | None:
    """What recording `path` is: "a link log" (`fsw monitor --log`, `fsw sim
    --plant`), "a ground station archive" (`fsw ground`: SQLite with the
    archive's application id), or None."""
    head = file_head(path, 100)
    if head is None:
        return None
    if head.startswith(RECORDING_MAGIC):
        return "a link log"
    if len(head) == 100 and head.startswith(b"SQLite format 3\0") and int.from_bytes(head[68:72], "big") == ARCHIVE_ID:
        return "a ground station archive"
    return None


def is_recording(path: str) -> bool:
    return recording(path) is not None


def is_direct(path: str) -> bool:
    """Paths written in place: devices, FIFOs, /dev/stdout and the like."""
    if path.startswith(("/dev/", "/proc/")):
        return True
    try:
        st = os.stat(path)
    except OSError:
        return False
    return not stat.S_ISREG(st.st_mode)


def not_an_input(path: str, inputs=(), what: str = "output") -> None:
    """Refuses an output path that names one of the command's input files:
    OutputError."""
    for i in inputs:
        if i is not None and os.path.exists(path) and same_file(path, i):
            raise OutputError(f"{path}: the {what} would overwrite an input of this command: "
                              "choose another name")


def check(path: str, inputs=(), *, force: bool = False, log: bool = False, ask: bool = False,
          what: str = "output") -> None:
    """Refuses an output path before any work is done: OutputError. A
    recording there is refused, but for a link log that a new one replaces
    with `force` (`log`: the output is itself a link log, `fsw monitor
    --log`, `fsw dump`); an archive never is. `ask`: any other file there
    is refused too, unless `force` (the user's `--force`)."""
    not_an_input(path, inputs, what)
    if os.path.isdir(path):
        raise OutputError(f"cannot write {path}: it is a folder (name a file for the {what})")
    if is_direct(path):
        return
    if os.path.lexists(path):
        kind = recording(path)
        if kind is not None and not (log and kind == "a link log"):
            raise OutputError(f"{path}: {kind} (a recording) is there: it is never overwritten; "
                              "choose another name, or move it away first")
        if (ask or kind is not None) and not force:
            raise OutputError(f"{path} exists: it is replaced only when asked (--force)")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise OutputError(f"cannot write {path}: no such folder {folder}")


class Stream:
    """A text stream whose write errors are OutputErrors naming it (a pipe
    closed by its reader stays a BrokenPipeError: `fsw ... | head` is not a
    failure)."""

    failed = False  # a write or flush failed (its OutputError raised)

    def __init__(self, f, name: str):
        self._f, self.name = f, name

    def __getattr__(self, name):  # isatty, fileno, encoding...: the file's own
        return getattr(self._f, name)

    @property
    def raw(self):
        """The file itself, for writers that take a file (its errors are OSErrors)."""
        return self._f

    def _fail(self, e: OSError):
        if isinstance(e, BrokenPipeError):
            raise e
        self.failed = True
        raise OutputError(f"cannot write {self.name}: {e.strerror or e}") from None

    def write(self, text) -> int:
        try:
            return self._f.write(text)
        except OSError as e:
            self._fail(e)

    def flush(self) -> None:
        try:
            self._f.flush()
        except OSError as e:
            self._fail(e)


def discard_stdout() -> None:
    """Points standard output at /dev/null once it failed (its failure said),
    so that later flushes, the interpreter's last one included, do not fail
    again."""
    try:
        fd = os.open(os.devnull, os.O_WRONLY)
        os.dup2(fd, sys.stdout.fileno())
        os.close(fd)
    except (OSError, ValueError, AttributeError, io.UnsupportedOperation):
        pass


def stdout() -> Stream:
    return Stream(sys.stdout, "standard output")


@contextlib.contextmanager
def output(path: str | None, inputs=(), *, binary: bool = False, newline: str | None = None,
           force: bool = False, ask: bool = False, what: str = "output"):
    """A stream for the command's output: standard output for None or "-",
    else a temporary file beside `path` that replaces it when the block
    ends without an exception (and is removed when it raises)."""
    if path is None or path == "-":
        out = stdout()
        yield out
        out.flush()
        return
    check(path, inputs, force=force, ask=ask, what=what)
    if is_direct(path):
        try:
            f = open(path, "wb" if binary else "w", **({} if binary else {"newline": newline}))
        except OSError as e:
            raise OutputError(f"cannot write {path}: {e.strerror or e}") from None
        s = Stream(f, path)
        try:
            yield s
            s.flush()
        finally:
            with contextlib.suppress(OSError):
                f.close()
        return
    with replacing(path) as tmp:
        try:
            f = open(tmp, "wb" if binary else "w", **({} if binary else {"newline": newline}))
        except OSError as e:
            raise OutputError(f"cannot write {path}: {e.strerror or e}") from None
        s = Stream(f, path)
        done = False
        try:
            yield s
            s.flush()
            try:
                os.fsync(f.fileno())
            except OSError as e:
                raise OutputError(f"cannot write {path}: {e.strerror or e}") from None
            done = True
        finally:
            try:  # after a failed write, closing fails again: the first error is the one said
                f.close()
            except OSError as e:
                if done:
                    raise OutputError(f"cannot write {path}: {e.strerror or e}") from None


def _new_file_mode(tmp: str, target: str) -> None:
    """The mode the output would have had (mkstemp makes 0600): the old
    file's, or a new file's under the umask."""
    try:
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, stat.S_IMODE(os.stat(target).st_mode) if os.path.exists(target) else 0o666 & ~umask)
    except OSError:
        pass


@contextlib.contextmanager
def replacing(path: str):
    """The name of a new temporary file beside `path` (a symbolic link's
    target, if it is one), moved onto `path` when the block ends without an
    exception, removed otherwise."""
    target = os.path.realpath(path) if os.path.islink(path) else path
    folder = os.path.dirname(os.path.abspath(target))
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{os.path.basename(target)}.", suffix=".part", dir=folder)
    except OSError as e:
        raise OutputError(f"cannot write {path}: {e.strerror or e}") from None
    os.close(fd)
    try:
        _new_file_mode(tmp, target)
        yield tmp
        try:
            os.replace(tmp, target)
        except OSError as e:
            raise OutputError(f"cannot write {path}: {e.strerror or e}") from None
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


class Replacement:
    """`replacing` for writers that take a path: `path` is where to write
    (a temporary file beside the output, or the output itself for a device),
    `finish(True)` moves it into place, `finish(False)` removes it."""

    def __init__(self, target: str):
        self.target = target
        if is_direct(target):
            self.path, self._final = target, None
            return
        self._final = os.path.realpath(target) if os.path.islink(target) else target
        try:
            fd, self.path = tempfile.mkstemp(prefix=f".{os.path.basename(self._final)}.", suffix=".part",
                                             dir=os.path.dirname(os.path.abspath(self._final)))
        except OSError as e:
            raise OutputError(f"cannot write {target}: {e.strerror or e}") from None
        os.close(fd)
        _new_file_mode(self.path, self._final)

    def finish(self, ok: bool) -> None:
        if self._final is None:
            return
        try:
            if ok:
                os.replace(self.path, self._final)
            else:
                os.unlink(self.path)
        except OSError as e:
            if ok:
                raise OutputError(f"cannot write {self.target}: {e.strerror or e}") from None
        self._final = None


def write_text(path: str | None, text: str, inputs=(), *, what: str = "output") -> None:
    with output(path, inputs, what=what) as f:
        f.write(text)


stopped_by: int | None = None  # the signal a block of `stopped_by_signals` was stopped by, if any


class Stopped(KeyboardInterrupt):
    """SIGTERM or SIGHUP (`kill`, a closed terminal, a cancelled job) while a
    command writes: it ends as by Ctrl-C, its outputs left consistent."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


@contextlib.contextmanager
def stopped_by_signals():
    """SIGTERM and SIGHUP raise Stopped in the block instead of ending the
    process on the spot (a SIGHUP ignored under nohup stays ignored)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def stop(signum, _frame):
        global stopped_by
        stopped_by = signum
        raise Stopped(signum)

    saved = {}
    for sig in (signal.SIGTERM, signal.SIGHUP):
        if signal.getsignal(sig) not in (signal.SIG_IGN, None):  # None: a handler not set from Python
            saved[sig] = signal.signal(sig, stop)
    try:
        yield
    finally:
        for sig, handler in saved.items():
            signal.signal(sig, handler)


# The line by which a command's output names it, among its first lines
# (`fsw graph`: DOT's first, Mermaid's second; `fsw skeleton`: the first):
# a file that only mentions the command (notes, a README) is not its output.
# The line ends with the digest of the text the command wrote (`stamped`):
# a skeleton is made to be edited in place, and an edited one is the user's.
OWN_HEADS = {
    "graph": re.compile(r"\s*(?://|%%) state machine .+: `fsw graph(?: --format mermaid)?` output"),
    "skeleton": re.compile(r"# State-script skeleton for .+, made by `fsw skeleton`"),
}
_DIGEST = re.compile(rb" \(digest ([0-9a-f]{12})\)$")
_LARGEST_OWN = 64 << 20  # no graph or skeleton is this big: a bigger file is not read whole


def _head_line(lines: list, command: str) -> int | None:
    """The index of the command's head line among the first three of `lines` (bytes)."""
    head = OWN_HEADS[command]
    for i, line in enumerate(lines[:3]):
        if head.match(line.decode("utf-8", "replace")):
            return i
    return None


def _digest(text: bytes) -> str:
    return hashlib.sha256(text).hexdigest()[:12]


def stamped(text: str, command: str) -> str:
    """`text`, the output of `fsw COMMAND` (OWN_HEADS), with the digest of
    that text at the end of its head line: ` (digest 0123456789ab)`."""
    lines = text.split("\n")
    i = _head_line([line.encode() for line in lines], command)
    assert i is not None, "the output names its command (its head line)"
    lines[i] += f" (digest {_digest(text.encode())})"
    return "\n".join(lines)


def _unedited(data: bytes, command: str) -> bool:
    """Whether `data`, a file's whole text, is `fsw COMMAND`'s output as it
    wrote it: its head line's digest is that of the text without it."""
    lines = data.split(b"\n")
    i = _head_line(lines, command)
    m = _DIGEST.search(lines[i]) if i is not None else None
    if m is None:
        return False
    lines[i] = lines[i][:m.start()]
    return _digest(b"\n".join(lines)) == m.group(1).decode()


def _own_head(start: bytes, command: str) -> bool:
    """Whether the first lines of a file (`start`) are those of `fsw COMMAND`'s output."""
    if command not in OWN_HEADS:
        lines = start.decode("utf-8", "replace").splitlines()[:3]
        return any(f"`fsw {command}" in line for line in lines)
    return _head_line(start.split(b"\n"), command) is not None


def only_its_own(path: str | None, command: str, force: bool = False, head: int = 8192,
                 starts: bytes | None = None, what: str = "output") -> None:
    """Refuses (OutputError) to replace a regular, non-empty file at `path`
    whose first lines are not the command's own head line (OWN_HEADS: `fsw
    graph`, `fsw skeleton`; a file that only mentions the command is not
    its output), or that does not begin with `starts` when given (a
    trace's whole first line): a file the user wrote there, a state script beside
    its machine, is not this command's to replace unless asked (`force`).
    Standard output, devices, FIFOs and paths with nothing there pass."""
    if path is None or path == "-" or force or is_direct(path):
        return
    start = file_head(path, max(head, len(starts or b"")))  # None: nothing there to lose (or unreadable)
    if not start:
        return
    if not (start.startswith(starts) if starts is not None else _own_head(start, command)):
        raise OutputError(f"{path} exists and is not an earlier {what} of `fsw {command}` (a file you wrote?): "
                          "it is replaced only when asked (--force)")
    if command in OWN_HEADS and starts is None and not _unedited(file_head(path, _LARGEST_OWN) or b"", command):
        raise OutputError(f"{path} was edited since `fsw {command}` wrote it (its text no longer has the digest "
                          "at the end of its head line): it is replaced only when asked (--force)")
