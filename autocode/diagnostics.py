"""Located diagnostics: `file:line:col`, the source line as written and a
caret under the reported column. Every front-end stage reports through a
`Diagnostics` collector so that one run reports every independent error."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

TAB = 8

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
    counts one column and restarts the tab stops."""

    __slots__ = ("text", "index", "length", "pos")

    def __init__(self, text: str):
        self.text = text
        self.index = self.length = self.pos = 0  # expanded length and tab-stop position at `index`

    def __call__(self, index: int) -> int:
        if index < self.index:
            self.index = self.length = self.pos = 0
        i, length, pos = self.index, self.length, self.pos
        for m in _TAB_OR_RESET.finditer(self.text, i, index):
            k = m.start() - i
            length, pos = length + k, pos + k
            if m.group() == "\t":
                step = TAB - pos % TAB
                length, pos = length + step, pos + step
            else:
                length, pos = length + 1, 0
            i = m.end()
        k = index - i
        self.index, self.length, self.pos = index, length + k, pos + k
        return self.length + 1


@dataclass(frozen=True)
class Source:
    """One config file's text, split into lines for diagnostics."""

    path: str  # as the user named it; diagnostics show it this way
    text: str
    lines: tuple[str, ...]

    @classmethod
    def from_text(cls, path: str, text: str) -> "Source":
        lines = tuple(l[:-1] if l.endswith("\r") else l for l in text.split("\n"))
        return cls(path, text, lines)

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
        shown = display_line(self.source_line)
        caret = " " * (max(self.col, 1) - 1) + "^"
        return f"{head} @ {self.path}:{self.line}:{self.col}:\n  | {shown}\n  | {caret} {self.message}"

    @property
    def sort_key(self):
        return (self.path, self.line, self.col, self.message)


@dataclass
class Diagnostics:
    """Collects the diagnostics of one run, in the order they were found."""

    items: list[Diagnostic] = field(default_factory=list)

    def add(self, src: Source, lang: str, line: int, col: int, message: str,
            severity: str = "error") -> None:
        if (src.path, line) in self._lexical:
            return  # the line's lexical error said it: what follows is its echo
        d = Diagnostic(lang, severity, src.path, line, col, message, src.line(line))
        if d not in self._seen:
            self._seen.add(d)
            self.items.append(d)

    def __post_init__(self):
        self._seen: set[Diagnostic] = set()
        self._lexical: set[tuple[str, int]] = set()

    def lexical_error(self, src: Source, lang: str, line: int, col: int, message: str) -> None:
        """A lexical error: reported, and no later diagnostic about the same
        line is (the tokens it left are not what the user meant)."""
        d = Diagnostic(lang, "error", src.path, line, col, message, src.line(line))
        if d not in self._seen:
            self._seen.add(d)
            self.items.append(d)
        self._lexical.add((src.path, line))

    def error(self, src: Source, lang: str, line: int, col: int, message: str) -> None:
        self.add(src, lang, line, col, message, "error")

    def warning(self, src: Source, lang: str, line: int, col: int, message: str) -> None:
        self.add(src, lang, line, col, message, "warning")

    def extend(self, other: "Diagnostics") -> None:
        for d in other.items:
            if d not in self._seen:
                self._seen.add(d)
                self.items.append(d)

    @property
    def errors(self) -> list[Diagnostic]:
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
        return "\n".join(d.render() for d in self.in_order())


class ConfigError(Exception):
    """Raised by loaders when a config has errors; carries every diagnostic."""

    def __init__(self, diagnostics: Diagnostics):
        super().__init__(diagnostics.render())
        self.diagnostics = diagnostics


def read_source(path: str, diags: Diagnostics, lang: str) -> Source | None:
    """Reads a config file; an unreadable file is a located error at 1:1."""
    try:
        with open(path, "rb") as f:
            data = f.read()
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
