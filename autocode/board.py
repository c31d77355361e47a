"""Board definitions (`boards/<name>.toml`): what the checker, the code
generator and the build need to know about a board."""

from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass, field

from .diagnostics import read_input

from .kit import BOARDS as BOARDS_DIR, board_names


@dataclass(frozen=True)
class Board:
    name: str
    mcu: str
    f_cpu: int
    flash: int
    ram: int
    eeprom: int
    real: str  # evaluation type R: "f32" or "f64"
    digital_pins: frozenset[int]
    analog_pins: dict[str, int]  # "A0" -> pin number
    pwm_pins: frozenset[int]
    reserved: dict[int, str]  # pin -> why it is reserved
    adc_bits: int
    adc_vref: float
    # the timer the executor keeps (`executor.timer`), and the PWM pins it
    # takes from analog outputs (`executor.timer_pins`)
    timer: str = ""
    timer_pins: frozenset[int] = frozenset()
    # pins the board's bootloader drives high at a reset, before the firmware
    # runs (`pins.boot_driven`): pin -> what drives it
    boot_driven: dict[int, str] = field(default_factory=dict, compare=False)
    # pin -> (port letter, bit) on an AVR board's MCU (`arduino.ports`); empty
    # when the board file does not say (channels then go through pin numbers)
    ports: dict[int, tuple[str, int]] = field(default_factory=dict, compare=False)
    raw: dict = field(default_factory=dict, compare=False, repr=False)  # the whole definition

    def pin(self, text: str) -> int | None:
        """The pin number a table names (`A0`, `4`), or None."""
        if text in self.analog_pins:
            return self.analog_pins[text]
        if text.isdigit() and text.isascii() and len(text) <= 3:  # pins are 0..255 (a 5,000-digit int() raises)
            n = int(text)
            if n in self.digital_pins or n in self.reserved or n in self.analog_pins.values():
                return n
        return None

    @property
    def is_avr(self) -> bool:
        return self.raw.get("board", {}).get("arch") == "avr"


class BoardError(Exception):
    pass


def load_board(name: str) -> Board:
    """The named board; BoardError (with the known names) when there is none."""
    path = os.path.join(BOARDS_DIR, name + ".toml")
    if not name.replace("_", "").isalnum() or not os.path.isfile(path):
        known = ", ".join(board_names()) or "none"
        raise BoardError(f"unknown board `{name}` (known boards: {known})")
    try:
        d = tomllib.loads(read_input(path).decode("utf-8"))
        return board_from_dict(name, d)
    except (OSError, tomllib.TOMLDecodeError, KeyError, TypeError, ValueError) as e:
        raise BoardError(f"board definition {path} is unreadable: {e}") from e


U32_MAX = (1 << 32) - 1


def _int(v, where: str, lo: int, hi: int) -> int:
    """A whole-number field of a definition, in range: TOML integers have no
    bound and a float or `true` is no count (ValueError naming the field)."""
    if type(v) is not int or not lo <= v <= hi:
        raise ValueError(f"`{where}` must be an integer from {lo:,} to {hi:,}, found {v!r}")
    return v


def _volts(v, where: str) -> float:
    """A voltage field: a finite positive number (TOML floats include `inf`,
    `nan` and `1e400`, which reads as infinity)."""
    if type(v) not in (int, float) or not math.isfinite(v) or not 0 < v <= 1000:
        raise ValueError(f"`{where}` must be a number of volts above 0 and at most 1000, found {v!r}")
    return float(v)


def board_from_dict(name: str, d: dict) -> Board:
    """A Board from a parsed definition (fields: docs/boards.md); every
    number range-checked (ValueError naming the field)."""
    pins = d["pins"]
    b = d["board"]
    mem = d["memory"]
    real = d["eval"]["R"]
    if real not in ("f32", "f64"):
        raise ValueError(f"`eval.R` must be \"f32\" or \"f64\", found {real!r}")
    if "baud" in d.get("upload", {}):
        _int(d["upload"]["baud"], "upload.baud", 0, 10_000_000)  # 0: nothing to upload (native)
    pin = lambda v, where: _int(v, where, 0, 255)  # noqa: E731
    return Board(
        name=b.get("name", name),
        mcu=b["mcu"],
        f_cpu=_int(b["f_cpu"], "board.f_cpu", 0, U32_MAX),
        flash=_int(mem.get("flash_usable", mem["flash"]), "memory.flash_usable", 0, U32_MAX),
        ram=_int(mem["ram"], "memory.ram", 0, U32_MAX),
        eeprom=_int(mem.get("eeprom", 0), "memory.eeprom", 0, U32_MAX),
        real=real,
        digital_pins=frozenset(pin(p, "pins.digital") for p in pins["digital"]),
        analog_pins={k: pin(v, f"pins.analog.{k}") for k, v in pins["analog"].items()},
        pwm_pins=frozenset(pin(p, "pins.pwm") for p in pins.get("pwm", [])),
        reserved={pin(r["pin"], "pins.reserved.pin"): str(r["reason"]) for r in pins.get("reserved", [])},
        adc_bits=_int(d["adc"]["bits"], "adc.bits", 1, 16),
        adc_vref=_volts(d["adc"]["vref"], "adc.vref"),
        timer=str(d.get("executor", {}).get("timer", "")),
        timer_pins=frozenset(pin(p, "executor.timer_pins") for p in d.get("executor", {}).get("timer_pins", [])),
        ports=_ports(d.get("arduino", {}).get("ports", [])),
        boot_driven={pin(r["pin"], "pins.boot_driven.pin"): str(r["reason"]) for r in pins.get("boot_driven", [])},
        raw=d,
    )


def _ports(names: list) -> dict[int, tuple[str, int]]:
    """`arduino.ports` ("D5": port D, bit 5; "" for a pin with no port) as
    {pin: (port, bit)}."""
    out = {}
    for pin, name in enumerate(names):
        if name == "":
            continue
        if not (isinstance(name, str) and len(name) == 2 and "A" <= name[0] <= "L" and "0" <= name[1] <= "7"):
            raise ValueError(f"arduino.ports[{pin}] = {name!r}: expected a port letter and a bit, like \"D5\"")
        out[pin] = (name[0], int(name[1]))
    return out
