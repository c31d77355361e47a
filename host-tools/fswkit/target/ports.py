"""Serial port discovery (`fsw ports`) and the default port of `fsw flash`
and `fsw monitor`: pyserial's list_ports, with a guess at the board behind
each USB port from its vendor and product IDs."""

from __future__ import annotations

from dataclasses import dataclass

# USB (VID, PID) -> (what it is, the kit's boards it can be). Genuine boards
# from the Arduino AVR core's boards.txt; USB-serial chips of Nanos and clones.
KNOWN_USB: dict[tuple[int, int], tuple[str, tuple[str, ...]]] = {
    (0x2341, 0x0043): ("Arduino Uno", ("uno",)),
    (0x2341, 0x0001): ("Arduino Uno", ("uno",)),
    (0x2A03, 0x0043): ("Arduino Uno", ("uno",)),
    (0x2341, 0x0243): ("Arduino Uno", ("uno",)),
    (0x2341, 0x006A): ("Arduino Uno", ("uno",)),
    (0x2341, 0x0010): ("Arduino Mega 2560", ("mega2560",)),
    (0x2341, 0x0042): ("Arduino Mega 2560", ("mega2560",)),
    (0x2A03, 0x0010): ("Arduino Mega 2560", ("mega2560",)),
    (0x2A03, 0x0042): ("Arduino Mega 2560", ("mega2560",)),
    (0x2341, 0x0210): ("Arduino Mega 2560", ("mega2560",)),
    (0x2341, 0x0242): ("Arduino Mega 2560", ("mega2560",)),
    (0x0403, 0x6001): ("FTDI FT232R USB-serial (Arduino Nano, older boards)", ("nano", "uno", "mega2560")),
    (0x1A86, 0x7523): ("CH340 USB-serial (Nano and Uno clones)", ("nano", "uno", "mega2560")),
    (0x10C4, 0xEA60): ("CP210x USB-serial (clones)", ("nano", "uno", "mega2560")),
}


class PortError(Exception):
    """No usable port, or no single one to default to: the message says why."""


@dataclass(frozen=True)
class Port:
    device: str
    description: str
    vid: int | None
    pid: int | None
    serial_number: str | None

    @property
    def usb(self) -> str:
        return f"{self.vid:04x}:{self.pid:04x}" if self.vid is not None and self.pid is not None else ""

    @property
    def guess(self) -> str:
        """What the port probably is: a board, a USB-serial chip, or the OS's description."""
        known = KNOWN_USB.get((self.vid, self.pid)) if self.vid is not None else None
        if known:
            return known[0]
        return self.description if self.description and self.description != "n/a" else ""

    @property
    def boards(self) -> tuple[str, ...]:
        """The kit's boards this port can be (empty: no idea)."""
        known = KNOWN_USB.get((self.vid, self.pid)) if self.vid is not None else None
        return known[1] if known else ()

    def label(self) -> str:
        parts = [p for p in (self.guess, f"USB {self.usb}" if self.usb else "") if p]
        return f"{self.device} ({', '.join(parts)})" if parts else self.device


def list_ports(include_all: bool = False) -> list[Port]:
    """Serial ports, sorted by device name. Candidates (the default) are USB
    ports, where boards appear; `include_all` adds the others (built-in UARTs)."""
    try:
        from serial.tools import list_ports as lp
    except ImportError:
        raise PortError("pyserial is not installed: run `make setup` (or pip install pyserial)") from None
    ports = [Port(p.device, p.description or "", p.vid, p.pid, p.serial_number) for p in lp.comports()]
    if not include_all:
        ports = [p for p in ports if p.vid is not None]
    return sorted(ports, key=lambda p: p.device)


def default_port(port: str | None, command: str) -> tuple[str, Port | None]:
    """The port a command uses: the one named, else the only candidate.
    Returns (device, its listing if known); PortError when there is no
    candidate or several."""
    if port:
        found = [p for p in _safe_list() if p.device == port]
        return port, (found[0] if found else None)
    candidates = list_ports()
    if len(candidates) == 1:
        return candidates[0].device, candidates[0]
    if not candidates:
        raise PortError("no serial port found: connect the board by USB (`fsw ports` lists what is "
                        "connected), or name the port with --port")
    names = ", ".join(p.label() for p in candidates)
    raise PortError(f"{len(candidates)} serial ports found ({names}): choose one with --port")


def _safe_list() -> list[Port]:
    try:
        return list_ports(include_all=True)
    except PortError:
        return []


def format_table(ports: list[Port]) -> str:
    """`fsw ports` output: device, what it seems to be, USB IDs, the kit's boards."""
    rows = [("PORT", "WHAT IT SEEMS TO BE", "USB ID", "BOARD")]
    for p in ports:
        rows.append((p.device, p.guess or "-", p.usb or "-", " or ".join(p.boards) or "-"))
    widths = [max(len(r[i]) for r in rows) for i in range(3)]
    return "\n".join(f"{r[0]:<{widths[0]}}  {r[1]:<{widths[1]}}  {r[2]:<{widths[2]}}  {r[3]}".rstrip()
                     for r in rows) + "\n"
