"""The syntax trees of the application languages and their parsers: the
`.app` application config (spec §7) and the `.aio`/`.dio` channel tables
(spec §6). As in syntax.py, nothing is resolved: names are still text. The
leaves are the lexer's tokens (kind, text, line, col), so the checker
(appcheck.py, iotables.py) reports every problem where the user wrote it.

The parsers report only what stops a file from having rows at all: lexical
errors and malformed or unknown section headers. A row whose tail is
malformed (`rate=` without a value, a stray token after `scale=2`) keeps
what was read before it and records the rest as a `Problem`, which the
checker reports when it reaches that row: a row refused for an earlier
reason (a reused task name) says only that."""

from __future__ import annotations

import os
import re
from dataclasses import dataclass

from .diagnostics import APP, IO, Columns, Diagnostics, Source
from .lexer import ID, NUM, OP, Tok, lex, lex_line
from .parser import show, split_sections


@dataclass(frozen=True)
class Problem:
    """A malformed piece of a row, reported when the row is checked."""
    tok: Tok
    message: str


# ---- the application config (.app) ----------------------------------------------

SECTIONS = ("application", "configs", "time", "tasks", "telemetry", "uplink", "budget", "log", "pyro", "reload")
# Sections whose presence turns a feature on, and what they need: written
# empty, they would otherwise read as absent, and the feature silently off.
NEEDS_ROWS = {
    "log": "`store`, `machine`, `trigger` and an `element` (docs/recorder.md); remove the section for an "
           "application without a flight recorder",
    "reload": "`machine NAME`, the machine the ground may replace (docs/reload.md); remove the section for an "
              "application without one",
}


@dataclass(frozen=True)
class Option:
    """`key=value` after a task or a stream."""
    key: Tok
    value: Tok  # an ID or a NUM


@dataclass(frozen=True)
class Options:
    items: tuple[Option, ...]  # as written: a key given twice is here twice
    stray: Problem | None  # the token that ended them, when it is not `key=value`


@dataclass(frozen=True)
class Setting:
    """`key value ...`: a line of [application], [time] or [budget]."""
    key: Tok
    values: tuple[Tok, ...]


@dataclass(frozen=True)
class ConfigFile:
    """`kind file` in [configs]: `state_vector`, `machine` or `io`."""
    kind: Tok
    file: Tok | None  # the file name as written (a PATH token); None when the line has none
    path: str  # the file name as written (to a comment or the end of the line), beside the .app


@dataclass(frozen=True)
class TaskRow:
    """`name kind [machine] key=value...` in [tasks]."""
    name: Tok
    kind: Tok | None  # what the task runs
    machine: Tok | None  # for `machine`: the machine's name, when one follows
    options: Options


@dataclass(frozen=True)
class StreamRow:
    """`Region rate=HZ` in [telemetry]."""
    region: Tok
    options: Options


@dataclass(frozen=True)
class WritableRow:
    """An element the ground may write, in [uplink]."""
    element: Tok
    extra: Tok | None  # a second token on the line


@dataclass(frozen=True)
class PyroSetting:
    """`key=value` or `key=a,b,c` after a pyro channel's element; a `-`
    may stand before a number."""
    key: Tok
    values: tuple[Tok, ...]  # IDs or NUMs, as written
    negative: bool = False  # a `-` before the first value


@dataclass(frozen=True)
class PyroRow:
    """`element key=value...` in [pyro] (pyrocheck.py)."""
    element: Tok
    settings: tuple[PyroSetting, ...]  # as written: a key given twice is here twice
    stray: Problem | None  # the token that ended them, when it is not `key=value`


@dataclass(frozen=True)
class AppFile:
    """One .app file: the rows of each known section (empty when the
    section is absent; of a duplicate section, the first)."""
    src: Source
    application: tuple[Setting, ...] = ()
    configs: tuple[ConfigFile, ...] = ()
    time: tuple[Setting, ...] = ()
    tasks: tuple[TaskRow, ...] = ()
    telemetry: tuple[StreamRow, ...] = ()
    uplink: tuple[WritableRow, ...] = ()
    budget: tuple[Setting, ...] = ()
    log: tuple[Setting, ...] = ()
    pyro: tuple[PyroRow, ...] = ()
    reload: tuple[Setting, ...] = ()
    sections: frozenset = frozenset()  # the known sections written, empty or not


def parse_app(src: Source, diags: Diagnostics) -> AppFile:
    """The tree of an .app file; lexical errors, lines before the first
    section and unknown, malformed or duplicate sections are reported."""
    pre, sections = split_sections(src, _lex_app(src, diags), diags, APP)
    for toks in pre:
        diags.error(src, APP, toks[0].line, toks[0].col, f"unexpected {show(toks[0])} before the first section")
    body: dict[str, list[list[Tok]]] = {}
    for header, rows in sections:
        if header.name == "<malformed>":
            continue
        if header.name not in SECTIONS:
            diags.error(src, APP, header.line, header.col + 1, f"unknown section `[{header.name}]`: expected one of "
                        + ", ".join(f"[{k}]" for k in SECTIONS))
        elif header.name in body:
            diags.error(src, APP, header.line, header.col + 1, f"duplicate section `[{header.name}]`")
        else:
            body[header.name] = rows
            if not rows and header.name in NEEDS_ROWS:  # else it would read as no section at all
                diags.error(src, APP, header.line, header.col + 1,
                            f"[{header.name}] is empty: it needs {NEEDS_ROWS[header.name]}")
    folder = os.path.dirname(src.path)
    rows = lambda name, row: tuple(row(toks) for toks in body.get(name, ()))  # noqa: E731
    return AppFile(
        src,
        application=rows("application", _setting),
        configs=rows("configs", lambda toks: _config_file(src, folder, toks)),
        time=rows("time", _setting),
        tasks=rows("tasks", _task_row),
        telemetry=rows("telemetry", lambda toks: StreamRow(toks[0], parse_options(toks, 1))),
        uplink=rows("uplink", lambda toks: WritableRow(toks[0], toks[1] if len(toks) > 1 else None)),
        budget=rows("budget", _setting),
        log=rows("log", _setting),
        pyro=rows("pyro", _pyro_row),
        reload=rows("reload", _setting),
        sections=frozenset(body),
    )


PATH = "path"  # the kind of a [configs] row's file name: its text as written
_HEADER = re.compile(r"\s*\[\s*([A-Za-z_][A-Za-z0-9_]*)\s*\]")
_KIND = re.compile(r"\s*[A-Za-z_][A-Za-z0-9_]*")


def _lex_app(src: Source, diags: Diagnostics) -> list[list[Tok]]:
    """The tokens of an .app file, line by line. In [configs] a row is a
    kind and a file name: the name is not lexed but kept as one PATH token,
    the text as written to a comment or the end of the line, so `./`, `../`,
    spaces and any alphabet reach the file system as the user wrote them."""
    out: list[list[Tok]] = []
    section = None
    for i, text in enumerate(src.lines):
        n = i + 1
        header = _HEADER.match(text)
        if header is not None:
            section = header.group(1)
        kind = _KIND.match(text) if section == "configs" and header is None else None
        if kind is None:
            out.append(lex_line(src, n, text, diags, APP))
            continue
        toks = lex_line(src, n, text[:kind.end()], diags, APP)
        rest = text[kind.end():].split("#", 1)[0]
        name = rest.strip()
        if name:
            pos = kind.end() + (len(rest) - len(rest.lstrip()))
            col = Columns(text)(pos) if "\t" in text else pos + 1
            toks.append(Tok(PATH, name, n, col))
        out.append(toks)
    return out


def _setting(toks: list[Tok]) -> Setting:
    return Setting(toks[0], tuple(toks[1:]))


def _config_file(src: Source, folder: str, toks: list[Tok]) -> ConfigFile:
    if len(toks) < 2:
        return ConfigFile(toks[0], None, "")
    return ConfigFile(toks[0], toks[1], os.path.join(folder, toks[1].text))


def _task_row(toks: list[Tok]) -> TaskRow:
    kind = toks[1] if len(toks) > 1 else None
    machine = None
    start = 2
    if kind is not None and kind.text == "machine" and len(toks) > 2 and toks[2].kind == ID \
            and not (len(toks) > 3 and toks[3].text == "="):
        machine, start = toks[2], 3
    return TaskRow(toks[0], kind, machine, parse_options(toks, start))


def _follows(a: Tok, b: Tok) -> bool:
    """`b` stands right after `a` on its line, no blank between: a setting's
    value after its `=` (`arm=  continuity=x` is `arm=` with no value, not
    `arm=continuity`)."""
    return b.line == a.line and b.col == a.col + len(a.text)


def _no_value(key: Tok) -> str:
    return f"`{key.text}=` has no value: write it right after the `=` (`{key.text}=VALUE`, no blank between)"


def _pyro_row(toks: list[Tok]) -> PyroRow:
    """`element key=value key=a,b ...`: values are names or numbers, a list
    is separated by commas, a number may be negative."""
    settings: list[PyroSetting] = []
    i, n = 1, len(toks)
    while i < n:
        t = toks[i]
        if not (t.kind == ID and i + 1 < n and toks[i + 1].kind == OP and toks[i + 1].text == "="):
            return PyroRow(toks[0], tuple(settings), Problem(t, f"unexpected {show(t)}: expected `key=value`"))
        j = i + 2
        if j >= n or not _follows(toks[i + 1], toks[j]):
            return PyroRow(toks[0], tuple(settings), Problem(t, _no_value(t)))
        negative = j < n and toks[j].kind == OP and toks[j].text == "-" and j + 1 < n and toks[j + 1].kind == NUM
        j += negative
        values: list[Tok] = []
        while True:
            if j >= n or toks[j].kind not in (ID, NUM):
                at = toks[j] if j < n else toks[j - 1]
                return PyroRow(toks[0], tuple(settings),
                               Problem(at, f"expected a value after `{toks[j - 1].text}`"))
            values.append(toks[j])
            j += 1
            if j < n and toks[j].kind == OP and toks[j].text == ",":
                j += 1
                continue
            break
        settings.append(PyroSetting(t, tuple(values), bool(negative)))
        i = j
    return PyroRow(toks[0], tuple(settings), None)


def parse_options(toks: list[Tok], start: int) -> Options:
    """`key=value` pairs from toks[start:], up to the first token that does
    not begin one."""
    items: list[Option] = []
    i = start
    while i < len(toks):
        t = toks[i]
        if (t.kind == ID and i + 1 < len(toks) and toks[i + 1].kind == OP and toks[i + 1].text == "="
                and (i + 2 >= len(toks) or not _follows(toks[i + 1], toks[i + 2]))):
            return Options(tuple(items), Problem(t, _no_value(t)))
        if not (t.kind == ID and i + 2 < len(toks) and toks[i + 1].kind == OP and toks[i + 1].text == "="
                and toks[i + 2].kind in (ID, NUM)):
            return Options(tuple(items), Problem(t, f"unexpected {show(t)}: expected `key=value`"))
        items.append(Option(t, toks[i + 2]))
        i += 3
    return Options(tuple(items), None)


def col_index(line: str, col: int) -> int:
    """The index in `line` of visual column `col`."""
    if "\t" not in line:
        return col - 1
    for i in range(len(line) + 1):
        if len(line[:i].expandtabs(8)) + 1 >= col:
            return i
    return len(line)


# ---- channel tables (.aio, .dio) ------------------------------------------------

CALIBRATIONS = ("scale", "offset")


@dataclass(frozen=True)
class Calibration:
    """`scale=K` or `offset=B` after an analog input."""
    key: Tok
    negative: bool  # a `-` before the number
    number: Tok | None  # None: `problem` says what stands there instead
    problem: Problem | None = None


@dataclass(frozen=True)
class ChannelRow:
    """`direction pin element [scale=K] [offset=B]`."""
    direction: Tok  # `i` or `o`
    pin: Tok  # an ID (`A0`) or a NUM (`4`)
    element: Tok
    calibrations: tuple[Calibration, ...]  # as written, up to the first malformed one
    stray: Problem | None  # a token after them that is no calibration


@dataclass(frozen=True)
class Table:
    src: Source
    analog: bool  # .aio; .dio is digital
    rows: tuple[ChannelRow | Problem, ...]  # a Problem: a line without its direction, pin and element


def parse_table(src: Source, analog: bool, diags: Diagnostics) -> Table:
    """The tree of a channel table; lexical errors are reported."""
    return Table(src, analog, tuple(_channel_row(toks) for toks in lex(src, diags, IO) if toks))


def _channel_row(toks: list[Tok]) -> ChannelRow | Problem:
    d = toks[0]
    if d.kind != ID or d.text not in ("i", "o"):
        return Problem(d, f"expected a direction `i` or `o`, found `{d.text}`")
    if len(toks) < 2 or toks[1].kind not in (ID, NUM):
        return Problem(toks[1] if len(toks) > 1 else d, "expected a pin after the direction")
    if len(toks) < 3 or toks[2].kind != ID:
        return Problem(toks[2] if len(toks) > 2 else toks[1], "expected an element after the pin")
    calibrations: list[Calibration] = []
    i = 3
    while i < len(toks):
        t = toks[i]
        if not (t.kind == ID and t.text in CALIBRATIONS and i + 1 < len(toks)
                and toks[i + 1].kind == OP and toks[i + 1].text == "="):
            return ChannelRow(d, toks[1], toks[2], tuple(calibrations),
                              Problem(t, f"unexpected `{t.text}`: expected `scale=K` or `offset=B`"))
        cal, i = _calibration(toks, i)
        calibrations.append(cal)
        if cal.problem is not None:
            break
    return ChannelRow(d, toks[1], toks[2], tuple(calibrations), None)


def _calibration(toks: list[Tok], i: int) -> tuple[Calibration, int]:
    """The calibration whose key is toks[i] (and `=` toks[i + 1]); returns
    it and the index after it."""
    key, j = toks[i], i + 2
    negative = j < len(toks) and toks[j].kind == OP and toks[j].text == "-"
    if negative:
        j += 1
    if j >= len(toks) or toks[j].kind != NUM:
        at = toks[j] if j < len(toks) else toks[-1]
        return Calibration(key, negative, None, Problem(at, f"expected a number after `{key.text}=`")), len(toks)
    return Calibration(key, negative, toks[j]), j + 1
