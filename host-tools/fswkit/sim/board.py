"""The simulated board: a firmware ELF running on simavr, driven from Python.

`SimBoard` starts the harness (`harness.c`, compiled with the host's gcc
against libsimavr on first use and cached like the native runner) and speaks
its control protocol (docs/sim.md): advance simulated time in lock-step or let
the board run free, set analog inputs in volts, read and drive digital pins,
timestamp pin edges in cycles, read PWM duty, exchange UART bytes through the
control channel or a pseudo-terminal, and read simulated time and cycles.

    with SimBoard("examples/tank/build/uno/tank.elf", "uno") as b:
        b.set_analog("A0", 3.7)          # 800 psi
        b.run_for(0.1)                   # simulated seconds
        assert b.digital(4)              # the vent valve is open

`fsw sim` (`main`) builds a project, bridges UART0 to a pty and runs the
board in real time until Ctrl-C or `--duration`.
"""

from __future__ import annotations

import functools
import hashlib
import io
import os
import re
import shutil
import struct
import subprocess
import tempfile
from dataclasses import dataclass
from typing import NamedTuple

from fswkit.autocode.board import Board, BoardError, load_board
from fswkit.autocode.diagnostics import read_head

HERE = os.path.dirname(os.path.abspath(__file__))
HARNESS_SRC = os.path.join(HERE, "harness.c")
CC = os.environ.get("CC", "gcc")
CFLAGS = ["-std=gnu11", "-O2", "-Wall", "-Wextra"]  # the tests add -Werror
LIBS = ["-lsimavr", "-lutil"]
# simavr linked in whole (libsimavr-dev's libsimavr.a, not position
# independent, so the harness is not either): its calls are direct, not
# through the shared library's tables, and a simulated second costs about
# 15 % less than with libsimavr.so. The shared library is the fallback.
LIBS_STATIC = ["-no-pie", "-Wl,-Bstatic", "-lsimavr", "-Wl,-Bdynamic", "-l:libelf.so.1", "-lutil"]
SIMAVR_HEADER = "/usr/include/simavr/sim_avr.h"
ARDUINO = "/usr/share/arduino/hardware/arduino/avr"
PROTO_VERSION = 1

# AVR ELF e_flags architecture numbers (binutils' EF_AVR_MACH) of the MCUs
# the boards use: an ELF built for another MCU class is refused up front.
AVR_ARCH = {"atmega328p": 5, "atmega168": 5, "atmega2560": 6, "atmega1280": 5}
AVR_ARCH_NAMES = {2: "avr2", 25: "avr25", 3: "avr3", 31: "avr31", 35: "avr35", 4: "avr4", 5: "avr5",
                  51: "avr51", 6: "avr6", 100: "avrtiny", 102: "avrxmega2", 104: "avrxmega4",
                  106: "avrxmega6"}

# PWM outputs of the Arduino timers: timer channel (as pins_arduino.h names
# it) -> (TCCRnA data address, its COMnx1 bit, OCRnx data address). The
# addresses are those of the ATmega328P and ATmega2560 datasheets (equal
# where both MCUs have the timer).
TIMER_CHANNELS = {
    "TIMER0A": (0x44, 7, 0x47), "TIMER0B": (0x44, 5, 0x48),
    "TIMER1A": (0x80, 7, 0x88), "TIMER1B": (0x80, 5, 0x8A), "TIMER1C": (0x80, 3, 0x8C),
    "TIMER2A": (0xB0, 7, 0xB3), "TIMER2B": (0xB0, 5, 0xB4),
    "TIMER3A": (0x90, 7, 0x98), "TIMER3B": (0x90, 5, 0x9A), "TIMER3C": (0x90, 3, 0x9C),
    "TIMER4A": (0xA0, 7, 0xA8), "TIMER4B": (0xA0, 5, 0xAA), "TIMER4C": (0xA0, 3, 0xAC),
    "TIMER5A": (0x120, 7, 0x128), "TIMER5B": (0x120, 5, 0x12A), "TIMER5C": (0x120, 3, 0x12C),
}

STOP_REASONS = ("target", "sim-limit", "wall-limit", "done", "crashed", "interrupted")
# What `reset` can simulate, and the MCUSR flag each leaves (ATmega328P/2560).
RESET_CAUSES = ("brownout", "watchdog", "external", "power")
RESET_FLAGS = {"power": 0x01, "external": 0x02, "brownout": 0x04, "watchdog": 0x08}


class SimError(Exception):
    """The board cannot be simulated as asked (a message for the user)."""


class EdgeOverflow(SimError):
    """The board recorded more pin edges than it keeps (1,048,576) since they were last read."""


# ---- the harness ------------------------------------------------------------------

def cache_dir() -> str:
    base = os.environ.get("FSW_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "fswkit")
    return os.path.join(base, "sim")


def harness() -> str:
    """The harness executable, compiled on first use and cached by the hash
    of its source, compiler (its identity) and command. The compile runs in
    a temporary folder removed however it ends (native.removed_when_done)."""
    from fswkit.run.native import compiler_identity, private_tmp, removed_when_done, sweep

    with open(HARNESS_SRC, "rb") as f:
        src = f.read()
    command = [compiler_identity(CC), CC] + CFLAGS + LIBS_STATIC + LIBS
    h = hashlib.sha256(src + "\0".join(command).encode()).hexdigest()[:20]
    out = os.path.join(cache_dir(), h)
    exe = os.path.join(out, "simboard")
    if os.path.exists(exe):
        return exe
    if shutil.which(CC) is None:
        raise SimError(f"no host C compiler `{CC}` to build the simulated board (install gcc, or set CC)")
    if not os.path.exists(SIMAVR_HEADER):
        raise SimError("simavr's development files are missing: install libsimavr-dev (`make setup`)")
    sweep(cache_dir())
    tmp = private_tmp(out)
    with removed_when_done(tmp):
        try:
            os.makedirs(tmp, exist_ok=True)
        except OSError as e:
            raise SimError(f"cannot create the simulated board's cache folder {tmp}: {e.strerror or e} "
                           "(set FSW_CACHE_DIR to a writable folder)") from None
        for libs in (LIBS_STATIC, LIBS):
            r = subprocess.run([CC] + CFLAGS + [HARNESS_SRC, "-o", os.path.join(tmp, "simboard")] + libs,
                               capture_output=True, text=True)
            if r.returncode == 0:
                break
        if r.returncode != 0:
            raise SimError("the simulated board did not compile against this machine's simavr:\n" + r.stderr[-3000:])
        try:
            os.replace(tmp, out)
        except OSError:  # another process built it first
            pass
    return exe


# ---- boards and pins ----------------------------------------------------------------

def sim_board(board: str | Board) -> Board:
    """A board that has a simulated MCU; SimError otherwise."""
    if isinstance(board, str):
        try:
            board = load_board(board)
        except BoardError as e:
            raise SimError(str(e)) from None
    if not board.raw.get("sim", {}).get("simavr_mcu"):
        raise SimError(f"board `{board.name}` has no simulated MCU (its [sim] simavr_mcu is empty): "
                       "simulate an AVR board such as uno or mega2560")
    return board


@dataclass(frozen=True)
class PinMap:
    """Where a board's Arduino pins are on the MCU, from the Arduino core's
    pins_arduino.h for the board's variant (the table the firmware is built
    with)."""

    digital: dict[int, tuple[str, int]]  # pin -> (port letter, bit)
    timers: dict[int, str]  # PWM pin -> timer channel (TIMER0A ...)
    analog: dict[str, int]  # "A0" -> ADC channel

    def pin_of(self, port: str, bit: int) -> int | None:
        for p, pb in self.digital.items():
            if pb == (port, bit):
                return p
        return None


def _array(text: str, name: str) -> list[str]:
    m = re.search(r"\b" + name + r"\s*\[\s*\]\s*=\s*\{(.*?)\}\s*;", text, re.S)
    if not m:
        raise SimError(f"pins_arduino.h has no {name}")
    body = re.sub(r"/\*.*?\*/", "", m.group(1), flags=re.S)
    body = re.sub(r"//[^\n]*", "", body)
    return [t.strip() for t in body.split(",") if t.strip()]


@functools.lru_cache(maxsize=None)
def _variant_tables(mcu: str, variant: str) -> tuple[tuple, tuple, tuple]:
    vdir = os.path.join(ARDUINO, "variants", variant)
    if not os.path.isfile(os.path.join(vdir, "pins_arduino.h")):
        raise SimError(f"the Arduino core's variant `{variant}` is not installed ({vdir}): run `make setup`")
    if shutil.which("avr-gcc") is None:
        raise SimError("`avr-gcc` is not installed: run `make setup` (or tools/bootstrap.sh)")
    # Conditionals resolved for this MCU, macros left as written.
    r = subprocess.run(["avr-gcc", "-E", "-fdirectives-only", f"-mmcu={mcu}", "-DARDUINO_MAIN", "-I", vdir,
                        "-I", os.path.join(ARDUINO, "cores", "arduino"), "-x", "c++", "-"],
                       input="#include <pins_arduino.h>\n", capture_output=True, text=True)
    if r.returncode != 0:
        raise SimError(f"cannot read the pin table of variant `{variant}`: {r.stderr.strip()[-500:]}")
    return (tuple(_array(r.stdout, "digital_pin_to_port_PGM")), tuple(_array(r.stdout, "digital_pin_to_bit_mask_PGM")),
            tuple(_array(r.stdout, "digital_pin_to_timer_PGM")))


def pin_map(board: Board) -> PinMap:
    ports, masks, timers = _variant_tables(board.raw["sim"]["simavr_mcu"],
                                           board.raw.get("arduino", {}).get("variant") or "standard")
    digital, pwm = {}, {}
    for pin, (port, mask) in enumerate(zip(ports, masks)):
        pm = re.fullmatch(r"P([A-L])", port)
        bm = re.fullmatch(r"_BV\(\s*(\d)\s*\)", mask)
        if pm is None or bm is None:  # NOT_A_PORT and the like
            continue
        digital[pin] = (pm.group(1), int(bm.group(1)))
        if pin < len(timers) and timers[pin] in TIMER_CHANNELS:
            pwm[pin] = timers[pin]
    analog = {}
    for name in board.analog_pins:
        m = re.fullmatch(r"A(\d+)", name)
        if m:
            analog[name] = int(m.group(1))
    return PinMap(digital, pwm, analog)


# ---- ELF checks -----------------------------------------------------------------------

def check_elf(path: str, mcu: str) -> None:
    """SimError unless `path` is an AVR ELF executable for `mcu`'s class."""
    try:
        head = read_head(path, 52)
    except FileNotFoundError:
        raise SimError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise SimError(f"{path}: a folder, not a firmware ELF") from None
    except OSError as e:
        raise SimError(f"{path}: {e.strerror or e}") from None
    if len(head) < 52 or head[:4] != b"\x7fELF":
        raise SimError(f"{path}: not an ELF file (a firmware .elf from `fsw build` is needed)")
    if head[4] != 1 or head[5] != 1:
        raise SimError(f"{path}: not a 32-bit little-endian ELF, so not AVR firmware")
    e_type, e_machine = struct.unpack_from("<HH", head, 16)
    (e_flags,) = struct.unpack_from("<I", head, 36)
    if e_machine != 83:
        raise SimError(f"{path}: an ELF for another processor (machine {e_machine}), not AVR firmware")
    if e_type != 2:
        raise SimError(f"{path}: an AVR object file, not a linked firmware executable")
    arch = e_flags & 0x7F
    want = AVR_ARCH.get(mcu)
    if want is not None and arch and arch != want:
        raise SimError(f"{path}: built for {AVR_ARCH_NAMES.get(arch, f'AVR architecture {arch}')}, "
                       f"not for the {mcu} ({AVR_ARCH_NAMES[want]}): build it for this board")


# ---- the board ------------------------------------------------------------------------

@dataclass(frozen=True)
class RunResult:
    """Where a run stopped: the cycle, simulated seconds, the CPU's state
    (running, sleeping, done, crashed) and why (one of STOP_REASONS)."""

    cycle: int
    time: float
    state: str
    stop: str


_new = object.__new__


@dataclass(frozen=True)
class Edge:
    cycle: int
    pin: int | None  # Arduino pin number (None: a port bit no pin maps to)
    port: str
    bit: int
    level: bool


class Batch(NamedTuple):
    """What one `batch` step returns: where the run stopped, the watched
    pins' edges during it (oldest first) and the UART's bytes. (A named
    tuple: made once a co-simulation step, it is the cheapest record.)"""

    run: RunResult
    edges: list[Edge]
    uart: bytes
    guard: bytes = b""  # the guarded RAM bytes after the run (`guard`), when any are


@dataclass(frozen=True)
class RamUsage:
    """RAM of the firmware in bytes: its static data (.data, .bss, .noinit),
    the deepest the stack has reached so far, their sum, and the MCU's RAM."""

    static: int
    stack: int
    total: int
    ram: int


@dataclass(frozen=True)
class FunctionProfile:
    """Calls of one profiled function and the cycles they took (interrupts
    taken during a call included)."""

    entry: int  # byte address in flash
    calls: int
    total: int
    worst: int


@dataclass(frozen=True)
class Profile:
    """What `prof` measured since profiling started: cycles the core slept,
    the frames (a frame runs from the start of the first profiled function to
    the end of the last profiled call before it starts again: one executor
    cycle when that function is the first task), and each function's calls."""

    sleep: int
    frames: int
    frame_total: int
    frame_worst: int
    frame_worst_at: int  # the cycle the worst frame started at
    functions: tuple[FunctionProfile, ...]


# The byte fswkit firmware paints its free RAM with at boot
# (FSW_STACK_PAINT_BYTE, firmware/src/psl_arduino.cpp).
STACK_PAINT = 0xC5
PEEK_MAX = 4096  # bytes per `peek` command


def link_problem(path: str) -> str | None:
    """What forbids making `path` the symbolic link to the board's pty, or
    None. Only a path with nothing there, or a stale link of a simulated
    board (a symbolic link to a pseudo-terminal that is gone), may be used:
    whatever else is there is never removed."""
    if not path:
        return "--link needs a path (the symbolic link to make)"
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        return f"--link {path}: no such folder {folder}"
    if not os.path.lexists(path):
        return None
    if os.path.islink(path):
        target = os.readlink(path)
        if re.fullmatch(r"/dev/pts/[0-9]+", target):
            if not os.path.exists(target):
                return None  # a link a board left behind: its pty is gone
            return (f"--link {path}: it links to {target}, a pseudo-terminal that is open (another simulated "
                    "board's?): stop that board, or remove the link if it is stale")
        return f"--link {path}: a symbolic link to {target} is there: it is never replaced; choose another path"
    what = "a folder" if os.path.isdir(path) else "a file"
    return f"--link {path}: {what} is there: it is never replaced; choose another path"


def _fields(line: str) -> dict[str, str]:
    return dict(t.split("=", 1) for t in line.split()[1:] if "=" in t)


class SimBoard:
    """A simulated board running one firmware ELF (see the module docstring).

    uart: "control" (bytes through `uart_read`/`uart_write`), "pty" (a
    pseudo-terminal whose path is `port`) or "none". sim_limit / wall_limit:
    seconds of simulated time / of wall-clock time since start after which
    every run stops (None: no limit). analog: initial volts per analog pin,
    set before the first instruction runs. link: with a pty, also make this
    path a symbolic link to it. spi_flash: an SPI NOR flash chip (a
    W25Q64JV's commands and timing) on the MCU's SPI with its chip select on
    this port pin, and optionally its size in bytes ("B2", "B2:1048576"; 8
    MiB by default). flash_file / eeprom_file: files that keep the flash's /
    the EEPROM's bytes between runs (read at start if present, written when
    the board closes). ram_seed: the seed of the pseudo-random bytes a
    `reset("power")` leaves in RAM (the same seed, the same bytes). parts:
    sensors on the MCU's I2C (TWI) or SPI, each (kind, where): a kind of
    `PART_KINDS` and its 7-bit I2C address, or for a part with SPI its chip
    select's port pin (`[("bmp280", 0x76), ("mpu6050", 0x68), ("adxl345",
    "B1")]`; harness `-I`, docs/sim.md "Parts on I2C and SPI"); the `part_*`
    methods drive them.
    """

    def __init__(self, elf: str, board: str | Board = "uno", *, uart: str = "control",
                 sim_limit: float | None = None, wall_limit: float | None = None,
                 analog: dict[str, float] | None = None, link: str | None = None, f_cpu: int | None = None,
                 eeprom: bytes | None = None, spi_flash: str | None = None, flash_file: str | None = None,
                 eeprom_file: str | None = None, ram_seed: int = 1,
                 parts: list[tuple[str, int | str]] | None = None):
        self.board = sim_board(board)
        self.mcu = self.board.raw["sim"]["simavr_mcu"]
        self.f_cpu = int(f_cpu or self.board.f_cpu)
        self.pins = pin_map(self.board)
        self._names: dict = {}  # ("a" | "d" | "p", an input) -> its name in a `batch` line (_batch_line)
        if uart not in ("control", "pty", "none"):
            raise ValueError(f"uart must be control, pty or none, not {uart!r}")
        self.uart = uart
        check_elf(elf, self.mcu)
        self.elf = elf
        args = [harness(), "-c", "-m", self.mcu, "-f", str(self.f_cpu), "-u", uart]
        if sim_limit is not None:
            args += ["-t", repr(float(sim_limit))]
        if wall_limit is not None:
            args += ["-w", repr(float(wall_limit))]
        if link:
            problem = link_problem(link)
            if problem is not None:
                raise SimError(problem)
            args += ["-l", link]
        for pin, volts in (analog or {}).items():
            args += ["-a", f"{self.adc_channel(pin)}={self._millivolts(volts)}"]
        if flash_file is not None and spi_flash is None:
            raise ValueError("flash_file keeps the SPI flash's bytes: it needs spi_flash")
        if spi_flash is not None:
            args += ["-s", str(spi_flash)]
        if flash_file is not None:
            args += ["-S", os.fspath(flash_file)]
        if eeprom_file is not None:
            args += ["-E", os.fspath(eeprom_file)]
        for kind, where in parts or ():
            if kind not in PART_KINDS:
                raise ValueError(f"a part is one of {', '.join(PART_KINDS)}, not {kind!r}")
            args += ["-I", f"{kind}@{_part_id(where)}"]
        if int(ram_seed) != 1:
            if not 0 <= int(ram_seed) < 1 << 64:
                raise ValueError(f"ram_seed must be a whole number from 0 to 2**64 - 1, not {ram_seed}")
            args += ["-R", str(int(ram_seed))]
        self._err = tempfile.TemporaryFile()
        try:
            self._proc = subprocess.Popen(args + [elf], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                          stderr=self._err, bufsize=0, process_group=0)
        except OSError as e:
            self._err.close()
            raise SimError(f"cannot start the simulated board: {e.strerror or e}") from None
        # Responses are read through a buffer: readline on the raw pipe costs a
        # system call per byte, ten times the round trip itself.
        self._out = io.BufferedReader(self._proc.stdout, 65536)
        self._closed = False
        try:
            f = _fields(self._read())
            if f.get("proto") != str(PROTO_VERSION):
                raise SimError(f"the simulated board speaks protocol {f.get('proto')}, not {PROTO_VERSION}")
        except BaseException:
            self.close()
            raise
        self.port: str | None = f.get("port")
        self.cycle = 0
        if eeprom:  # programmed before the firmware's first instruction (fsw sim --fw-params)
            self.eeprom_write(0, eeprom)

    # -- plumbing --
    def _stderr(self) -> str:
        try:
            self._err.seek(0)
            return self._err.read().decode(errors="replace").strip()
        except (OSError, ValueError):
            return ""

    def _read(self) -> str:
        """The next response; SimError for an `err` response."""
        text = self._read_line()
        if text.startswith("err"):
            raise SimError(text[4:])
        return text

    def _read_line(self) -> str:
        line = self._out.readline()
        if not line:
            code = self._proc.wait()
            msg = self._stderr() or f"the simulated board exited (status {code})"
            self._closed = True
            raise SimError(msg.replace("simboard: ", "", 1) if msg.startswith("simboard: ") else msg)
        return line.decode(errors="replace").rstrip("\n")

    def _send(self, text: str) -> None:
        if self._closed:
            raise SimError("the simulated board has stopped")
        try:
            self._proc.stdin.write(text.encode())
        except (BrokenPipeError, OSError):
            self._read()  # raises with the board's last words
            raise SimError("the simulated board went away")

    def command(self, line: str) -> str:
        """Sends one protocol command; returns its `ok ...` response."""
        self._send(line + "\n")
        return self._read()

    def exchange(self, lines: list[str]) -> list[str]:
        """Sends several commands in one write and reads their responses:
        one pipe round trip for a whole co-simulation step."""
        self._send("".join(line + "\n" for line in lines))
        out = [self._read_line() for _ in lines]  # all of them, so the channel stays in step
        for line in out:
            if line.startswith("err"):
                raise SimError(line[4:])
        return out

    def _run_result(self, line: str) -> RunResult:
        f = _fields(line)
        self.cycle = int(f["cycle"])
        return RunResult(self.cycle, float(f["time"]), f["state"], f["stop"])

    def _edges(self, toks: list[str]) -> list[Edge]:
        """Edges from the `n=K overflow=F PB@CYCLE=L ...` words of an
        `edges` or `batch` response; EdgeOverflow if the board lost some."""
        out = []
        for t in toks:
            if t.startswith("overflow="):
                if t != "overflow=0":
                    raise EdgeOverflow("more than 1,048,576 edges since the last read: read edges more often")
            elif "@" in t:
                where, rest = t.split("@")
                cycle, level = rest.split("=")
                port, bit = where[0], int(where[1:])
                out.append(Edge(int(cycle), self.pins.pin_of(port, bit), port, bit, level == "1"))
        return out

    # -- time --
    @property
    def time(self) -> float:
        """Simulated seconds since reset (as of the last run)."""
        return self.cycle / self.f_cpu

    def cycles_for(self, seconds: float) -> int:
        return int(round(seconds * self.f_cpu))

    def step(self, cycles: int, analog: dict[str, float] | None = None) -> RunResult:
        """Sets analog inputs (volts), then runs `cycles` more cycles, in one round trip."""
        lines = [f"adc {self.adc_channel(p)} {self._millivolts(v)}" for p, v in (analog or {}).items()]
        lines.append(f"step {int(cycles)}")
        return self._run_result(self.exchange(lines)[-1])

    def until(self, cycle: int) -> RunResult:
        """Runs until the absolute cycle count `cycle`."""
        return self._run_result(self.command(f"until {int(cycle)}"))

    def run_for(self, seconds: float) -> RunResult:
        return self.step(self.cycles_for(seconds))

    def batch(self, until: int, analog: dict[str, float] | None = None,
              digital: dict[int, bool] | None = None,
              parts: dict[int | str, dict[str, int]] | None = None) -> Batch:
        """One lock-step of a co-simulation in one command and one round
        trip: sets analog inputs (volts), then drives digital input pins,
        then sets parts' raw counts (`{0x76: {"adc_P": 415148}, "B1": {"z":
        256}}`: by I2C address or SPI chip-select port pin, the names
        `part_raw` takes; latched by each part's next conversion to end),
        runs to the absolute cycle `until`, and returns the run's result with
        the watched pins' edges and the UART's bytes since the last read
        (what `set_analog`s, `set_digital`s, `part_raw`s, `until`, `edges`
        and `uart_read` do in turn)."""
        self._send(self._batch_line("batch", until, analog, digital, parts))
        return self._batch_result(self._read())

    def batches(self, steps: list[tuple]) -> list[Batch | None]:
        """Several lock-steps in one write, their inputs worked out ahead:
        `steps` is a list of `batch`'s arguments, (until, analog, digital,
        parts). The first runs as `batch` does; each later one runs only if
        no step before it in the list saw a watched pin's edge, a change of
        the guarded RAM bytes (`guard`) or a stop short of its cycle, and is
        None otherwise (the board did nothing for it). A co-simulation whose
        plant reacts to the firmware's outputs works its plant out again
        from the last step run."""
        self.batches_send(steps)
        return self.batches_read(len(steps))

    def batches_send(self, steps: list[tuple], chained: bool = False) -> None:
        """The first half of `batches`: sends the steps and returns at once
        (the board works on them meanwhile). `chained`: every step is a
        `batch?`, so none runs if the run of steps the write before began
        has stopped. Read the responses with `batches_read`, in order."""
        self._send("".join(self._batch_line("batch?" if i or chained else "batch", *step)
                           for i, step in enumerate(steps)))

    def batches_read(self, count: int) -> list[Batch | None]:
        """The responses of `count` steps sent with `batches_send`."""
        lines = [self._read_line() for _ in range(count)]  # every response, so the channel stays in step
        for line in lines:
            if line.startswith("err"):
                raise SimError(line[4:])
        return [None if line == "skip" else self._batch_result(line) for line in lines]

    def guard(self, addr: int, size: int) -> None:
        """RAM bytes (data addresses, up to 8; size 0: none) whose change ends
        a `batches` run after the step that changed them; each step's
        `Batch.guard` holds their value after it."""
        self.command(f"guard {int(addr)} {int(size)}")

    def _batch_line(self, word: str, until: int, analog=None, digital=None, parts=None) -> str:
        line = f"{word} {int(until)}"
        # each input's name in the protocol, looked up once (a co-simulation sends a line a plant step)
        names = self._names
        if analog:
            for p, v in analog.items():
                name = names.get(("a", p))
                if name is None:
                    name = names["a", p] = f" {self.adc_channel(p)}="
                line += f"{name}{self._millivolts(v)}"
        if digital:
            for pin, level in digital.items():
                name = names.get(("d", pin))
                if name is None:
                    port, bit = self._port_bit(pin)
                    name = names["d", pin] = f" {port}{bit}="
                line += f"{name}{1 if level else 0}"
        if parts:
            for where, values in parts.items():
                if values:
                    name = names.get(("p", where))
                    if name is None:
                        name = names["p", where] = f" @{_part_id(where)}:"
                    line += name + ",".join([f"{k}={int(v)}" for k, v in values.items()])
        return line + "\n"

    def _batch_result(self, text: str) -> Batch:
        # `ok cycle=C time=S state=ST stop=R uart=HEX n=K overflow=F EDGE... [guard=HEX]`, read
        # by position: one step of a co-simulation, kept cheap
        toks = text.split(" ")
        self.cycle = cycle = int(toks[1][6:])
        # the frozen dataclass's fields set as its __init__ would, without its four object.__setattr__ calls
        run = _new(RunResult)
        d = run.__dict__
        d["cycle"], d["time"], d["state"], d["stop"] = cycle, float(toks[2][5:]), toks[3][6:], toks[4][5:]
        guard = b""
        if toks[-1].startswith("guard="):
            guard = bytes.fromhex(toks.pop()[6:])
        edges = self._edges(toks[7:]) if toks[6] != "n=0" or toks[7] != "overflow=0" else []
        return Batch(run, edges, bytes.fromhex(toks[5][5:]), guard)

    def reset(self, cause: str = "brownout") -> None:
        """Resets the MCU for `cause`, one of RESET_CAUSES: "brownout" (the
        default), "watchdog", "external" (the reset pin) or "power" (a
        power-on). The firmware starts again from its reset vector with its
        I/O as at power-on and MCUSR holding that cause's flag alone (BORF,
        WDRF, EXTRF, PORF); the cycle count goes on. RAM keeps its bytes,
        except after "power", which fills it with pseudo-random bytes from
        `ram_seed` (nothing kept in RAM survives a power-on). After
        "watchdog" the watchdog runs at its shortest period, as on the part.
        Inputs driven from outside read their power-on levels until set
        again."""
        if cause not in RESET_CAUSES:
            raise ValueError(f"reset cause {cause!r}: one of {', '.join(RESET_CAUSES)}")
        self.command(f"reset {cause}")

    def go(self, until: float | None = None, realtime: bool = True) -> RunResult:
        """Runs free, paced to the wall clock unless realtime=False, until
        simulated second `until` (None: no end), a limit, or Ctrl-C
        (stop="interrupted")."""
        target = self.cycles_for(until) if until is not None else 0
        if until is not None and target == 0:
            target = 1
        self._send(f"go {target} {'realtime' if realtime else 'fast'}\n")
        try:
            return self._run_result(self._read())
        except KeyboardInterrupt:
            # Ask the board to stop; it answers the `go`, then the `stop`.
            self._send("stop\n")
            result = None
            while True:
                line = self._read()
                if " stop=" in line:
                    result = self._run_result(line)
                elif line.strip() == "ok":
                    break
            return result or self._run_result(self.command("step 0"))

    def info(self) -> dict[str, str]:
        return _fields(self.command("info"))

    # -- analog inputs --
    def adc_channel(self, pin: str | int) -> int:
        """The ADC channel of an analog pin (`A0`, or its pin number)."""
        if pin in self.pins.analog:
            return self.pins.analog[pin]
        if isinstance(pin, int) or (isinstance(pin, str) and pin.isdigit()):
            names = [n for n, p in self.board.analog_pins.items() if p == int(pin)]
            pin = names[0] if names else f"pin {pin}"
        if pin not in self.pins.analog:
            known = ", ".join(self.pins.analog)
            raise SimError(f"board `{self.board.name}` has no analog input {pin} (it has {known})")
        return self.pins.analog[pin]

    def _millivolts(self, volts: float) -> int:
        """Volts at an analog pin as the ADC sees them: clamped to 0..vref
        (the converter saturates there), in millivolts."""
        v = float(volts)
        if v != v:
            raise ValueError("analog input volts must be a number, not NaN")
        return int(round(min(max(v, 0.0), self.board.adc_vref) * 1000))

    def set_analog(self, pin: str | int, volts: float) -> None:
        self.command(f"adc {self.adc_channel(pin)} {self._millivolts(volts)}")

    # -- digital pins --
    def _port_bit(self, pin: int) -> tuple[str, int]:
        if pin not in self.pins.digital:
            raise SimError(f"board `{self.board.name}` has no digital pin {pin}")
        return self.pins.digital[pin]

    def ports(self) -> dict[str, tuple[int, int, int]]:
        """Every I/O port's (PORT, DDR, PIN) registers."""
        out = {}
        for tok in self.command("ports").split()[1:]:
            name, regs = tok.split("=")
            out[name] = tuple(int(x, 16) for x in regs.split(":"))
        return out

    def levels(self) -> dict[int, bool]:
        """Every digital pin's level: the driven level of an output, the
        sensed level of an input."""
        regs = self.ports()
        out = {}
        for pin, (port, bit) in self.pins.digital.items():
            if port in regs:
                p, ddr, pin_reg = regs[port]
                out[pin] = bool(((p if ddr >> bit & 1 else pin_reg) >> bit) & 1)
        return out

    def digital(self, pin: int) -> bool:
        port, bit = self._port_bit(pin)
        p, ddr, pin_reg = self.ports()[port]
        return bool(((p if ddr >> bit & 1 else pin_reg) >> bit) & 1)

    def is_output(self, pin: int) -> bool:
        port, bit = self._port_bit(pin)
        return bool(self.ports()[port][1] >> bit & 1)

    def set_digital(self, pin: int, level: bool) -> None:
        """Drives an input pin from outside (a switch, a plant's sensor)."""
        port, bit = self._port_bit(pin)
        self.command(f"din {port} {bit} {1 if level else 0}")

    def watch(self, pin: int) -> None:
        """Records this pin's edges, timestamped in cycles (see `edges`)."""
        port, bit = self._port_bit(pin)
        self.command(f"watch {port} {bit}")

    def edges(self) -> list[Edge]:
        """The edges of watched pins since the last call, oldest first."""
        return self._edges(self.command("edges").split()[1:])

    def pwm(self, pin: int) -> float:
        """The duty (0..1) a pin outputs: OCR/255 while its timer drives it
        (`analogWrite(pin, v)` with 0 < v < 255 gives v/255), else its digital
        level (0 or 1)."""
        timer = self.pins.timers.get(pin)
        if timer is None:
            raise SimError(f"pin {pin} of board `{self.board.name}` has no PWM")
        tccr, com_bit, ocr = TIMER_CHANNELS[timer]
        if self.peek(tccr, 1)[0] >> com_bit & 1:
            return self.peek(ocr, 1)[0] / 255.0
        return 1.0 if self.digital(pin) else 0.0

    # -- UART0 --
    def uart_read(self) -> bytes:
        """Bytes the firmware sent since the last call (uart="control")."""
        return bytes.fromhex(self.command("uart")[3:])

    def uart_write(self, data: bytes) -> None:
        """Queues bytes for the firmware's receiver (uart="control"); the
        UART takes them at its baud rate as simulated time passes."""
        for i in range(0, len(data), 8192):
            self.command("send " + data[i:i + 8192].hex())

    # -- memory --
    def peek(self, address: int, count: int) -> bytes:
        """`count` bytes of the MCU's data space (registers, I/O, RAM)."""
        return bytes.fromhex(self.command(f"peek {int(address)} {int(count)}")[3:])

    def schedule(self, changes) -> int:
        """Input changes applied by the board itself as simulated time
        reaches them: `changes` is [(cycle, {pin: volts}, {pin: level})] in
        cycle order. An open-loop replay then runs in long steps, without a
        round trip per change. Returns the number of changes scheduled."""
        fd, path = tempfile.mkstemp(prefix="fsw-sched-", suffix=".txt")
        try:
            with os.fdopen(fd, "w") as f:
                for cycle, analog, digital in changes:
                    for p, v in analog.items():
                        f.write(f"{int(cycle)} {self.adc_channel(p)}={self._millivolts(v)}\n")
                    for pin, level in digital.items():
                        port, bit = self._port_bit(pin)
                        f.write(f"{int(cycle)} {port}{bit}={1 if level else 0}\n")
            return int(self.command(f"sched {path}").split("n=")[1])
        finally:
            os.unlink(path)

    # -- EEPROM (kept across resets) --
    def eeprom_read(self, address: int, count: int) -> bytes:
        """`count` bytes of the EEPROM from `address`."""
        out = b""
        for a in range(address, address + count, 1024):
            n = min(1024, address + count - a)
            out += bytes.fromhex(self.command(f"eeprom read {int(a)} {int(n)}")[3:])
        return out

    def eeprom_write(self, address: int, data: bytes) -> None:
        """Writes EEPROM bytes as a programmer would (no write time, no count)."""
        for i in range(0, len(data), 1024):
            self.command(f"eeprom write {int(address + i)} {data[i:i + 1024].hex()}")

    def eeprom_cut(self, writes: int) -> None:
        """A power cut right after the firmware's `writes`-th EEPROM byte
        write from now: the MCU resets there as with reset("power") (MCUSR
        PORF, RAM pseudo-random), the EEPROM keeps what was written."""
        self.command(f"eeprom cut {int(writes)}")

    def eeprom_count(self) -> tuple[int, int]:
        """(EEPROM byte writes the firmware started, power cuts made)."""
        f = dict(t.split("=") for t in self.command("eeprom count").split()[1:])
        return int(f["writes"]), int(f["cuts"])

    # -- SPI NOR flash (spi_flash=...) --
    def flash_read(self, address: int, count: int) -> bytes:
        """`count` bytes of the SPI flash's array from `address`."""
        out = b""
        for a in range(address, address + count, PEEK_MAX):
            n = min(PEEK_MAX, address + count - a)
            out += bytes.fromhex(self.command(f"flash read {int(a)} {int(n)}")[3:])
        return out

    def flash_write(self, address: int, data: bytes) -> None:
        """Stores bytes in the flash's array as they are (no write enable,
        no 1->0 rule, no time): a test's fixture."""
        for i in range(0, len(data), 1024):
            self.command(f"flash write {int(address + i)} {data[i:i + 1024].hex()}")

    def flash_erase(self) -> None:
        """Sets the whole flash to 0xFF at once (as from the factory)."""
        self.command("flash erase")

    def flash_info(self) -> dict:
        """The chip: size (bytes), jedec (the 3 ID bytes), cs ("B2"), busy
        and wel (its status bits), programs and erases started, cuts made,
        armed (a `flash_cut` is pending)."""
        f = _fields(self.command("flash info"))
        out: dict = {k: int(v) for k, v in f.items() if k not in ("jedec", "cs")}
        for k in ("busy", "wel", "armed"):
            out[k] = bool(out[k])
        out["jedec"] = bytes.fromhex(f["jedec"])
        out["cs"] = f["cs"]
        return out

    def flash_cut(self, operations: int) -> None:
        """A power cut right after the `operations`-th page program or erase
        from now starts: the MCU resets there as with reset("power") and
        that operation is left half done (a prefix of its bytes programmed or erased, the same for
        the same operation count); the chip's BUSY and WEL are cleared."""
        self.command(f"flash cut {int(operations)}")

    # -- sensors on I2C and SPI (parts=...) --
    def parts(self) -> dict[int | str, str]:
        """The parts on the board: {I2C address or SPI chip-select pin: kind}."""
        out: dict[int | str, str] = {}
        for tok in self.command("part").split()[1:]:
            where, kind = tok.split("=")
            out[int(where, 16) if where.startswith("0x") else where] = kind
        return out

    def part_calibration(self, part: int | str, data: bytes | None = None) -> bytes:
        """The part's calibration block (the BMP280's 24 bytes at 0x88..0x9F;
        the MS5611's PROM, 8 big-endian words, word 7's low 4 bits its CRC-4;
        the MPU-6050's self-test registers 0x0D..0x10; the ADXL345's offsets
        0x1E..0x20); with `data`, first replaces its first len(data) bytes
        (no CRC is recomputed: a test may store a bad one). `part` is the
        part's I2C address or SPI chip-select pin."""
        line = f"part {_part_id(part)} cal" + (f" {bytes(data).hex()}" if data is not None else "")
        return bytes.fromhex(self.command(line)[3:])

    def part_raw(self, part: int | str, **values: int) -> None:
        """Sets raw counts, by name, that the part's next conversion or sample
        to end puts in its result registers (those already ended keep the
        old ones): bmp280 adc_P, adc_T (20 bits); ms5611 D1, D2 (24 bits);
        mpu6050 ax, ay, az, temp, gx, gy, gz and adxl345 x, y, z (signed
        16 bits). Names not given keep their values."""
        if values:
            self.command(f"part {_part_id(part)} raw " + " ".join(f"{k}={int(v)}" for k, v in values.items()))

    def part_fail(self, part: int | str, mode: str) -> None:
        """A failure of the part, one of `PART_FAILS`: "nack" (it stops
        answering: its address, or its SPI select, gets no answer), "stuck"
        (its results stop changing; conversions still end), "ok" (works
        again). Noise is the host's to add to the raw counts."""
        if mode not in PART_FAILS:
            raise ValueError(f"a part's failure is one of {', '.join(PART_FAILS)}, not {mode!r}")
        self.command(f"part {_part_id(part)} fail {mode}")

    def part_info(self, part: int | str) -> dict:
        """{kind, bus ("i2c"/"spi"), fail, busy (a conversion runs),
        conversions (ended since its power-on), and the raw counts by name}."""
        f = _fields(self.command(f"part {_part_id(part)} info"))
        return {k: (v if k in ("kind", "bus", "fail") else int(v)) for k, v in f.items()}

    def part_registers(self, part: int | str, register: int, count: int) -> bytes:
        """`count` of the part's registers from `register`, as they are (no
        read side effects, no conversion brought up to date by the read
        itself); not for the MS5611, which has commands."""
        return bytes.fromhex(self.command(f"part {_part_id(part)} reg {int(register)} {int(count)}")[3:])

    def symbol(self, name: str) -> tuple[int, int]:
        """(data address, size) of a variable of the firmware, by its
        (demangled) name, from the ELF's symbol table."""
        r = subprocess.run(["avr-nm", "-S", self.elf], capture_output=True, text=True)
        rows = [p for p in (line.split(None, 3) for line in r.stdout.splitlines())
                if len(p) == 4 and p[2].lower() in "bdgs" and int(p[0], 16) >= 0x800000]
        # the link-time optimiser renames some (`_ZN...recE.lto_priv.24`): the name without the suffix,
        # demangled, is the variable's
        bare = [re.sub(r"(\.(lto_priv|constprop|isra)\.\d+)+$", "", p[3]) for p in rows]
        demangled = subprocess.run(["avr-c++filt"], input="\n".join(bare), capture_output=True,
                                   text=True).stdout.splitlines()
        for p, d in zip(rows, demangled):
            if d == name:
                return int(p[0], 16) - 0x800000, int(p[1], 16)
        raise SimError(f"{self.elf}: no variable `{name}`")

    # -- profiling --
    def profile(self, entries: list[int]) -> None:
        """Starts counting the cycles spent in the functions at these byte
        addresses (the first marks a frame: see `Profile`), from zero."""
        self.command("prof " + " ".join(str(int(e)) for e in entries))

    def profile_read(self) -> Profile:
        """What `profile` has counted so far."""
        toks = self.command("prof").split()[1:]
        f = dict(t.split("=", 1) for t in toks if not t[0].isdigit())
        fns = []
        for t in toks:
            if t[0].isdigit():
                entry, counts = t.split("=")
                calls, total, worst = counts.split(":")
                fns.append(FunctionProfile(int(entry), int(calls), int(total), int(worst)))
        return Profile(int(f["sleep"]), int(f["frames"]), int(f["frame_total"]), int(f["frame_worst"]),
                       int(f["frame_worst_at"]), tuple(fns))

    def function(self, name: str) -> int:
        """The byte address in flash of a function of the firmware, by its
        (demangled) name without the parameter list and any ` [clone ...]`
        (`fsw::link_uplink_task`)."""
        r = subprocess.run(["avr-nm", "-C", self.elf], capture_output=True, text=True)
        for line in r.stdout.splitlines():
            parts = line.split(None, 2)
            if len(parts) == 3 and parts[1] in "tTwW" and parts[2].split("(")[0] == name:
                return int(parts[0], 16)
        raise SimError(f"{self.elf}: no function `{name}`")

    # -- stack and RAM --
    @functools.cached_property
    def _ram_layout(self) -> tuple[int, int, int]:
        """(start of RAM, end of the static data, top of RAM + 1) as data
        addresses: `_end` (after .data, .bss and .noinit) and `__stack`
        (RAMEND) from the ELF's symbols, the start from the board's RAM size.
        Fails for firmware that does not paint its free RAM at boot
        (FSW_STACK_PAINT)."""
        r = subprocess.run(["avr-nm", self.elf], capture_output=True, text=True)
        if r.returncode != 0:
            raise SimError(f"{self.elf}: avr-nm failed: {r.stderr.strip()}")
        syms = {}
        for line in r.stdout.splitlines():
            parts = line.split()
            if len(parts) == 3:
                syms[parts[2]] = int(parts[0], 16) & 0xFFFF  # data addresses carry 0x800000
        if "fsw_paint_stack" not in syms:
            raise SimError(f"{self.elf}: this firmware does not paint its stack at boot "
                           "(fswkit firmware built with FSW_STACK_PAINT=1 does)")
        missing = [n for n in ("_end", "__stack") if n not in syms]
        if missing:
            raise SimError(f"{self.elf}: no {', '.join(missing)} symbol: not an avr-libc program")
        top = syms["__stack"] + 1
        return top - self.board.ram, syms["_end"], top

    def stack_high_water(self) -> int:
        """Bytes of stack used at the deepest point so far (interrupts
        included): the top of RAM minus the lowest address, scanning up from
        the end of the static data, whose boot-time paint was overwritten.
        A pushed byte that happens to equal the paint byte at the very bottom
        reads as unused, so the figure can be low by a byte or two."""
        _, end, top = self._ram_layout
        addr = end
        while addr < top:
            n = min(PEEK_MAX, top - addr)
            chunk = self.peek(addr, n)
            for i, b in enumerate(chunk):
                if b != STACK_PAINT:
                    return top - (addr + i)
            addr += n
        return 0

    def ram_usage(self) -> RamUsage:
        """Static data, stack high-water mark and their total (RamUsage)."""
        start, end, top = self._ram_layout
        stack = self.stack_high_water()
        return RamUsage(end - start, stack, end - start + stack, top - start)

    # -- end --
    save_errors: tuple = ()  # after close(): why a flash or EEPROM file could not be saved (the harness's words)

    def close(self) -> int:
        """Stops the board; returns the harness's exit status (`save_errors`
        says why, when a memory's file could not be saved)."""
        if self._proc.poll() is None:
            try:
                if not self._closed:
                    self._proc.stdin.write(b"quit\n")
                self._proc.stdin.close()
            except OSError:
                pass
            try:
                self._proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self._proc.kill()
                self._proc.wait()
        self._closed = True
        try:
            self._out.close()
        except OSError:
            pass
        if self._proc.returncode and not self.save_errors:  # a memory's file it could not write at the end
            self.save_errors = tuple(line.split("simboard: ", 1)[-1] for line in self._stderr().splitlines()
                                     if "cannot save the" in line)
        self._err.close()
        return self._proc.returncode

    def __enter__(self) -> "SimBoard":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self):
        try:
            if self._proc.poll() is None:
                self._proc.kill()
        except Exception:
            pass


PART_KINDS = ("bmp280", "ms5611", "mpu6050", "adxl345")
PART_FAILS = ("ok", "nack", "stuck")


def _part_id(where: int | str) -> str:
    """A part's name in the protocol: its I2C address (0x76) or its SPI chip-select pin (B1)."""
    if isinstance(where, int):
        return f"0x{where:02x}"
    if isinstance(where, str) and re.fullmatch(r"[A-L][0-7]", where):
        return where
    raise ValueError(f"a part is at an I2C address (0x76) or an SPI chip-select pin (\"B1\"), not {where!r}")
