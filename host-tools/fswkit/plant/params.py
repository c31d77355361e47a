"""Plant parameter files (`plant.toml` beside a project): TOML read with
tomllib, then checked strictly against a schema — unknown tables and keys,
wrong types and out-of-range values are errors located at their line,
`plant.toml:12: [motor] propellant_kg: expected a number, found "lots"`,
every error of the file reported at once.

tomllib keeps no positions, so `locate` maps each `[table]` header and
`key =` line of the text to its line number.

`extends = "../hpr/plant.toml"` at a file's top starts it from another
parameters file (which may extend another in turn): the extending file's
tables override the base's key by key, and keys that are alternatives of
the one it sets (a table's `alternatives`: `part` instead of an analog
`channel` and its transfer function) are dropped from the base's. Every
message names the file and line that gave the key.
"""

from __future__ import annotations

import math
import os
import re
import tomllib
from dataclasses import dataclass, field

from fswkit.autocode.diagnostics import read_input, toml_error_at


class ParamsError(Exception):
    """One or more located errors in a parameters file."""

    def __init__(self, errors: list[str]):
        super().__init__("\n".join(errors))
        self.errors = errors


@dataclass(frozen=True)
class Field:
    """One key of a table: its kind (`float`, `int`, `str`, `bool`, `pin`,
    `curve`: a list of [x, y] pairs, `names`: a list of strings, `range`:
    [low, high] with both ends within lo..hi), an
    inclusive range for numbers, a default (None: required), and what it is."""

    kind: str
    doc: str
    default: object = None
    lo: float | None = None
    hi: float | None = None
    above: float | None = None  # exclusive lower bound
    required: bool = True
    x_hi: float | None = None  # curves: the largest first value (seconds); `hi` bounds the second

    def __post_init__(self):
        if self.default is not None:
            object.__setattr__(self, "required", False)


@dataclass(frozen=True)
class Table:
    doc: str
    fields: dict[str, Field] = field(default_factory=dict)
    # groups of keys that are alternatives of each other: a file that extends
    # another and sets a key of one group drops the base's keys of the others
    alternatives: tuple[tuple[str, ...], ...] = ()
    # (key, the key it belongs to): dropped with it by an alternative, unless
    # the extending file sets it too (a thrust curve's propellant mass)
    follows: tuple[tuple[str, str], ...] = ()


class Line(int):
    """A line number of another file than the one loaded (a key inherited
    through `extends`): messages name that file."""

    path: str

    def __new__(cls, n: int, path: str):
        line = super().__new__(cls, n)
        line.path = path
        return line


def _at(path: str, line) -> str:
    return f"{getattr(line, 'path', path)}:{int(line)}"


Schema = dict  # table name ("" for the top level) -> Table
_STRINGS = re.compile(r"\"(\\.|[^\"\\])*\"|'[^']*'")


def locate(text: str) -> dict[tuple[str, str], int]:
    """(table, key) -> line of `key =` in that table, and (table, "") -> the
    line of the table's header. Keys before any header are in table "". A
    dotted key (`vehicle.mass_sd = 0.1`) is located as the key it sets and
    each table it names on the way; an array of tables (`[[name]]`) as the
    key `name` of the table it is in."""
    where: dict[tuple[str, str], int] = {("", ""): 1}
    table = ""
    part = r"(?:[A-Za-z0-9_\-]+|\"[^\"]*\")"
    header = re.compile(r"\s*(\[\[?)\s*(" + part + r"(?:\s*\.\s*" + part + r")*)\s*\]\]?\s*(#.*)?$")
    key = re.compile(r"\s*(" + part + r"(?:\s*\.\s*" + part + r")*)\s*=")
    depth = 0  # brackets still open in a multi-line value

    def parts(dotted: str) -> list[str]:
        return [p.strip('"') for p in re.findall(part, dotted)]

    for n, line in enumerate(text.splitlines(), 1):
        code = _STRINGS.sub('""', line).split("#", 1)[0]
        if depth == 0:
            m = header.match(line)
            if m:
                names = parts(m.group(2))
                if m.group(1) == "[[":  # an array of tables: located as the key that holds it
                    where.setdefault((".".join(names[:-1]), names[-1]), n)
                    table = "[[" + ".".join(names)  # its keys are no table's the schema knows
                else:
                    table = ".".join(names)
                    where.setdefault((table, ""), n)
                continue
            m = key.match(line)
            if m:
                names = parts(m.group(1))
                for i, name in enumerate(names):
                    at = ".".join([table] * bool(table) + names[:i])
                    where.setdefault((at, name), n)
                    if i:
                        where.setdefault((at, ""), n)
                code = code.split("=", 1)[1]
            else:
                continue
        depth = max(0, depth + code.count("[") - code.count("]"))
    return where


def _kind_of(v) -> str:
    if isinstance(v, bool):
        return "a boolean"
    if isinstance(v, (int, float)):
        return "a number"
    if isinstance(v, str):
        return "a string"
    if isinstance(v, list):
        return "a list"
    if isinstance(v, dict):
        return "a table"
    return type(v).__name__


def _show(v) -> str:
    return f'"{v}"' if isinstance(v, str) else str(v).lower() if isinstance(v, bool) else repr(v)


def _number(v, f: Field, name: str) -> tuple[object, str | None]:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return None, f"{name}: expected a number, found {_kind_of(v)} {_show(v)}"
    if f.kind == "int" and not isinstance(v, int):
        return None, f"{name}: expected a whole number, found {v!r}"
    x = float(v) if f.kind == "float" else int(v)
    if isinstance(x, float) and not math.isfinite(x):
        return None, f"{name}: expected a finite number, found {v}"
    if f.lo is not None and x < f.lo or f.hi is not None and x > f.hi:
        lo = "" if f.lo is None else f"{f.lo:g}"
        hi = "" if f.hi is None else f"{f.hi:g}"
        rng = f"{lo} to {hi}" if lo and hi else f"at least {lo}" if lo else f"at most {hi}"
        return None, f"{name}: {v} is out of range ({rng})"
    if f.above is not None and x <= f.above:
        return None, f"{name}: {v} is out of range (above {f.above:g})"
    return x, None


def _value(v, f: Field, name: str) -> tuple[object, str | None]:
    if f.kind in ("float", "int"):
        return _number(v, f, name)
    if f.kind == "pin":  # a digital pin number or an analog pin name, as the .dio/.aio write them
        if isinstance(v, bool) or not isinstance(v, (int, str)):
            return None, f"{name}: expected a pin (a number such as 5, or a name such as \"A0\"), found {_kind_of(v)}"
        return v, None
    if f.kind == "str":
        if not isinstance(v, str) or not v:
            return None, f"{name}: expected a non-empty string, found {_kind_of(v)} {_show(v)}"
        return v, None
    if f.kind == "bool":
        if not isinstance(v, bool):
            return None, f"{name}: expected true or false, found {_kind_of(v)} {_show(v)}"
        return v, None
    if f.kind == "names":
        if not isinstance(v, list) or not v or not all(isinstance(x, str) and x for x in v):
            return None, f"{name}: expected a list of names such as [\"Safe\", \"Armed\"]"
        return tuple(v), None
    if f.kind == "range":  # [low, high]: each within lo..hi, low <= high
        if (not isinstance(v, list) or len(v) != 2
                or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)):
            return None, f"{name}: expected a range [low, high] of two numbers, found {_kind_of(v)} {_show(v)}"
        pair = []
        for x in v:
            x, e = _number(x, Field("float", f.doc, lo=f.lo, hi=f.hi), name)
            if e:
                return None, e
            pair.append(x)
        if pair[0] > pair[1]:
            return None, f"{name}: the range's low end {v[0]} is above its high end {v[1]}"
        return tuple(pair), None
    if f.kind == "curve":
        if not isinstance(v, list) or len(v) < 2:
            return None, f"{name}: expected a list of two or more [seconds, value] points"
        pts = []
        for i, p in enumerate(v):
            if (not isinstance(p, list) or len(p) != 2
                    or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
                               for x in p)):
                return None, f"{name}: point {i + 1} is not a pair of numbers [seconds, value]: {_show(p)}"
            pts.append((float(p[0]), float(p[1])))
        for i, (t, y) in enumerate(pts):
            if t < 0 or y < 0:
                return None, f"{name}: point {i + 1} {list(pts[i])}: seconds and values must be >= 0"
            if f.x_hi is not None and t > f.x_hi:
                return None, f"{name}: point {i + 1} {list(pts[i])}: {t:g} s is out of range (at most {f.x_hi:g})"
            if f.hi is not None and y > f.hi:
                return None, f"{name}: point {i + 1} {list(pts[i])}: {y:g} is out of range (at most {f.hi:g})"
            if i and t <= pts[i - 1][0]:
                return None, f"{name}: point {i + 1}: times must increase ({pts[i - 1][0]:g} then {t:g})"
        return tuple(pts), None
    raise ValueError(f"unknown field kind {f.kind}")


def check(data: dict, schema: Schema, where: dict, path: str, bad: set | None = None) -> tuple[dict, list[str]]:
    """The checked values as {table: {key: value}} (defaults filled in), and
    the located errors. A key whose value is in error (missing, of the wrong
    type, out of range, in a table that is not one) is None in the values,
    and added to `bad` as (table, key)."""
    bad = set() if bad is None else bad
    errors: list[tuple[int, str]] = []
    out: dict[str, dict] = {}

    def err(line: int, msg: str) -> None:
        errors.append((line, msg))

    for tname, table in schema.items():
        got = data if tname == "" else data.get(tname)
        tline = where.get((tname, ""), 1)
        if tname and got is None:
            if any(f.required for f in table.fields.values()):
                err(1, f"missing table [{tname}] ({table.doc})")
            got = {}
        elif tname and not isinstance(got, dict):
            many = isinstance(got, list) and got and all(isinstance(x, dict) for x in got)
            err(where.get(("", tname), 1), f"`{tname}` must be a table [{tname}]"
                + (f", not an array of tables [[{tname}]]" if many else ""))
            got = {}
            bad.update((tname, key) for key in table.fields)
        vals = {}
        for key, f in table.fields.items():
            label = f"[{tname}] {key}" if tname else key
            if key not in got:
                if f.required:
                    err(tline, f"{label}: missing ({f.doc})")
                    bad.add((tname, key))
                vals[key] = f.default
                continue
            v, e = _value(got[key], f, label)
            if e:
                err(where.get((tname, key), tline), e)
                bad.add((tname, key))
            vals[key] = v
        for key in got:
            if tname == "" and key in schema:  # a table's name: its own check reports a value that is not one
                continue
            if key not in table.fields:
                label = f"[{tname}] " if tname else ""
                known = ", ".join(table.fields) or "none"
                if tname == "" and isinstance(got[key], dict):
                    err(where.get((key, ""), 1), f"unknown table [{key}] (tables: "
                        + ", ".join(t for t in schema if t) + ")")
                else:
                    err(where.get((tname, key), tline), f"{label}unknown key `{key}` (known: {known})")
        out[tname] = vals
    return out, [f"{_at(path, line)}: {msg}" for line, msg in sorted(errors, key=lambda e: e[0])]


def read(path: str) -> tuple[dict, str]:
    """A parameters file's TOML and text; ParamsError located in it."""
    try:
        raw = read_input(path)
    except FileNotFoundError:
        raise ParamsError([f"{path}: no such file (a plant's parameters: see docs/sim.md, Closed-loop flights)"]) \
            from None
    except OSError as e:
        raise ParamsError([f"{path}: {e.strerror or e}"]) from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        line = raw[:e.start].count(b"\n") + 1
        raise ParamsError([f"{path}:{line}: not UTF-8 text"]) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ParamsError([f"{path}:{toml_error_at(e, text)}"]) from None
    except ValueError:  # an integer of more digits than Python converts (4,300), not a TOML error
        m = re.search(r"(?<![\w.])[+-]?[0-9][0-9_]{4300,}", text)
        if m is None:
            raise
        line = text.count("\n", 0, m.start()) + 1
        col = m.start() - (text.rfind("\n", 0, m.start()) + 1) + 1
        digits = sum(ch.isdigit() for ch in m.group())
        raise ParamsError([f"{path}:{line}:{col}: an integer of {digits:,} digits: far beyond any parameter "
                           "(write a number in the physical range, e.g. 1e3)"]) from None
    return data, text


MAX_EXTENDS = 8  # files in one chain of `extends`


def resolve(path: str, schema: Schema | None = None, _chain: tuple[str, ...] = ()) -> tuple[dict, dict]:
    """A parameters file with its `extends` chain merged: (data, where),
    where's lines of the base files `Line`s naming their file. `schema`
    gives the tables' alternatives (None: none). ParamsError located at the
    `extends` key for a base that cannot be read, a cycle, a chain too long."""
    data, text = read(path)
    where: dict = locate(text)
    if "extends" not in data:
        return data, where
    base_rel = data.pop("extends")
    line = where.get(("", "extends"), 1)
    here = f"{_at(path, line)}: extends"
    if not isinstance(base_rel, str) or not base_rel:
        raise ParamsError([f"{here}: expected the path of another parameters file (\"../hpr/plant.toml\"), "
                           f"found {_kind_of(base_rel)} {_show(base_rel)}"])
    base = os.path.normpath(os.path.join(os.path.dirname(path), base_rel))
    chain = _chain + (os.path.realpath(path),)
    if os.path.realpath(base) in chain:
        raise ParamsError([f"{here}: {base} extends, in the end, this file again (a cycle)"])
    if len(chain) >= MAX_EXTENDS:
        raise ParamsError([f"{here}: more than {MAX_EXTENDS} files in one chain of `extends`"])
    if not os.path.isfile(base):
        raise ParamsError([f"{here}: no such file {base}"])
    bdata, bwhere = resolve(base, schema, chain)
    out = dict(bdata)
    loc = {k: (v if isinstance(v, Line) else Line(v, base)) for k, v in bwhere.items()}
    for tname, tval in data.items():
        table = (schema or {}).get(tname)
        if isinstance(tval, dict) and isinstance(out.get(tname), dict):
            merged = dict(out[tname])
            for group in (table.alternatives if table else ()):
                others = [k for k in group if k in tval]
                if others:
                    for g in table.alternatives:
                        if g is not group:
                            for k in g:
                                if k not in tval:
                                    merged.pop(k, None)
                                    loc.pop((tname, k), None)
            for k, leader in (table.follows if table else ()):
                if leader in out[tname] and leader not in merged and k not in tval:
                    merged.pop(k, None)
                    loc.pop((tname, k), None)
            merged.update(tval)
            out[tname] = merged
        else:
            out[tname] = tval
            for k in [k for k in loc if k[0] == tname and k[1]]:
                del loc[k]
    for k, v in where.items():
        if k[1] or k not in loc or k[0] in data:
            loc[k] = v
    return out, loc


def load(path: str, schema: Schema) -> tuple[dict, dict]:
    """Reads and checks a parameters file (its `extends` chain merged);
    (values, locations). ParamsError with every located error."""
    values, where, errors, _bad = load_all(path, schema)
    if errors:
        raise ParamsError(errors)
    return values, where


def load_all(path: str, schema: Schema) -> tuple[dict, dict, list[str], set]:
    """Reads and checks a parameters file (its `extends` chain merged), its
    errors returned rather than raised, so that the checks of its names and
    pins against a project can run on the values that are good and every
    error of the file be reported in one run: (values, locations, errors,
    bad), where `bad` holds the (table, key) of each value in error (None in
    `values`). ParamsError only for a file that cannot be read as TOML at
    all (or its `extends`)."""
    data, where = resolve(path, schema)
    bad: set = set()
    values, errors = check(data, schema, where, path, bad)
    return values, where, errors, bad


def key_file(path: str, where: dict, table: str, key: str) -> str:
    """The file that gave `table`.`key`: `path`, or the base it was
    inherited from through `extends` (a path in its value is relative to
    that file)."""
    return getattr(where.get((table, key)), "path", path)


def error_at(path: str, where: dict, table: str, key: str, msg: str) -> str:
    """A located message about a value that passed the schema but not a
    check across files (a pin the project does not have, ...)."""
    line = where.get((table, key)) or where.get((table, ""), 1)
    label = f"[{table}] {key}" if table else key
    return f"{_at(path, line)}: {label}: {msg}"
