"""Parameter files: plain TOML that teams keep next to their project, one
top-level key per parameter (`MAIN_ALT = 200`). Read with tomllib (the
standard library's TOML parser); every problem is located at its line and
column. Written with the range, unit and default of each parameter as
comments."""

from __future__ import annotations

import re
import tomllib

from fswkit.autocode.diagnostics import read_input
from fswkit.autocode.params import AppParam, check_value


class ParamFileError(Exception):
    """A located problem in a parameter file (`path:line:col: message`)."""


def _blank_strings(text: str) -> str:
    """`text` with the inside of its multi-line strings blanked (line breaks
    kept), so that a `NAME = ...` written in one is not taken for a key."""
    return re.sub(r'"""[\s\S]*?"""|\'\'\'[\s\S]*?\'\'\'',
                  lambda m: re.sub(r"[^\n]", " ", m.group()), text)


def _where(text: str, key: str) -> tuple[int, int, int]:
    """Line, the key's column and the value's column of the top-level key
    `key` as the file writes it: `key = ...`, a dotted `key.sub = ...` or a
    table header `[key]`, `[[key]]`, `[key.sub]` (the header's column for
    both); (1, 1, 1) when not found."""
    name = rf'(?:"{re.escape(key)}"|\'{re.escape(key)}\'|{re.escape(key)})'
    pats = (re.compile(rf"^([ \t]*){name}[ \t]*=[ \t]*", re.M),
            re.compile(rf"^([ \t]*){name}[ \t]*\.", re.M),
            re.compile(rf"^([ \t]*)\[\[?[ \t]*{name}[ \t]*[.\]]", re.M))
    plain = _blank_strings(text)
    found = [m for m in (p.search(plain) for p in pats) if m is not None]
    if not found:
        return 1, 1, 1
    m = min(found, key=lambda m: m.start())
    line = plain.count("\n", 0, m.start()) + 1
    bol = plain.rfind("\n", 0, m.start()) + 1
    key_col = m.start() + len(m.group(1)) - bol + 1
    return line, key_col, (m.end() - bol + 1 if m.re is pats[0] else key_col)


def read_params(path: str, params: tuple[AppParam, ...]) -> dict[str, object]:
    """{name: checked value} of a parameter file; ParamFileError (located)
    for a file that is not TOML, a table, an unknown name, a value of the
    wrong type or out of range."""
    try:  # a FIFO, a device or a huge file is refused without reading it
        data = read_input(path)
    except OSError as e:
        raise ParamFileError(f"{path}: cannot read: {e.strerror or e}") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise ParamFileError(f"{path}: not UTF-8 text (byte {e.start})") from None
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        msg = str(e)
        m = re.search(r"\(at line (\d+), column (\d+)\)", msg)
        at = f"{m.group(1)}:{m.group(2)}" if m else "1:1"
        what = re.sub(r" \(at .*\)$", "", msg)
        raise ParamFileError(f"{path}:{at}: not valid TOML: {what}") from None
    by_name = {p.name: p for p in params}
    out: dict[str, object] = {}
    problems = []
    for key, value in doc.items():
        line, col, vcol = _where(text, key)
        tables = isinstance(value, list) and value and all(isinstance(v, dict) for v in value)
        if isinstance(value, dict) or tables:
            problems.append(f"{path}:{line}:{col}: `{key}` is {'an array of tables' if tables else 'a table'}: "
                            "a parameter file holds one `NAME = value` per parameter, no tables")
            continue
        p = by_name.get(key)
        if p is None:
            known = ", ".join(by_name) or "none"
            problems.append(f"{path}:{line}:{col}: unknown parameter `{key}` (the project's parameters: {known})")
            continue
        why = _not_a_value(p, value)
        v, why = (None, why) if why is not None else check_value(p, value)
        if why is not None:
            problems.append(f"{path}:{line}:{vcol}: {why}")
            continue
        out[key] = v
    if problems:
        raise ParamFileError("\n".join(problems))
    return out


def _not_a_value(p: AppParam, value) -> str | None:
    """Why a TOML value is none a parameter takes, in the file's words
    (None for a boolean, an integer or a float: check_value judges those).
    A string is not typed text here: a quoted value belongs to a file
    written for something else."""
    import datetime

    if isinstance(value, (bool, int, float)):
        return None
    if isinstance(value, str):
        want = "true or false" if p.type.is_bool else "the number"
        text = value if len(value) <= 40 else value[:40] + "..."
        return f"`{p.name}` is {p.type.name}: {_quoted(text)} is text; give {want} without quotes"
    kind = ("a date and time" if isinstance(value, datetime.datetime) else "a date"
            if isinstance(value, datetime.date) else "a time" if isinstance(value, datetime.time)
            else "an array" if isinstance(value, list) else "a table")
    return f"`{p.name}` is {p.type.name}: {kind} is not a value of it"


def _quoted(text: str) -> str:
    """`text` between double quotes, as TOML writes a basic string."""
    import json

    return json.dumps(text, ensure_ascii=False)


def _toml_value(p: AppParam, v) -> str:
    if p.type.is_bool:
        return "true" if v else "false"
    if p.type.is_float:
        return repr(float(v))  # ranges are finite: no inf or nan here
    return str(int(v))


def params_text(params: tuple[AppParam, ...], values: dict[str, object], title: str) -> str:
    """A parameter file with every parameter's value, commented."""
    lines = [f"# {title}", "# fswkit parameter file (docs/parameters.md): NAME = value", ""]
    for p in params:
        v = values.get(p.name, p.default)
        unit = f" {p.unit}" if p.unit else ""
        lines.append(f"# {p.machine}: {p.type.name}, {p.range_text()}{unit}, default {_toml_value(p, p.default)}, "
                     f"changes in {' '.join(p.when)}")
        lines.append(f"{p.name} = {_toml_value(p, v)}")
    return "\n".join(lines) + "\n"
