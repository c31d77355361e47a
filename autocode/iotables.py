"""Analog and digital channel tables (`.aio`, `.dio`; spec §6): one channel
per line, checked against the board and the state vector."""

from __future__ import annotations

import math
from dataclasses import dataclass

from . import model as M
from .board import Board
from .diagnostics import IO, Diagnostics, Source
from .lexer import ID, NUM, OP, lex
from .numeric import REALS


@dataclass(frozen=True)
class Channel:
    analog: bool
    direction: str  # "i" or "o"
    pin: str  # as written: "A0", "4"
    pin_number: int  # the board's pin number
    element: M.Element
    scale: float  # analog inputs: element = volts * scale + offset
    offset: float
    path: str
    line: int


def _parse_value(toks, i, src, diags, what, real: str):
    """A signed number at toks[i:]; returns (value, next index). It must be
    finite as binary64 and as the board's evaluation type `real` (the
    firmware computes in it: `scale=1e39` is infinity in binary32)."""
    neg = False
    if i < len(toks) and toks[i].kind == OP and toks[i].text == "-":
        neg, i = True, i + 1
    if i >= len(toks) or toks[i].kind != NUM:
        t = toks[i] if i < len(toks) else toks[-1]
        diags.error(src, IO, t.line, t.col, f"expected a number after `{what}=`")
        return None, len(toks)
    v = float(toks[i].text)
    if not (math.isfinite(v) and math.isfinite(REALS[real].literal(repr(v)))):  # as emit_app converts it
        most = "binary32: 3.4028235e38" if real == "f32" else "binary64: 1.7976931348623157e308"
        diags.error(src, IO, toks[i].line, toks[i].col,
                    f"`{what}` is outside the representable range of the board's numbers ({most} at most)")
        return None, len(toks)
    return (-v if neg else v), i + 1


def check_table(src: Source, analog: bool, sv: M.StateVector, board: Board,
                diags: Diagnostics, used_pins: dict[int, tuple[str, int]] | None = None,
                used_inputs: dict[str, tuple[str, int]] | None = None) -> tuple[Channel, ...]:
    """The channels of one table. `used_pins` / `used_inputs` carry what
    earlier tables of the same application took, so a pin or an input
    element used twice across tables is reported too."""
    used_pins = {} if used_pins is None else used_pins
    used_inputs = {} if used_inputs is None else used_inputs
    err = lambda t, msg: diags.error(src, IO, t.line, t.col, msg)  # noqa: E731
    kind = "analog" if analog else "digital"
    out: list[Channel] = []
    for toks in lex(src, diags, IO):
        if not toks:
            continue
        d = toks[0]
        if d.kind != ID or d.text not in ("i", "o"):
            err(d, f"expected a direction `i` or `o`, found `{d.text}`")
            continue
        if len(toks) < 2 or toks[1].kind not in (ID, NUM):
            t = toks[1] if len(toks) > 1 else d
            err(t, "expected a pin after the direction")
            continue
        pin_tok = toks[1]
        if len(toks) < 3 or toks[2].kind != ID:
            t = toks[2] if len(toks) > 2 else pin_tok
            err(t, "expected an element after the pin")
            continue
        el_tok = toks[2]
        scale, offset = 1.0, 0.0
        i = 3
        bad = False
        seen_opt: set[str] = set()
        while i < len(toks):
            t = toks[i]
            if (t.kind == ID and t.text in ("scale", "offset") and i + 1 < len(toks)
                    and toks[i + 1].kind == OP and toks[i + 1].text == "="):
                if not analog or d.text != "i":
                    err(t, f"`{t.text}=` applies only to analog inputs")
                    bad = True
                    break
                if t.text in seen_opt:
                    err(t, f"`{t.text}=` given twice")
                    bad = True
                    break
                seen_opt.add(t.text)
                v, i = _parse_value(toks, i + 2, src, diags, t.text, board.real)
                if v is None:
                    bad = True
                    break
                if t.text == "scale":
                    scale = v
                else:
                    offset = v
            else:
                err(t, f"unexpected `{t.text}`: expected `scale=K` or `offset=B`")
                bad = True
                break
        if bad:
            continue
        direction = d.text
        pin = board.pin(pin_tok.text)
        if pin is None:
            err(pin_tok, f"board `{board.name}` has no pin `{pin_tok.text}`")
            continue
        if pin in board.reserved:
            err(pin_tok, f"pin `{pin_tok.text}` is reserved on `{board.name}`: {board.reserved[pin]}")
            continue
        if analog and direction == "i" and pin not in board.analog_pins.values():
            err(pin_tok, f"pin `{pin_tok.text}` of `{board.name}` is not an analog input")
            continue
        if analog and direction == "o" and pin not in board.pwm_pins:
            err(pin_tok, f"pin `{pin_tok.text}` of `{board.name}` cannot drive PWM "
                         f"(PWM pins: {', '.join(str(p) for p in sorted(board.pwm_pins))})")
            continue
        if not analog and pin not in board.digital_pins:
            err(pin_tok, f"pin `{pin_tok.text}` of `{board.name}` cannot be used as a digital pin")
            continue
        if pin in used_pins:
            where, line = used_pins[pin]
            err(pin_tok, f"pin `{pin_tok.text}` is already used ({where}:{line})")
            continue
        e = sv.find(el_tok.text)
        if e is None:
            err(el_tok, f"unknown element `{el_tok.text}`")
            continue
        if analog and not e.type.is_float:
            err(el_tok, f"{kind} channels need an F32 or F64 element; `{e.name}` is {e.type}")
            continue
        if not analog and not e.type.is_bool:
            err(el_tok, f"{kind} channels need a bool element; `{e.name}` is {e.type}")
            continue
        if direction == "i":
            if e.name in used_inputs:
                where, line = used_inputs[e.name]
                err(el_tok, f"element `{e.name}` is already written by an input ({where}:{line})")
                continue
            used_inputs[e.name] = (src.path, d.line)
        used_pins[pin] = (src.path, d.line)
        out.append(Channel(analog, direction, pin_tok.text, pin, e, scale, offset, src.path, d.line))
    return tuple(out)
