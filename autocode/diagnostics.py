"""Located diagnostics: `file:line:col`, the source line as written and a
caret under the reported column. Every front-end stage reports through a
`Diagnostics` collector so that one run reports every independent error."""

from __future__ import annotations

import errno
import os
import re
import stat
from dataclasses import dataclass, field

TAB = 8
SHOWN = 160  # columns of a source line a diagnostic shows (the rest is cut, `...`)

# What one run shows; the rest is counted ("N more errors not shown"), so a
# hostile file (a 40 KB line of `$a`, megabytes of random bytes) costs output
# and memory bounded by these, not by the square of its size.
PER_LINE = 10  # diagnostics of one severity shown for one line
PER_FILE = 100  # diagnostics of one severity shown for one file

# The first words of a diagnostic name the language it is about (spec §8).
SV = "state vector config"
SM = "state machine config"
SS = "state script"
IO = "I/O config"
APP = "application config"


def display_line(text: str) -> str:
    """A source line as shown under a diagnostic: tabs expanded, other
    control characters replaced so the caret stays aligned."""
    text = text.expandtabs(TAB)
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else "?" for c in text)


def clip(shown: str, at: int) -> tuple[str, int]:
    """A displayed line longer than `SHOWN` columns cut to the `SHOWN`
    columns around column index `at`, `...` marking each cut; (text, the
    caret's index in it). A diagnostic about a 40 KB line shows 160 columns,
    not 40 KB."""
    if len(shown) <= SHOWN:
        return shown, at
    start = min(max(at - SHOWN // 2, 0), len(shown) - SHOWN)
    end = start + SHOWN
    head = "..." if start > 0 else ""
    tail = "..." if end < len(shown) else ""
    return head + shown[start:end] + tail, at - start + len(head)


_QUOTED = re.compile(r"`([^`]*)`")
QUOTED = 60  # characters of a name or token a message quotes (a 40 KB name is cut)


def _clip_quoted(m: re.Match) -> str:
    text = m.group(1)
    if len(text) <= QUOTED:
        return m.group()
    return f"`{text[:QUOTED // 2]}...{text[-QUOTED // 2:]}`"


def ranges(numbers, sep: str = ", ") -> str:
    """Whole numbers as runs, sorted: 1 2 3 5 -> "1-3, 5" (`sep` between runs)."""
    ns = sorted(numbers)
    out, start = [], None
    for i, n in enumerate(ns):
        if start is None:
            start = n
        if i + 1 == len(ns) or ns[i + 1] != n + 1:
            out.append(str(start) if start == n else f"{start}-{n}")
            start = None
    return sep.join(out)


def visual_col(text: str, index: int) -> int:
    """1-based column of character `index` of `text` once tabs are expanded."""
    if "\t" not in text:
        return index + 1
    return len(text[:index].expandtabs(TAB)) + 1


_TAB_OR_RESET = re.compile(r"[\t\n\r]")


class Columns:
    """`visual_col` of one line at increasing indices, in time linear in the
    line (`visual_col` for every token of a long line with tabs was
    quadratic: a 100 KB line took seconds). Like `str.expandtabs`, a CR
    counts one column and restarts the tab stops. The line's tabs and line
    ends are found once: a call that passes none is a few additions."""

    __slots__ = ("stops", "k", "index", "length", "pos")

    def __init__(self, text: str):
        # (index, is a tab) of every tab, CR or LF, in order
        self.stops = [(m.start(), m.group() == "\t") for m in _TAB_OR_RESET.finditer(text)]
        self.k = 0  # stops[k] is the first at or after `index`
        self.index = self.length = self.pos = 0  # expanded length and tab-stop position at `index`

    def __call__(self, index: int) -> int:
        if index < self.index:
            self.k = self.index = self.length = self.pos = 0
        i, length, pos, k = self.index, self.length, self.pos, self.k
        stops = self.stops
        n = len(stops)
        while k < n and stops[k][0] < index:
            at, tab = stops[k]
            d = at - i
            length, pos = length + d, pos + d
            if tab:
                step = TAB - pos % TAB
                length, pos = length + step, pos + step
            else:
                length, pos = length + 1, 0
            i = at + 1
            k += 1
        d = index - i
        self.index, self.length, self.pos, self.k = index, length + d, pos + d, k
        return self.length + 1


@dataclass(frozen=True)
class Source:
    """One config file's text, split into lines for diagnostics."""

    path: str  # as the user named it; diagnostics show it this way
    text: str
    lines: tuple[str, ...]

    @classmethod
    def from_text(cls, path: str, text: str) -> "Source":
        lines = text.split("\n")
        if "\r" in text:  # a CR before a line's LF is no part of the line
            lines = [l[:-1] if l.endswith("\r") else l for l in lines]
        return cls(path, text, tuple(lines))

    def line(self, n: int) -> str:
        return self.lines[n - 1] if 1 <= n <= len(self.lines) else ""


@dataclass(frozen=True)
class Diagnostic:
    lang: str  # one of SV, SM, SS, IO, APP
    severity: str  # "error" or "warning"
    path: str
    line: int
    col: int
    message: str
    source_line: str
    title: str | None = None  # replaces "<lang> <severity>" (e.g. "assertion failure")

    def render(self) -> str:
        head = self.title or f"{self.lang} {self.severity}"
        shown, at = clip(display_line(self.source_line), max(self.col, 1) - 1)
        caret = " " * at + "^"
        message = _QUOTED.sub(_clip_quoted, self.message)
        return f"{head} @ {self.path}:{self.line}:{self.col}:\n  | {shown}\n  | {caret} {message}"

    @property
    def sort_key(self):
        return (self.path, self.line, self.col, self.message)


@dataclass
class Diagnostics:
    """Collects the diagnostics of one run, in the order they were found.
    At most `PER_LINE` per line and `PER_FILE` per file of each severity are
    kept; the others are only counted (`hidden`). Code that asks "did this
    add an error?" compares `error_count`, which counts both."""

    items: list[Diagnostic] = field(default_factory=list)

    def __post_init__(self):
        self._seen: set[Diagnostic] = set()
        self._lexical: set[tuple[str, int]] = set()
        self._per_line: dict[tuple[str, int, str], int] = {}
        self._per_file: dict[tuple[str, str], int] = {}
        self.hidden: dict[tuple[str, str], int] = {}  # (path, severity) -> not kept
        # Each diagnostic not kept, by its hash (what `_seen` is for the kept
        # ones): a file reported twice (a machine, then beside its script) is
        # counted once. An int a diagnostic: memory linear in the input.
        self._hidden_keys: dict[int, tuple[str, str]] = {}
        self._seen_keys: set[int] = set()
        self.error_count = self.warning_count = 0
        for d in self.items:  # given at construction: kept as they are
            self._seen.add(d)
            self._seen_keys.add(hash(d))
            self._count(d.severity, 1)

    def _count(self, severity: str, n: int) -> None:
        if severity == "error":
            self.error_count += n
        else:
            self.warning_count += n

    def _keep(self, d: Diagnostic) -> None:
        key = hash(d)  # once: a kept diagnostic's hash is in _seen_keys too
        if key in self._hidden_keys or (key in self._seen_keys and d in self._seen):
            return
        file_key, line_key = (d.path, d.severity), (d.path, d.line, d.severity)
        if self._per_file.get(file_key, 0) >= PER_FILE or self._per_line.get(line_key, 0) >= PER_LINE:
            self._hide(key, file_key)
            return
        self._count(d.severity, 1)
        self._per_file[file_key] = self._per_file.get(file_key, 0) + 1
        self._per_line[line_key] = self._per_line.get(line_key, 0) + 1
        self._seen.add(d)
        self._seen_keys.add(key)
        self.items.append(d)

    def _hide(self, key: int, file_key: tuple[str, str]) -> None:
        self._hidden_keys[key] = file_key
        self.hidden[file_key] = self.hidden.get(file_key, 0) + 1
        self._count(file_key[1], 1)

    def add(self, src: Source, lang: str, line: int, col: int, message: str,
            severity: str = "error") -> None:
        if (src.path, line) in self._lexical:
            return  # the line's lexical error said it: what follows is its echo
        self._keep(Diagnostic(lang, severity, src.path, line, col, message, src.line(line)))

    def lexical_error(self, src: Source, lang: str, line: int, col: int, message: str) -> None:
        """A lexical error: reported, and no later diagnostic about the same
        line is (the tokens it left are not what the user meant)."""
        self._keep(Diagnostic(lang, "error", src.path, line, col, message, src.line(line)))
        self._lexical.add((src.path, line))

    def error(self, src: Source, lang: str, line: int, col: int, message: str) -> None:
        self.add(src, lang, line, col, message, "error")

    def warning(self, src: Source, lang: str, line: int, col: int, message: str) -> None:
        self.add(src, lang, line, col, message, "warning")

    def extend(self, other: "Diagnostics") -> None:
        for d in other.items:
            self._keep(d)
        for key, file_key in other._hidden_keys.items():
            if key not in self._hidden_keys and key not in self._seen_keys:
                self._hide(key, file_key)

    @property
    def errors(self) -> list[Diagnostic]:
        """The errors kept (`error_count` counts the hidden ones too)."""
        return [d for d in self.items if d.severity == "error"]

    @property
    def warnings(self) -> list[Diagnostic]:
        return [d for d in self.items if d.severity == "warning"]

    def in_order(self) -> list[Diagnostic]:
        """Files in the order they were first reported on; within a file, by
        line and column (stable, so one spot's diagnostics keep their order)."""
        first: dict[str, int] = {}
        for d in self.items:
            first.setdefault(d.path, len(first))
        return sorted(self.items, key=lambda d: (first[d.path], d.line, d.col))

    def render(self) -> str:
        out: list[str] = []
        path = None
        for d in self.in_order():
            if d.path != path:
                if path is not None:
                    out += self._not_shown(path)
                path = d.path
            out.append(d.render())
        if path is not None:
            out += self._not_shown(path)
        return "\n".join(out)

    def _not_shown(self, path: str) -> list[str]:
        parts = [f"{n} more {severity}{'' if n == 1 else 's'}"
                 for severity in ("error", "warning") if (n := self.hidden.get((path, severity)))]
        if not parts:
            return []
        return [f"{path}: {' and '.join(parts)} not shown (at most {PER_LINE} a line "
                f"and {PER_FILE} a file of each are)"]


class ConfigError(Exception):
    """Raised by loaders when a config has errors; carries every diagnostic."""

    def __init__(self, diagnostics: Diagnostics):
        super().__init__(diagnostics.render())
        self.diagnostics = diagnostics


# The largest config, board, state script or plant file the tools read:
# 1 MiB, some 25,000 lines, far beyond any vehicle's (the rocket's largest
# file is 5 KB), and a bound on what a hostile file costs the front end.
MAX_INPUT = 1 << 20


def toml_error_at(e: Exception, text: str) -> str:
    """A TOML parser's error (tomllib.TOMLDecodeError) as `LINE:COL: what`,
    or `LINE: what` when it is at the end of the document, to follow a
    file's path."""
    msg = str(e)
    m = re.search(r"\(at line (\d+), column (\d+)\)", msg)
    if m:
        return f"{m.group(1)}:{m.group(2)}: {msg[:m.start()].strip()}"
    m = re.search(r"\(at end of document\)", msg)
    return f"{text.count(chr(10)) + 1}: {msg[:m.start()].strip() if m else msg}"


class InputError(OSError):
    """A user's file that is not read: not a regular file, or too large.
    An OSError, so every reader's `except OSError` reports it."""

    def __init__(self, message: str):
        super().__init__(message)
        self.strerror = message

    def __str__(self) -> str:
        return self.strerror


def _open_regular(path: str):
    """`path` opened for reading, refused (InputError) unless a regular
    file. Opened non-blocking, so a FIFO with no writer does not hang."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except OSError as e:
        if e.errno == errno.ENXIO and stat.S_ISSOCK(os.stat(path).st_mode):  # a socket cannot be opened
            raise InputError("not a regular file (a socket): the tools read regular files only") from None
        raise
    f = os.fdopen(fd, "rb", buffering=0)
    mode = os.fstat(fd).st_mode
    if not stat.S_ISREG(mode):
        f.close()
        if stat.S_ISDIR(mode):
            raise InputError("is a folder, not a file")
        kind = "a FIFO" if stat.S_ISFIFO(mode) else "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) \
            else "a socket" if stat.S_ISSOCK(mode) else "not a regular file"
        raise InputError(f"not a regular file ({kind}): the tools read regular files only")
    return f


def read_input(path: str, limit: int = MAX_INPUT) -> bytes:
    """The bytes of a file the user named (config, board, state script,
    plant parameters; a recorded log with a larger `limit`): the one place
    the tools read them. A FIFO, device or folder is refused without
    reading, and so is a file over `limit` bytes (read at most `limit` + 1
    bytes, so a file growing meanwhile cannot exhaust memory). OSError
    (InputError for those two) on failure."""
    with _open_regular(path) as f:
        size = os.fstat(f.fileno()).st_size
        if size > limit:
            raise InputError(f"file too large: {size:,} bytes, over the {limit:,} the tools read from one file")
        chunks, size = [], 0
        while size <= limit:
            chunk = f.read(limit + 1 - size)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    if size > limit:
        raise InputError(f"file too large: over the {limit:,} bytes the tools read from one file")
    return b"".join(chunks)


def read_head(path: str, n: int) -> bytes:
    """The first `n` bytes (or fewer) of a file the user named, such as a
    firmware ELF whose header is checked; refused as `read_input` refuses."""
    with _open_regular(path) as f:
        return f.read(n)


def read_source(path: str, diags: Diagnostics, lang: str) -> Source | None:
    """Reads a config file; an unreadable file is a located error at 1:1."""
    try:
        data = read_input(path)
    except OSError as e:
        src = Source.from_text(path, "")
        diags.error(src, lang, 1, 1, f"cannot read file: {e.strerror or e}")
        return None
    return Source.from_text(path, decode(data))


def decode(data: bytes) -> str:
    """A config file's text: UTF-8, a leading byte order mark dropped. Bytes
    that are not UTF-8 become U+DC80..U+DCFF, which the lexer reports by
    value (and `display_line` shows as `?`)."""
    return data.decode("utf-8-sig", errors="surrogateescape")
