"""Analog and digital channel tables (`.aio`, `.dio`; spec §6): the checker.
A table is parsed (appsyntax.parse_table) into rows of tokens; each row is
checked against the board and the state vector and becomes a `Channel` of
the model."""

from __future__ import annotations

import math
from fractions import Fraction

from . import model as M
from .appsyntax import Calibration, ChannelRow, Problem, Table, parse_table
from .board import Board
from .diagnostics import IO, Diagnostics, Source
from .model import Channel
from .numeric import REALS, f32_from_fraction, to_type

__all__ = ["Channel", "analog_gain", "analog_value", "check_channels", "check_table"]


# ---- what an analog input's element holds (firmware/src/fsw_io.h) -------------
# The firmware converts a count with one multiply-add, `count * gain +
# offset`, in the board's arithmetic R: the generator folds the converter
# (vref / (2^bits - 1)) and the .aio's `scale` into `gain` here, so no
# division runs on the MCU. Host tools that predict an element's value
# (tape replays, fswkit.sim.sensors) use analog_value: bit for bit what the
# native and AVR builds compute.

def analog_gain(scale: float, vref: float, bits: int, real) -> float:
    """Element units per count in R (`real`: numeric.REALS[...]): the exact
    R(scale) * R(vref) / (2^bits - 1) rounded once to R."""
    q = Fraction(real.literal(repr(float(scale)))) * Fraction(real.literal(repr(float(vref)))) / ((1 << bits) - 1)
    return f32_from_fraction(q) if real.bits == 32 else float(q)


def analog_value(count: int, gain: float, offset: float, real) -> float:
    """count * gain + offset as the firmware computes it in R: the product
    rounded to R, then the sum rounded to R (never fused)."""
    if real.bits == 32:
        product = f32_from_fraction(Fraction(count) * Fraction(gain))
        if not math.isfinite(product):  # overflowed: IEEE's infinity plus a finite offset
            return product + offset
        return f32_from_fraction(Fraction(product) + Fraction(offset))
    return float(count) * gain + offset


def check_table(src: Source, analog: bool, sv: M.StateVector, board: Board,
                diags: Diagnostics, used_pins: dict[int, tuple] | None = None,
                used_inputs: dict[str, tuple[str, int]] | None = None,
                refused: dict[int, str] | None = None) -> tuple[Channel, ...]:
    """The channels of one table, parsed and checked. `used_pins` /
    `used_inputs` carry what earlier tables of the same application took, so
    a pin or an input element used twice across tables is reported too
    (`used_pins`: pin -> (path, line), and for a sensor part's pin what it
    is there, sensors.py);
    `refused` maps pins no channel may have (though a chip select may) to why."""
    return check_channels(parse_table(src, analog, diags), sv, board, diags, used_pins, used_inputs, refused)


def check_channels(table: Table, sv: M.StateVector, board: Board, diags: Diagnostics,
                   used_pins: dict[int, tuple] | None = None,
                   used_inputs: dict[str, tuple[str, int]] | None = None,
                   refused: dict[int, str] | None = None) -> tuple[Channel, ...]:
    """The channels of a parsed table; every refused row is reported."""
    used_pins = {} if used_pins is None else used_pins
    used_inputs = {} if used_inputs is None else used_inputs
    err = lambda t, msg: diags.error(table.src, IO, t.line, t.col, msg)  # noqa: E731
    out: list[Channel] = []
    for row in table.rows:
        if isinstance(row, Problem):
            err(row.tok, row.message)
            continue
        calibration = _calibration(row, table.analog, board.real, err)
        if calibration is None:
            continue
        pin = _pin(row, table.analog, board, used_pins, err, refused or {})
        if pin is None:
            continue
        e = _element(row, table, sv, used_inputs, err)
        if e is None:
            continue
        if table.analog and row.direction.text == "i" and not _span(row, *calibration, e, board, err):
            continue
        used_pins[pin] = (table.src.path, row.direction.line)
        out.append(Channel(table.analog, row.direction.text, row.pin.text, pin, e, *calibration,
                           table.src.path, row.direction.line))
    return tuple(out)


def _calibration(row: ChannelRow, analog: bool, real: str, err) -> tuple[float, float] | None:
    """(scale, offset) of a row; None when one is refused."""
    values = {"scale": 1.0, "offset": 0.0}
    seen: set[str] = set()
    for cal in row.calibrations:
        key = cal.key.text
        if not analog or row.direction.text != "i":
            err(cal.key, f"`{key}=` applies only to analog inputs")
            return None
        if key in seen:
            err(cal.key, f"`{key}=` given twice")
            return None
        seen.add(key)
        v = _value(cal, real, err)
        if v is None:
            return None
        values[key] = v
    if row.stray is not None:
        err(row.stray.tok, row.stray.message)
        return None
    return values["scale"], values["offset"]


def _span(row: ChannelRow, scale: float, offset: float, e: M.Element, board: Board, err) -> bool:
    """Whether an analog input's calibration gives its element a finite
    value that follows the pin: the span per count (analog_gain) is not 0
    in the board's numbers, and the value at both ends of the converter,
    count 0 and 2^bits - 1, computed as the firmware computes it and stored
    in the element's type, is finite. Reported at `scale=` (at `offset=`
    when the row gives no scale)."""
    real = REALS[board.real]
    cals = {c.key.text: c.number for c in row.calibrations}
    at = cals.get("scale") or cals.get("offset")
    gain = analog_gain(scale, board.adc_vref, board.adc_bits, real)
    if gain == 0:
        err(at, f"`scale={_g(scale)}` gives `{e.name}` the offset ({_g(offset)}) whatever the pin reads: its "
                f"span, scale x {_g(board.adc_vref)} V / {(1 << board.adc_bits) - 1} counts, is 0 in the board's "
                f"numbers ({_BINARY[real.bits].split(':')[0]}); give the sensor's scale (element units per volt), "
                "negative if it falls as the volts rise")
        return False
    full = (1 << board.adc_bits) - 1
    for count, volts in ((0, 0), (full, board.adc_vref)):
        v = to_type(e.type, analog_value(count, gain, real.literal(repr(offset)), real))
        if not math.isfinite(v):
            what = (f"its {e.type} element (binary32: 3.4028235e38 at most)" if e.type.size == 4 and real.bits != 32
                    else f"the board's numbers ({_BINARY[real.bits]} at most)")
            sign = "-" if offset < 0 else "+"
            err(at, f"`{e.name}` = volts x {_g(scale)} {sign} {_g(abs(offset))} overflows {what} at "
                    + (f"the pin's full scale ({_g(volts)} V, count {count})" if count else "0 V (count 0)")
                    + f": the firmware would store {'-' if v < 0 else ''}infinity; check the calibration's units")
            return False
    return True


_BINARY = {32: "binary32: 3.4028235e38", 64: "binary64: 1.7976931348623157e308"}


def _g(v: float) -> str:
    """A number as a message shows it, exactly: `250`, `1e+39`, `0.5`."""
    return str(int(v)) if v.is_integer() and abs(v) < 1e16 else repr(v)


def _value(cal: Calibration, real: str, err) -> float | None:
    """The calibration's number. It must be finite as binary64 and as the
    board's evaluation type `real` (the firmware computes in it:
    `scale=1e39` is infinity in binary32)."""
    if cal.problem is not None:
        err(cal.problem.tok, cal.problem.message)
        return None
    v = float(cal.number.text)
    if not (math.isfinite(v) and math.isfinite(REALS[real].literal(repr(v)))):  # as the app emitter converts it
        most = "binary32: 3.4028235e38" if real == "f32" else "binary64: 1.7976931348623157e308"
        err(cal.number, f"`{cal.key.text}` is outside the representable range of the board's numbers "
                        f"({most} at most)")
        return None
    return -v if cal.negative else v


def _pin(row: ChannelRow, analog: bool, board: Board, used_pins: dict, err, refused: dict) -> int | None:
    """The board's number of the row's pin, when the row may use it."""
    text = row.pin.text
    pin = board.pin(text)
    if pin is None:
        problem = f"board `{board.name}` has no pin `{text}`"
    elif pin in board.reserved:
        problem = f"pin `{text}` is reserved on `{board.name}`: {board.reserved[pin]}"
    elif analog and row.direction.text == "i" and pin not in board.analog_pins.values():
        problem = f"pin `{text}` of `{board.name}` is not an analog input"
    elif analog and row.direction.text == "o" and pin in board.timer_pins:
        problem = (f"pin `{text}` of `{board.name}` cannot drive PWM: its timer ({board.timer}) paces the "
                   f"executor (PWM pins: {', '.join(str(p) for p in sorted(board.pwm_pins - board.timer_pins))})")
    elif analog and row.direction.text == "o" and pin not in board.pwm_pins:
        problem = (f"pin `{text}` of `{board.name}` cannot drive PWM "
                   f"(PWM pins: {', '.join(str(p) for p in sorted(board.pwm_pins - board.timer_pins))})")
    elif not analog and pin not in board.digital_pins:
        problem = f"pin `{text}` of `{board.name}` cannot be used as a digital pin"
    elif pin in used_pins:
        where, line, *role = used_pins[pin]  # a sensor part's pins say what they are there
        problem = f"pin `{text}` is already used ({where}:{line})" + (f": {role[0]}" if role else "")
    elif pin in refused:
        problem = f"pin `{text}` cannot be a channel's: {refused[pin]}"
    else:
        return pin
    err(row.pin, problem)
    return None


def _element(row: ChannelRow, table: Table, sv: M.StateVector, used_inputs: dict, err) -> M.Element | None:
    """The row's element, when it has the channel's type and, for an input,
    no other input writes it."""
    tok = row.element
    e = sv.find(tok.text)
    kind = "analog" if table.analog else "digital"
    if e is None:
        problem = f"unknown element `{tok.text}`"
    elif table.analog and not e.type.is_float:
        problem = f"{kind} channels need an F32 or F64 element; `{e.name}` is {e.type}"
    elif not table.analog and not e.type.is_bool:
        problem = f"{kind} channels need a bool element; `{e.name}` is {e.type}"
    elif row.direction.text == "i" and e.name in used_inputs:
        where, line = used_inputs[e.name]
        problem = f"element `{e.name}` is already written by an input ({where}:{line})"
    else:
        if row.direction.text == "i":
            used_inputs[e.name] = (table.src.path, row.direction.line)
        return e
    err(tok, problem)
    return None
