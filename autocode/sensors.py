"""Sensor tables (`.sns`; docs/sensor-table.md): digital sensor parts on
the I2C (TWI) or SPI bus, one row each, named in the .app's [configs] as
`io FILE.sns` beside the `.aio`/`.dio` channel tables.

    # part    bus        settings             quantity=element ...
    bmp280    i2c:0x76   osrs_p=4 stuck=50    pressure=pressure fault=baroFault
    adxl345   spi:7      range=16 rate=400    -z=accel

A row is words separated by blanks (`#` starts a comment): the part, its
bus, then `key=value` words in any order: the part's settings (integers,
each with a default) and what its readings write (`quantity=element`, a
`-` before the quantity negating it; `fault=` a bool, `health=` a U8).
Each row is checked against the board, the state vector, the channel
tables and the other parts, and becomes a `Sensor` of the model; a refused
row is reported at its first problem (file:line:col, as the channel
tables are) and left out."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from os.path import basename

from . import model as M
from .board import Board
from .buses import i2c_bus, spi_bus, spi_channel_problem
from .diagnostics import IO, Columns, Diagnostics, Source
from .lexer import describe
from .model import SENSOR_PARTS, Sensor

MAX_SENSORS = 8  # parts in one application: a health byte each in health frames

# the 7-bit addresses each part answers at (its address pin)
ADDRESSES = {"bmp280": (0x76, 0x77), "ms5611": (0x76, 0x77), "adxl345": (0x53, 0x1D), "mpu6050": (0x68, 0x69)}
# settings by part, in the order Sensor.settings keeps them: (key, default, allowed values)
_COMMON = (("stuck", 50, tuple(range(256))), ("timeout", 3, tuple(range(1, 256))))
SETTINGS = {
    "bmp280": (("osrs_p", 4, (1, 2, 4, 8, 16)), ("osrs_t", 1, (1, 2, 4, 8, 16))) + _COMMON,
    "ms5611": (("osr", 1024, (256, 512, 1024, 2048, 4096)),) + _COMMON,
    "adxl345": (("range", 16, (2, 4, 8, 16)), ("rate", 400, (25, 50, 100, 200, 400, 800, 1600, 3200))) + _COMMON,
    "mpu6050": (("range", 16, (2, 4, 8, 16)), ("dlpf", 3, tuple(range(7)))) + _COMMON,
}
# what a part's readings give, and their units
QUANTITIES = {"bmp280": ("pressure", "temperature"), "ms5611": ("pressure", "temperature"),
              "adxl345": ("x", "y", "z"), "mpu6050": ("x", "y", "z", "temperature")}
UNITS = {"pressure": "Pa", "temperature": "degC", "x": "g", "y": "g", "z": "g"}
STATUS = ("fault", "health")  # fault=BOOL, health=U8
SPI_PARTS = ("adxl345",)  # parts the generated code drives on SPI

_WORD = re.compile(r"[^ \t\f\v\r]+")
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def _a(part: str) -> str:
    """The part with its article, as it is read aloud: `an ms5611`."""
    return f"{'an' if part[0] in 'am' else 'a'} {part}"


def sensor_name(s: Sensor) -> str:
    """How the host names a part: `bmp280@0x76`, `adxl345@spi:7`."""
    return f"{s.part}@0x{s.address:02x}" if s.bus == "i2c" else f"{s.part}@spi:{s.cs_pin}"


@dataclass(frozen=True)
class Word:
    text: str
    line: int
    col: int


@dataclass
class SensorState:
    """What the tables of one application took so far: shared by all its
    `.sns` tables (and, through `used_pins` / `used_inputs`, with the
    channel tables)."""
    count: int = 0
    addresses: dict[int, tuple[str, int, str]] = field(default_factory=dict)  # addr -> (path, line, part)
    cs_pins: dict[int, tuple[str, int, str]] = field(default_factory=dict)  # pin -> (path, line, part)
    i2c: tuple[str, int] | None = None  # the first I2C part: where it is
    spi: tuple[str, int] | None = None


def words(src: Source, diags: Diagnostics) -> list[list[Word]]:
    """The words of each line (comments dropped); a character that is not
    printable is reported and ends its line."""
    out = []
    for n, text in enumerate(src.lines, 1):
        body = text.split("#", 1)[0]
        cols = Columns(text) if "\t" in text else None
        row: list[Word] = []
        for m in _WORD.finditer(body):
            bad = next((i for i, ch in enumerate(m.group()) if not ch.isprintable()), None)
            if bad is not None:
                at = m.start() + bad
                diags.error(src, IO, n, cols(at) if cols else at + 1, f"unexpected {describe(body[at])}")
                row = []
                break
            row.append(Word(m.group(), n, cols(m.start()) if cols else m.start() + 1))
        out.append(row)
    return out


def check_sensor_table(src: Source, sv: M.StateVector, board: Board, diags: Diagnostics,
                       channels: list[M.Channel], used_pins: dict, used_inputs: dict,
                       state: SensorState) -> tuple[Sensor, ...]:
    """The parts of one `.sns` table, each row checked; every refused row is
    reported. `channels`: those of the tables before this one (whose pins
    the buses must not take); `used_pins`, `used_inputs`: as the channel
    tables share them (iotables.check_table); `state`: the parts so far."""
    out = []
    for row in words(src, diags):
        if not row:
            continue
        try:
            out.append(_check_row(row, src, sv, board, channels, used_pins, used_inputs, state))
        except _Refused as e:
            diags.error(src, IO, e.w.line, e.w.col, e.msg)
    return tuple(out)


class _Refused(Exception):
    """A row refused: the word at fault and why (the row's one report)."""

    def __init__(self, w: Word, msg: str):
        super().__init__(msg)
        self.w, self.msg = w, msg


def _where(path: str, line: int) -> str:
    return f"{basename(path)}:{line}"


def _check_row(row, src, sv, board, channels, used_pins, used_inputs, state) -> Sensor:
    pw = row[0]
    part = pw.text
    if part not in SENSOR_PARTS:
        raise _Refused(pw, f"unknown part `{part}`: expected one of {', '.join(SENSOR_PARTS)}")
    if state.count == MAX_SENSORS:
        raise _Refused(pw, f"sensor part {MAX_SENSORS + 1}: an application has at most {MAX_SENSORS} "
                           "(a health byte each in health frames)")
    if len(row) < 2:
        raise _Refused(pw, f"expected the {part}'s bus after the part: `i2c:ADDRESS` or `spi:PIN`")
    bw = row[1]
    bus, _, where = bw.text.partition(":")
    if bus not in ("i2c", "spi") or not where:
        raise _Refused(bw, f"expected the {part}'s bus: `i2c:ADDRESS` (e.g. `i2c:0x{ADDRESSES[part][0]:02x}`) or "
                           f"`spi:PIN` (the chip select's pin), found `{bw.text}`")
    at = Word(where, bw.line, bw.col + len(bus) + 1)
    address = cs_pin = None
    if bus == "i2c":
        address = _address(at, part, state)
    else:
        cs_pin = _cs_pin(at, part, board, channels, used_pins, state)
    settings, outputs, fault, health = _pairs(row[2:], part, sv, used_inputs, bw)
    # nothing refused: the row takes its bus, its pins and its elements
    if bus == "i2c":
        if state.i2c is None:
            _claim_bus(i2c_bus(board), "I2C", board, channels, used_pins, pw, src, bw)
            state.i2c = (src.path, pw.line)
        state.addresses[address] = (src.path, pw.line, part)
    else:
        if state.spi is None:
            _claim_bus(spi_bus(board), "SPI", board, channels, used_pins, pw, src, bw)
            state.spi = (src.path, pw.line)
        state.cs_pins[cs_pin] = (src.path, pw.line, part)
        used_pins[cs_pin] = (src.path, pw.line, f"the chip select of the {part} there")
    for _, el in outputs:
        used_inputs[el.name] = (src.path, pw.line)
    for el in (fault, health):
        if el is not None:
            used_inputs[el.name] = (src.path, pw.line)
    state.count += 1
    return Sensor(part, bus, address, cs_pin, where, settings, outputs, fault, health, src.path, pw.line)


def _address(w: Word, part: str, state: SensorState) -> int:
    t = w.text
    if re.fullmatch(r"0[xX][0-9A-Fa-f]{1,2}", t):
        a = int(t, 16)
    elif re.fullmatch(r"[0-9]{1,3}", t):
        a = int(t)
    else:
        raise _Refused(w, f"expected an I2C address after `i2c:`, hex (`0x76`) or decimal, found `{t}`")
    known = ADDRESSES[part]
    if a not in known:
        raise _Refused(w, f"{_a(part)} answers at 0x{known[0]:02x} or 0x{known[1]:02x} "
                          f"(its address pin chooses), not 0x{a:02x}")
    if a in state.addresses:
        path, line, other = state.addresses[a]
        raise _Refused(w, f"address 0x{a:02x} is already the {other}'s ({_where(path, line)}): two parts "
                          "on one I2C bus need two addresses")
    return a


def _cs_pin(w: Word, part: str, board: Board, channels, used_pins: dict, state: SensorState) -> int:
    if part not in SPI_PARTS:
        if part == "bmp280":
            raise _Refused(w, "a bmp280 on SPI is not supported yet: wire it to the I2C bus (`i2c:0x76` or "
                              "`i2c:0x77`)")
        raise _Refused(w, f"{_a(part)} speaks I2C only: `i2c:0x{ADDRESSES[part][0]:02x}` or "
                          f"`i2c:0x{ADDRESSES[part][1]:02x}`")
    t = w.text
    pin = board.pin(t) if t.isascii() else None
    if pin is None or pin not in board.digital_pins:
        pins = sorted(board.digital_pins)
        raise _Refused(w, f"the {board.name} has no digital pin `{t}` for the chip select "
                          f"(digital pins: {pins[0]}..{pins[-1]})")
    if pin in board.reserved:
        raise _Refused(w, f"pin {pin} is reserved on the {board.name}: {board.reserved[pin]}")
    bus = dict(spi_bus(board))
    bus.update(i2c_bus(board) if state.i2c is not None else {})
    if pin in bus:
        which = "I2C" if bus[pin] in ("SDA", "SCL") else "SPI"
        raise _Refused(w, f"pin {pin} is the {which} bus's {bus[pin]} on the {board.name}: the chip select must "
                          "be another pin")
    if pin in state.cs_pins:
        path, line, other = state.cs_pins[pin]
        raise _Refused(w, f"pin {pin} is already the chip select of the {other} ({_where(path, line)})")
    for c in channels:
        if c.pin_number == pin:
            raise _Refused(w, f"pin {pin} is already the channel of `{c.element.name}` ({_where(c.path, c.line)})")
    if pin in used_pins:
        path, line = used_pins[pin][:2]
        raise _Refused(w, f"pin {pin} is already used ({_where(path, line)})")
    return pin


def _claim_bus(bus: dict[int, str], name: str, board: Board, channels, used_pins: dict, pw: Word, src, bw) -> None:
    """The first part on a bus: no channel of an earlier table may be on the
    bus's pins; the pins are then taken (a later table's channel on one is
    reported there)."""
    for c in channels:
        if c.pin_number in bus:
            raise _Refused(bw, f"the {name} bus takes pin {c.pin} ({bus[c.pin_number]}) on the {board.name}, but it "
                               f"is the channel of `{c.element.name}` ({_where(c.path, c.line)})")
    hit = spi_channel_problem(board, channels) if name == "SPI" else None
    if hit is not None:  # a channel on SS: the master drives it (a later table's is refused at its pin)
        c, why = hit
        raise _Refused(bw, f"with a part on the SPI bus, pin {c.pin} is {why}: the channel of "
                           f"`{c.element.name}` ({_where(c.path, c.line)}) cannot have it; move the channel to "
                           "another pin")
    for pin, role in bus.items():
        used_pins.setdefault(pin, (src.path, pw.line, f"the {name} bus's {role}, which the {pw.text} there is on"))


def _pairs(ws: list[Word], part: str, sv: M.StateVector, used_inputs: dict, bw: Word):
    """(settings, outputs, fault, health) of the row's `key=value` words."""
    table = {k: (d, allowed) for k, d, allowed in SETTINGS[part]}
    given: dict[str, int] = {}
    outputs: list[tuple[str, M.Element]] = []
    status: dict[str, M.Element] = {}
    seen: dict[str, Word] = {}
    for w in ws:
        key, eq, value = w.text.partition("=")
        if not eq or not key or not value:
            raise _Refused(w, f"expected `key=value` (a setting, or `quantity=element`), found `{w.text}`")
        vw = Word(value, w.line, w.col + len(key) + 1)
        negative = key.startswith("-")
        name = key[1:] if negative else key
        if name in seen:
            raise _Refused(w, f"`{name}` given twice (first at column {seen[name].col})")
        if name in table and not negative:
            seen[name] = w
            given[name] = _setting_value(vw, name, part, table[name][1])
        elif name in QUANTITIES[part]:
            seen[name] = w
            outputs.append((key, _element(vw, sv, used_inputs, outputs, status, "float", key, part)))
        elif name in STATUS and not negative:
            seen[name] = w
            status[name] = _element(vw, sv, used_inputs, outputs, status, name, name, part)
        else:
            raise _Refused(w, _unknown_key_problem(key, name, negative, part))
    if not outputs:
        at = ws[-1] if ws else bw
        raise _Refused(at, f"the {part} writes no element: give at least one of "
                           + ", ".join(f"`{q}=ELEMENT`" for q in QUANTITIES[part]))
    settings = tuple((k, given.get(k, d)) for k, d, _ in SETTINGS[part])
    return settings, tuple(outputs), status.get("fault"), status.get("health")


def _unknown_key_problem(key: str, name: str, negative: bool, part: str) -> str:
    settings = ", ".join(k for k, _, _ in SETTINGS[part])
    quantities = ", ".join(QUANTITIES[part])
    if negative and (name in STATUS or any(name == k for k, _, _ in SETTINGS[part])):
        return f"`-` negates a quantity ({quantities}); `{name}` is none"
    if any(name in q for q in QUANTITIES.values()):
        return f"{_a(part)} measures no `{name}`: its quantities are {quantities}"
    if any(name == k for s in SETTINGS.values() for k, _, _ in s):
        return f"`{name}` is no setting of the {part}: its settings are {settings}"
    return (f"unknown setting or quantity `{key}`: {_a(part)} takes the settings {settings}, the quantities "
            f"{quantities}, and `fault=`, `health=`")


def _setting_value(w: Word, key: str, part: str, allowed: tuple[int, ...]) -> int:
    if not re.fullmatch(r"[0-9]{1,6}", w.text) or int(w.text) not in allowed:
        if allowed == tuple(range(allowed[0], allowed[-1] + 1)):
            shown = f"a whole number from {allowed[0]} to {allowed[-1]}"
        else:
            shown = "one of " + ", ".join(str(v) for v in allowed)
        raise _Refused(w, f"the {part}'s `{key}` is {shown}, found `{w.text}`")
    return int(w.text)


def _element(w: Word, sv: M.StateVector, used_inputs: dict, outputs, status, kind: str, key: str,
             part: str) -> M.Element:
    e = sv.find(w.text) if _NAME.fullmatch(w.text) else None
    if e is None:
        raise _Refused(w, f"unknown element `{w.text}`")
    if kind == "float" and not e.type.is_float:
        raise _Refused(w, f"`{key}` is a reading ({UNITS[key.lstrip('-')]}): it needs an F32 or F64 element; "
                          f"`{e.name}` is {e.type}")
    if kind == "fault" and not e.type.is_bool:
        raise _Refused(w, f"`fault` needs a bool element; `{e.name}` is {e.type}")
    if kind == "health" and e.type.name != "U8":
        raise _Refused(w, f"`health` needs a U8 element (the health code); `{e.name}` is {e.type}")
    if e.name in used_inputs:
        path, line = used_inputs[e.name]
        raise _Refused(w, f"element `{e.name}` is already written by an input ({_where(path, line)})")
    if any(el.name == e.name for _, el in outputs) or any(el.name == e.name for el in status.values()):
        raise _Refused(w, f"element `{e.name}` is written twice by this {part}")
    return e
