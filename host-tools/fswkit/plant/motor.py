"""RASP motor files (`.eng`): the thrust curves rocketeers download
(thrustcurve.org, the makers' sites) and every flight simulator reads.

    ; comments start with a semicolon, anywhere on a line
    G80T 29 124 4-7-10 0.0625 0.1252 AT
       0.02  95.0
       ...
       1.50   0.0

The header names the motor, its diameter and length in millimetres, its
delays (`4-7-10`, `P` for plugged, `0`), its propellant and total masses
in kilograms and its maker. Then one `time thrust` pair a line, seconds
from ignition and newtons, times increasing, ending at zero thrust. A file
may hold several motors, one after another (each header starts one).

The impulse and the propellant mass are held to each other: a specific
impulse outside ISP_MIN_S..ISP_MAX_S is a number in the wrong unit (masses
in grams, times in milliseconds), located at the header's propellant mass.

`load(path)` reads a file into EngMotor records; a bad file is an EngError
whose lines are located `file:line:col: message`.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from fswkit.autocode.diagnostics import PER_FILE


class EngError(Exception):
    """One or more located errors in a motor file."""

    def __init__(self, errors: list[str]):
        super().__init__("\n".join(errors))
        self.errors = errors


@dataclass(frozen=True)
class EngMotor:
    name: str
    diameter_mm: float
    length_mm: float
    delays: str
    propellant_kg: float
    total_kg: float
    maker: str
    points: tuple  # ((s, N), ...) as the file gives them
    path: str
    line: int  # the header's

    def curve(self) -> tuple:
        """The points from ignition: (0, 0) first when the file starts later,
        as simulators read a RASP curve."""
        return self.points if self.points[0][0] == 0 else ((0.0, 0.0),) + self.points

    @property
    def total_impulse(self) -> float:
        c = self.curve()
        return sum((t1 - t0) * (f0 + f1) / 2 for (t0, f0), (t1, f1) in zip(c, c[1:]))

    @property
    def burn_time(self) -> float:
        return self.points[-1][0]


# The limits of a thrust curve, whether written in a plant file
# (`thrust_curve`) or read from a motor file, and of a motor's masses
# (`propellant_kg`): beyond any motor the plant flies.
CURVE_MAX_S = 600.0
CURVE_MAX_N = 1e6
MAX_MASS_KG = 1000.0

# A rocket motor's specific impulse (total impulse per unit weight of
# propellant): black powder about 80 s, composites and hybrids up to about
# 250 s, liquid engines up to about 450 s. A ratio outside this range is a
# number in the wrong unit: masses in grams, thrust not in newtons, times in
# milliseconds.
ISP_MIN_S = 20.0
ISP_MAX_S = 500.0
G0 = 9.80665


def impulse_problem(impulse: float, propellant_kg: float) -> str | None:
    """What is wrong with `impulse` N·s delivered by `propellant_kg` of
    propellant (a specific impulse no rocket motor has, and the unit that is
    likely wrong), or None."""
    isp = impulse / (propellant_kg * G0)
    if ISP_MIN_S <= isp <= ISP_MAX_S:
        return None
    shown = f"{isp:,.0f}" if isp >= 100 else f"{isp:.3g}"
    why = ("a mass in grams, or thrust in another unit than newtons?" if isp < ISP_MIN_S else
           "times in milliseconds, or a mass that is not all of the propellant's?")
    return (f"{impulse:,.4g} N·s from {propellant_kg:g} kg of propellant is a specific impulse of {shown} s; "
            f"a rocket motor's is {ISP_MIN_S:g} to {ISP_MAX_S:g} s (newtons, seconds and kilograms: {why})")


def _number(tok: str) -> float | None:
    if "_" in tok or not tok.isascii():  # Python reads 1_0 as 10, and digits of any script; a motor file's are plain
        return None
    try:
        x = float(tok)
    except ValueError:
        return None
    return x if math.isfinite(x) else None


_NUMERIC = re.compile(r"[-+]?[0-9.,_]*[0-9][0-9.,_]*(?:[eE][-+]?[0-9]+)?")
COMMA = "(a decimal point, not a comma; the fields of a line are separated by spaces)"


def _not_plain(tok: str) -> str | None:
    """What a token meant as a number lacks to be a motor file's number (a
    finite one, without `_`, with a decimal point), or None when it is one
    or does not look like a number at all."""
    if "," in tok and _NUMERIC.fullmatch(tok):
        return f"a number {COMMA}"
    try:
        x = float(tok)
    except ValueError:
        return None
    if "_" in tok:
        return "a plain number (no `_`)"
    if not tok.isascii():
        return "a plain number (ASCII digits)"
    return None if math.isfinite(x) else "a finite number"


HEADER = "name diameter_mm length_mm delays propellant_kg total_kg maker"
SHOWN_CHARS = 40  # of a name or a number a message shows


def _clip(tok: str) -> str:
    return tok if len(tok) <= SHOWN_CHARS else tok[:SHOWN_CHARS] + "..."
_CONTROL = re.compile(r"[\x00-\x08\x0e-\x1f\x7f]")  # not a tab, a line's end or a form feed


def parse(text: str, path: str) -> list[EngMotor]:
    """The motors of a motor file's text; EngError with every located error."""
    errors: list[str] = []
    motors: list[EngMotor] = []
    cur: dict | None = None

    hidden = 0  # errors past PER_FILE: counted, not shown

    def err(line: int, col: int, msg: str) -> None:
        nonlocal hidden
        if len(errors) < PER_FILE:
            errors.append(f"{path}:{line}:{col}: {msg}")
        else:
            hidden += 1

    def finish() -> None:
        if cur is None or cur.get("orphan"):
            return
        pts = cur["points"]
        if not pts and not cur.get("seen"):  # (a motor whose every point was wrong has its errors already)
            err(cur["line"], 1, f"motor {_clip(cur['name'])} has no thrust points (after its header, one "
                "`seconds newtons` pair a line)")
        elif not cur["bad"]:
            if pts[-1][1] != 0:
                err(cur["last"], cur["last_col"], f"the thrust curve of {_clip(cur['name'])} must end at zero thrust "
                    f"(its last point is {pts[-1][1]:g} N at {pts[-1][0]:g} s)")
            elif len(pts) < 2 and pts[0][0] == 0:
                err(cur["last"], 1, f"motor {_clip(cur['name'])} has one point at 0 s: no burn")
            else:
                m = EngMotor(cur["name"], cur["dia"], cur["len"], cur["delays"], cur["prop"], cur["total"],
                             cur["maker"], tuple(pts), path, cur["line"])
                if m.total_impulse == 0:
                    err(cur["line"], 1, f"motor {_clip(m.name)}: its thrust curve delivers no impulse (every point "
                        "is 0 N)")
                    return
                problem = impulse_problem(m.total_impulse, m.propellant_kg)
                if problem:
                    err(cur["line"], cur["prop_col"], f"motor {_clip(m.name)}: {problem}")
                    return
                motors.append(m)

    eof = text.find("\x1a")  # DOS's end-of-file mark, which old RASP files end with
    if eof >= 0 and not text[eof:].replace("\x1a", "").strip():
        text = text[:eof]
    start = len(text) - len(text.lstrip())
    if text[start:start + 1] == "<":  # a RockSim .rse (XML) under a RASP file's name
        line = text.count("\n", 0, start) + 1
        col = start - (text.rfind("\n", 0, start) + 1) + 1
        raise EngError([f"{path}:{line}:{col}: an XML file (a RockSim .rse motor file?), not a RASP .eng motor "
                        "file: download the motor's RASP (.eng) file instead"])
    for n, raw in enumerate(text.splitlines(), 1):
        code = raw.split(";", 1)[0]
        if not code.strip():
            continue
        ctrl = _CONTROL.search(code)
        if ctrl:  # invisible in a message: named, and the line not read
            err(n, ctrl.start() + 1, f"a control character (U+{ord(ctrl.group()):04X}) in the text: delete it (a "
                "motor file is plain text)")
            words = _CONTROL.sub(" ", code).split()
            if not words or _number(words[0]) is not None:  # a thrust point's line, or nothing else
                if cur is not None:
                    cur["bad"] = cur["seen"] = True
            else:  # a header's: its points are not another motor's
                finish()
                cur = {"name": "?", "line": n, "points": [], "bad": True, "orphan": True}
            continue
        toks, cols = [], []
        i = 0
        while i < len(code):
            if code[i].isspace():
                i += 1
                continue
            j = i
            while j < len(code) and not code[j].isspace():
                j += 1
            toks.append(code[i:j])
            cols.append(i + 1)
            i = j
        shown = [_clip(t) for t in toks]  # as messages show them
        first = _number(toks[0])
        why = _not_plain(toks[0]) if first is None and len(toks) < 4 else None
        if why:  # a thrust point whose time is written wrong (nan, 1_0, 0,5), not a header of 7 fields
            err(n, cols[0], f"`{shown[0]}`: expected the time in seconds, {why}")
            if cur is None:
                cur = {"name": "?", "line": n, "points": [], "bad": True, "orphan": True}
            cur["bad"] = cur["seen"] = True
            continue
        if first is None:  # a header
            finish()
            cur = {"name": toks[0], "line": n, "points": [], "bad": False, "last": n, "last_col": 1,
                   "dia": 0.0, "len": 0.0, "delays": "", "prop": 0.0, "total": 0.0, "maker": ""}
            if len(toks) < 7:
                err(n, cols[-1] + len(toks[-1]), f"a motor's header has 7 fields ({HEADER}); this one has "
                    f"{len(toks)}")
                cur["bad"] = True
                continue
            if len(toks) > 7:
                err(n, cols[7], f"a motor's header has 7 fields ({HEADER}); this one has {len(toks)} "
                    "(a maker's name with spaces? write it without)")
                cur["bad"] = True
                continue
            vals = {}
            for k, idx, lo, what in (("dia", 1, 0.0, "diameter in mm"), ("len", 2, 0.0, "length in mm"),
                                     ("prop", 4, 0.0, "propellant mass in kg"), ("total", 5, 0.0, "total mass in kg")):
                x = _number(toks[idx])
                if x is None or x <= lo:
                    err(n, cols[idx], f"`{shown[idx]}`: expected the motor's {what}, a positive number"
                        + (f" {COMMA}" if "," in toks[idx] and _NUMERIC.fullmatch(toks[idx]) else ""))
                    cur["bad"] = True
                elif k in ("prop", "total") and x > MAX_MASS_KG:
                    err(n, cols[idx], f"{shown[idx]} kg: the motor's {what.split(' in ')[0]} is at most "
                        f"{MAX_MASS_KG:g} kg")
                    cur["bad"] = True
                vals[k] = x
            if not cur["bad"]:
                if vals["prop"] > vals["total"]:
                    err(n, cols[4], f"the propellant ({shown[4]} kg) weighs more than the whole motor "
                        f"({shown[5]} kg)")
                    cur["bad"] = True
                cur.update(vals, delays=toks[3], maker=toks[6], prop_col=cols[4])
            continue
        if cur is None:
            err(n, cols[0], f"a thrust point before any motor header (the first line that is not a comment is "
                f"the header: {HEADER})")
            cur = {"name": "?", "line": n, "points": [], "bad": True, "orphan": True}
            continue
        cur["seen"] = True
        if len(toks) != 2:
            err(n, cols[min(2, len(toks) - 1)] if len(toks) > 2 else cols[0] + len(toks[0]),
                f"a thrust point is two numbers, `seconds newtons`; this line has {len(toks)} field"
                + ("s" if len(toks) != 1 else ""))
            cur["bad"] = True
            continue
        t, f = first, _number(toks[1])
        if f is None:
            err(n, cols[1], f"`{shown[1]}`: expected the thrust in newtons, {_not_plain(toks[1]) or 'a number'}")
            cur["bad"] = True
            continue
        if t < 0:
            err(n, cols[0], f"{shown[0]} s: a thrust point's time is seconds after ignition, never negative")
            cur["bad"] = True
            continue
        if f < 0:
            err(n, cols[1], f"{shown[1]} N: thrust is never negative")
            cur["bad"] = True
            continue
        if t > CURVE_MAX_S:
            err(n, cols[0], f"{shown[0]} s: a thrust curve lasts at most {CURVE_MAX_S:g} s")
            cur["bad"] = True
            continue
        if f > CURVE_MAX_N:
            err(n, cols[1], f"{shown[1]} N: a thrust curve's points are at most {CURVE_MAX_N:g} N")
            cur["bad"] = True
            continue
        pts = cur["points"]
        if pts and t <= pts[-1][0]:
            err(n, cols[0], f"times must increase: {t:g} s after {pts[-1][0]:g} s")
            cur["bad"] = True
            continue
        if pts and pts[-1][1] == 0 and pts[-1][0] > 0:
            err(n, cols[0], f"a point after the curve ended at zero thrust ({pts[-1][0]:g} s): a motor's curve "
                "ends at its first zero after ignition")
            cur["bad"] = True
            continue
        pts.append((t, f))
        cur["last"], cur["last_col"] = n, cols[1]
    finish()
    if not errors and not motors:
        errors.append(f"{path}:1:1: no motor in this file (a RASP .eng file: `;` comments, a header `{HEADER}`, "
                      "then `seconds newtons` lines ending at zero thrust)")
    if hidden:
        errors.append(f"{path}: {hidden:,} more error{'s' if hidden != 1 else ''} not shown (at most {PER_FILE} a "
                      "file are)")
    if errors:
        raise EngError(errors)
    return motors


def load(path: str) -> list[EngMotor]:
    """The motors of a motor file; EngError for a file that cannot be read
    or is not a motor file. Read as every input of the tools is
    (fswkit.autocode.diagnostics.read_input): a FIFO, a device or a file
    over MAX_INPUT bytes is refused unread."""
    from fswkit.autocode.diagnostics import read_input

    try:
        raw = read_input(path)
    except FileNotFoundError:
        raise EngError([f"{path}: no such motor file"]) from None
    except IsADirectoryError:
        raise EngError([f"{path}: a folder, not a motor file"]) from None
    except OSError as e:
        raise EngError([f"{path}: {e.strerror or e}"]) from None
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):  # a UTF-16 byte-order mark: every other byte is 0
        raise EngError([f"{path}:1:1: UTF-16 text (Notepad's \"Unicode\"): save the motor file as UTF-8 or ASCII "
                        "text"])
    if b"\0" in raw:
        line = raw[:raw.index(b"\0")].count(b"\n") + 1
        raise EngError([f"{path}:{line}:1: a binary file, not a RASP motor file (text)"])
    if raw.startswith(b"\xef\xbb\xbf"):  # the byte-order mark a Windows editor writes: not the file's text
        raw = raw[3:]
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")  # older files carry a maker's name or a comment in Latin-1
    return parse(text, path)
