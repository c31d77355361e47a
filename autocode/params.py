"""The application's parameters (docs/parameters.md): every machine's
`[parameters]` in one table, ids in [configs] order then file order, with
their place in the value block, the table hash the EEPROM banks carry, and
the values a ground or a parameter file may give them.

Both ends use this module: the generator for the firmware's tables and
defaults, the ground (`fsw param`), `fsw sim --params` and the tests."""

from __future__ import annotations

import hashlib
import math
import re
import struct
from dataclasses import dataclass

from .evaluate import local_values
from .numeric import REALS
from .numtext import decimal, integer, non_finite
from .protocol import crc16
from .types import ElemType

HEADER = 9  # a bank's header: magic, seq u16, table hash u32, CRC u16
MAGIC = 0x50
MAX_PARAMS = 255


@dataclass(frozen=True)
class AppParam:
    id: int
    name: str
    machine: str
    type: ElemType
    default: object  # a value of the type (int, or float), in the board's evaluation type
    min: object | None  # None for a bool
    max: object | None
    unit: str
    when: tuple[str, ...]  # the states that allow a change
    when_ids: tuple[int, ...]
    off: int  # offset in the value block
    state_element: str  # the declaring machine's `S` element
    var: int  # index in the machine's vars
    line: int
    path: str

    @property
    def fmt(self) -> str:
        return "<" + self.type.fmt

    def pack(self, value) -> bytes:
        return struct.pack(self.fmt, value)

    def unpack(self, data: bytes):
        v = struct.unpack(self.fmt, data)[0]
        return bool(v) if self.type.is_bool else v

    def range_text(self) -> str:
        if self.type.is_bool:
            return "true or false"
        return f"{_num(self.min)}..{_num(self.max)}"


def _num(x) -> str:
    return f"{x:g}" if isinstance(x, float) else str(x)


def app_parameters(app) -> tuple[AppParam, ...]:
    """The table: every machine's parameters, in [configs] order."""
    cached = getattr(app, "_fsw_params", None)
    if cached is not None:
        return cached
    real = REALS[app.board.real]
    out: list[AppParam] = []
    off = 0
    for m in app.machines:
        params = [v for v in m.vars if v.param is not None]
        if not params:
            continue
        values = local_values(m, real)
        names = {st.id: st.name for st in m.states}
        for v in params:
            out.append(AppParam(len(out), v.name, m.name, v.type, values[v.index], v.param.min, v.param.max,
                                v.param.unit, tuple(names[i] for i in v.param.when), v.param.when,
                                off, m.vars[m.s].name, v.index, v.line, m.path))
            off += v.type.size
    table = tuple(out)
    try:
        object.__setattr__(app, "_fsw_params", table)
    except (AttributeError, TypeError):
        pass
    return table


def block_size(params) -> int:
    return sum(p.type.size for p in params)


def table_text(params) -> str:
    """The canonical text the table hash is taken over: what a bank's bytes
    mean (ids, names, types, offsets) and what makes a value valid (ranges,
    states). Defaults and units are not in it: a bank saved before a default
    changed still holds valid values."""
    lines = ["parameters 1"]
    for p in params:
        rng = "-" if p.type.is_bool else f"{p.pack(p.min).hex()} {p.pack(p.max).hex()}"
        lines.append(f"{p.id} {p.name} {p.type.name} {p.off} {rng} {p.machine} "
                     f"{','.join(str(i) for i in p.when_ids)}")
    return "\n".join(lines) + "\n"


def param_hash(params) -> int:
    """The table hash (u32): the first 4 bytes, little-endian, of SHA-256
    over table_text."""
    return int.from_bytes(hashlib.sha256(table_text(params).encode()).digest()[:4], "little")


def default_block(params) -> bytes:
    return b"".join(p.pack(p.default) for p in params)


def check_value(p: AppParam, value) -> tuple[object, str | None]:
    """A value a user gave for `p` (a Python bool, int, float, or text as
    typed) as a value of its type, or (None, why it cannot be)."""
    t = p.type
    if isinstance(value, str):
        text = value.strip()
        low = text.lower()
        if t.is_bool:
            if low in ("true", "1"):
                return True, None
            if low in ("false", "0"):
                return False, None
            return None, f"`{p.name}` is bool: give true or false, not `{value}`"
        # plain ASCII (numtext): int() and float() would take `1_000`, other scripts' digits, `nan`
        value = integer(text, hex_ok=True) if t.is_int else None
        if value is None:  # `1e3` or `3000.0` for a whole number, as a parameter file's TOML takes them
            value = decimal(text)
        if value is None:
            value = non_finite(text)  # said below as what it is: not finite, not held
        if value is None:
            kind = "a whole number" if t.is_int else "a number"
            return None, f"`{p.name}` is {t.name}: `{text}` is not {kind}{_unit_hint(p, text)}"
    if t.is_bool:
        if isinstance(value, bool):
            return value, None
        return None, f"`{p.name}` is bool: give true or false, not {value!r}"
    if isinstance(value, bool):
        return None, f"`{p.name}` is {t.name}: give a number, not {str(value).lower()}"
    if t.is_int:
        if isinstance(value, float):
            if not math.isfinite(value) or value != int(value):  # int() of an infinity overflows
                return None, f"`{p.name}` is {t.name}: give a whole number, not {value!r}"
            value = int(value)
        if not isinstance(value, int):
            return None, f"`{p.name}` is {t.name}: give a whole number, not {value!r}"
    else:
        if not isinstance(value, (int, float)):
            return None, f"`{p.name}` is {t.name}: give a number, not {value!r}"
        value = float(value) + 0.0  # -0 is 0: the board tells a change by the bytes
        if value != value:
            return None, f"`{p.name}`: NaN is not a value a parameter may take"
        if t.size == 4:
            try:
                held = struct.unpack("<f", struct.pack("<f", value))[0]
            except OverflowError:
                return None, f"`{p.name}` is F32: {value:g} is beyond its range"
            if held == 0 and value != 0:  # a value the user set apart from 0 would be 0
                return None, f"`{p.name}` is F32: {value:g} is held as 0; give 0, or a number from 1.4e-45"
            value = held
    if not p.min <= value <= p.max:
        return None, f"`{p.name}` = {_num(value)} is outside its range {p.range_text()}" + \
            (f" {p.unit}" if p.unit else "")
    return value, None


_NUMBER_THEN_WORD = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?\s*[^\d\s.+-].*")


def _unit_hint(p: AppParam, text: str) -> str:
    """For a number typed with a unit after it (`2s`, `650 psi`): that the
    number goes alone, in the parameter's unit; else nothing."""
    if not _NUMBER_THEN_WORD.fullmatch(text):
        return ""
    return f": give the number alone, in {p.unit} (its unit)" if p.unit else \
        f": give the number alone (`{p.name}` has no unit)"


def value_block(params, values: dict[str, object]) -> bytes:
    """The value block with `values` (checked values, by name) over the
    defaults."""
    return b"".join(p.pack(values.get(p.name, p.default)) for p in params)


def bank_image(params, values: dict[str, object], seq: int = 1) -> bytes:
    """A bank's bytes as the firmware writes them (docs/parameters.md)."""
    block = value_block(params, values)
    h = param_hash(params)
    body = struct.pack("<HI", seq & 0xFFFF, h)
    crc = crc16(body + block)
    return bytes([MAGIC]) + body + struct.pack(">H", crc) + block


def valid_banks(params, eeprom: bytes, base: int = 0) -> list[tuple[int, int, bytes]]:
    """The banks the firmware would take at boot, as (bank, sequence number,
    value block), newest first: magic, table hash, CRC and every value in
    its range (fsw_param.cpp's rule, restated for tests and tools)."""
    size = block_size(params)
    h = param_hash(params)
    out = []
    for b in (0, 1):
        at = base + b * (HEADER + size)
        bank = eeprom[at:at + HEADER + size]
        if len(bank) < HEADER + size or bank[0] != MAGIC:
            continue
        seq, th = struct.unpack_from("<HI", bank, 1)
        if th != h or struct.unpack_from(">H", bank, 7)[0] != crc16(bank[1:7] + bank[HEADER:]):
            continue
        block = bank[HEADER:]
        ok = True
        for p in params:
            v = p.unpack(block[p.off:p.off + p.type.size])
            if p.type.is_bool:
                ok = ok and block[p.off] <= 1
            elif not (v == v and p.min <= v <= p.max):
                ok = False
        if ok:
            out.append((b, seq, block))
    if len(out) == 2 and ((out[1][1] - out[0][1]) & 0xFFFF) not in range(1, 0x8000):
        return out
    return list(reversed(out)) if len(out) == 2 else out


def _const_expr(v, line: int, col: int):
    from . import model as Mo

    if isinstance(v, bool):
        return Mo.Const("true" if v else "false", line, col)
    text = repr(float(v)) if isinstance(v, float) else str(int(v))
    if text.startswith("-"):
        return Mo.Neg(Mo.Const(text[1:], line, col), line, col)
    return Mo.Const(text, line, col)


def machine_with_values(m, values: dict[str, object]):
    """The machine with these parameters' defaults replaced by `values` (by
    name; checked values): what the host runs (a state script with
    overrides, a plant or tape run with a parameter file) sees them as the
    firmware would after loading them."""
    import dataclasses

    if not any(v.param is not None and v.name in values for v in m.vars):
        return m
    new_vars = tuple(dataclasses.replace(v, init=_const_expr(values[v.name], v.line, 1))
                     if v.param is not None and v.name in values else v for v in m.vars)
    return dataclasses.replace(m, vars=new_vars)


def app_with_values(app, values: dict[str, object]):
    """The application with its parameters' defaults replaced by `values`."""
    import dataclasses

    if not values:
        return app
    return dataclasses.replace(app, machines=tuple(machine_with_values(m, values) for m in app.machines))


def var_param(m, v) -> AppParam:
    """One machine's parameter as a table row (id -1: outside an
    application), for checking a value given for it."""
    names = {st.id: st.name for st in m.states}
    return AppParam(-1, v.name, m.name, v.type, None, v.param.min, v.param.max, v.param.unit,
                    tuple(names[i] for i in v.param.when), v.param.when, 0, m.vars[m.s].name, v.index, v.line, m.path)
