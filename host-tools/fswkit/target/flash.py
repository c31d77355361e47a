"""Uploading firmware (`fsw flash`, which builds it first with the build
service): through the board's bootloader with avrdude (Debian's package)
using the board's upload settings (boards/*.toml [upload]), or by
delegating to `pio run -t upload`. A missing port, a busy port, a port
without a bootloader or a board other than the one named raises FlashError
with a message saying so, never a traceback."""

from __future__ import annotations

import errno
import json
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys

EXIT_OK, EXIT_FAIL, EXIT_CONFIG = 0, 1, 2

# AVR device signatures avrdude reports -> the MCU.
SIGNATURES = {
    "1e950f": "ATmega328P",
    "1e9514": "ATmega328",
    "1e9406": "ATmega168",
    "1e940b": "ATmega168P",
    "1e9801": "ATmega2560",
    "1e9703": "ATmega1280",
    "1e9587": "ATmega32U4",
}


# avrdude's line for each try at the bootloader that got no answer: 7.x
# `avrdude warning: attempt 3 of 10: not in sync`, 6.x `stk500_getsync() attempt 3 of 10`
ATTEMPT = re.compile(r"\battempt (\d+) of (\d+)\b")


class FlashError(Exception):
    def __init__(self, message: str, code: int = EXIT_FAIL):
        super().__init__(message)
        self.code = code


def avrdude_command(board, hex_path: str, port: str) -> list[str]:
    """avrdude's arguments for a bootloader upload to `board` (its [upload]
    settings): part, protocol, port, speed; no chip erase (-D: the
    bootloader erases page by page), write then verify the flash."""
    up = board.raw.get("upload", {})
    return ["avrdude", "-p", str(up["partno"]), "-c", str(up["protocol"]), "-P", port,
            "-b", str(up["baud"]), "-D", "-U", f"flash:w:{hex_path}:i"]


# ---- the port --------------------------------------------------------------------------

def check_port(port: str, baud: int) -> None:
    """Fails with a clear message when the port is missing, busy or not
    ours to open. Opening it resets an Arduino, as avrdude's own open does."""
    if not os.path.exists(port):
        raise FlashError(f"no serial port {port}{_connected_hint()}")
    from fswkit.link.port import not_a_port

    why = not_a_port(port)  # a regular file or a folder (a slip): said as every command on a port says it
    if why is not None:
        raise FlashError(f"cannot open {port}: {why}")
    try:
        import serial
    except ImportError:
        raise FlashError("pyserial is not installed: run `make setup` (or pip install pyserial)") from None
    s = serial.Serial()
    s.port, s.baudrate, s.exclusive = port, baud, True
    try:
        s.open()
    except (serial.SerialException, OSError) as e:
        raise FlashError(_port_problem(port, getattr(e, "errno", None), str(e))) from None
    finally:
        if s.is_open:
            s.close()


def _port_problem(port: str, err: int | None, text: str) -> str:
    if err in (errno.EBUSY, errno.EAGAIN, errno.EWOULDBLOCK) or "busy" in text.lower() \
            or "exclusively lock" in text:
        from fswkit.link.port import holder

        rec = holder(port)
        if rec is not None:
            return (f"{port} is busy: held by {rec.get('command', 'a program')}, pid {rec['pid']}: end it "
                    "(Ctrl-C) and flash again")
        return (f"{port} is busy: another program has it open (a serial monitor, `fsw monitor`, "
                "the Arduino IDE): close it and flash again")
    from fswkit.link.port import denied, no_terminal

    words = denied(port, err, text) or no_terminal(port, err, text)
    if words:
        return words
    if err == errno.ENOENT:
        return f"no serial port {port}{_connected_hint()}"
    return f"cannot open {port}: {text}"


def _connected_hint() -> str:
    from fswkit.target.ports import PortError, list_ports

    try:
        ports = list_ports()
    except PortError:
        return ""
    if not ports:
        return ": no board is connected (`fsw ports` lists serial ports)"
    return ": connected now: " + ", ".join(p.label() for p in ports)


def check_board_on_port(board, listing, port: str) -> None:
    """A genuine Arduino says what it is over USB: refuse to flash a Mega's
    firmware into an Uno (--force skips this)."""
    if listing is None or not listing.boards or board.name in listing.boards:
        return
    raise FlashError(f"the board on {port} looks like an {listing.guess} (USB {listing.usb}), not a "
                     f"{board.name}: flash it with --board {listing.boards[0]}, or add --force if it is "
                     f"a {board.name} after all")


# ---- the upload tool's processes --------------------------------------------------------

def end_group(proc: subprocess.Popen) -> None:
    """Ends an upload tool started in a process group of its own
    (`process_group=0`) and everything it started (PlatformIO's build, its
    avrdude): SIGTERM, so that avrdude lets the port go, then SIGKILL to
    what is left after a few seconds. Used when the command is stopped
    (Ctrl-C, SIGTERM, SIGHUP), so that no upload goes on, or holds the
    port, after the command has ended. (In a group of its own, the tool is
    not sent a terminal's Ctrl-C directly: the command passes it on here.)"""
    for sig, wait in ((signal.SIGTERM, 5.0), (signal.SIGKILL, None)):
        try:
            os.killpg(proc.pid, sig)
        except (ProcessLookupError, PermissionError):
            pass
        try:
            proc.wait(timeout=wait)
        except subprocess.TimeoutExpired:
            continue


# ---- avrdude ---------------------------------------------------------------------------

def explain_avrdude(output: str, board, port: str, code: int) -> str:
    """What went wrong, from avrdude's output."""
    up = board.raw.get("upload", {})
    text = output.lower()
    sig = re.search(r"device signature = 0x([0-9a-f]{6})", text)
    expected = re.search(r"expected signature for (\S+) is ([0-9a-f]{2}) ([0-9a-f]{2}) ([0-9a-f]{2})", text)
    if sig and expected:
        found = sig.group(1)
        mcu = SIGNATURES.get(found, "an MCU fswkit does not know")
        return (f"the board on {port} is not a {board.name}: its MCU answers with signature 0x{found} "
                f"({mcu}), a {board.name} has an {board.mcu}: choose its board with --board")
    if "device or resource busy" in text:
        return _port_problem(port, errno.EBUSY, "busy")
    if "permission denied" in text:
        return _port_problem(port, errno.EACCES, "permission denied")
    if "can't open device" in text or "no such file or directory" in text:
        return f"avrdude cannot open {port}{_connected_hint()}"
    if any(s in text for s in ("not in sync", "not responding", "getsync", "receivemessage(): timeout",
                               "stk500v2_recv", "programmer is not responding")):
        return (f"no answer from a bootloader on {port} ({up.get('protocol')} protocol at "
                f"{up.get('baud')} baud): is it a {board.name}, and is this its port? (`fsw ports` lists "
                "them; an old-bootloader Nano answers at 57600 baud: PlatformIO's nanoatmega328)")
    tail = "\n".join("  " + line for line in output.strip().splitlines()[-8:])
    return f"avrdude failed (exit status {code}):\n{tail}"


def upload_avrdude(board, hex_path: str, port: str, verbose: bool) -> int:
    if shutil.which("avrdude") is None:
        raise FlashError("`avrdude` is not installed: run `make setup` (Debian package avrdude)")
    cmd = avrdude_command(board, hex_path, port)
    sys.stderr.write(f"fsw flash: {shlex.join(cmd)}\n")
    try:
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                errors="replace", process_group=0)
    except OSError as e:
        raise FlashError(f"cannot run avrdude: {e.strerror or e}") from None
    lines = []
    assert proc.stdout is not None
    try:
        _follow(proc, lines, port, verbose)
    except BaseException:  # Ctrl-C, SIGTERM, SIGHUP: avrdude ends with the command, never holds the port after it
        end_group(proc)
        raise
    code = proc.wait()
    output = "".join(lines)
    if code != 0:
        raise FlashError(explain_avrdude(output, board, port, code))
    m = re.search(r"(\d+) bytes of flash verified", output)
    size = f"{int(m.group(1)):,} B, verified" if m else "written"
    print(f"fsw flash: {os.path.basename(hex_path)} is on the {board.name} at {port} ({size})")
    return EXIT_OK


def _follow(proc, lines: list[str], port: str, verbose: bool) -> None:
    """avrdude's output as it comes: kept in `lines`, shown with `verbose`,
    else each try at the bootloader said in a line of ours."""
    for line in proc.stdout:
        lines.append(line)
        if verbose:
            sys.stderr.write(line)
        else:  # each try takes avrdude seconds (5 s in 7.1): a minute of silence would look like a hang
            attempt = ATTEMPT.search(line)
            if attempt:
                sys.stderr.write(f"fsw flash: no answer from a bootloader on {port} yet (attempt "
                                 f"{attempt.group(1)} of {attempt.group(2)}; Ctrl-C stops it)\n")
                sys.stderr.flush()


# ---- PlatformIO ------------------------------------------------------------------------

def pio_command() -> str:
    for exe in (shutil.which("pio"), shutil.which("platformio"),
                os.path.join(os.path.dirname(sys.executable), "pio")):
        if exe and os.path.isfile(exe) and os.access(exe, os.X_OK):
            return exe
    raise FlashError("PlatformIO is not installed: pip install platformio (docs/platformio.md), "
                     "or flash with avrdude (--via avrdude)")


def find_pio_project(app_path: str) -> str:
    """The folder of the platformio.ini nearest above the project."""
    d = os.path.dirname(os.path.abspath(app_path))
    while True:
        if os.path.isfile(os.path.join(d, "platformio.ini")):
            return d
        parent = os.path.dirname(d)
        if parent == d:
            raise FlashError(f"no platformio.ini in {os.path.dirname(app_path) or '.'} or above it: "
                             "`fsw new` writes one, docs/platformio.md describes it", EXIT_CONFIG)
        d = parent


def pio_env_for(pio: str, ini_dir: str, app) -> str:
    """The platformio.ini environment that builds this project for this board."""
    from fswkit.target.build import BuildError, find_app

    r = subprocess.run([pio, "project", "config", "-d", ini_dir, "--json-output"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise FlashError(f"PlatformIO cannot read {os.path.join(ini_dir, 'platformio.ini')}:\n"
                         f"{(r.stderr or r.stdout).strip()}", EXIT_CONFIG)
    try:
        sections = json.loads(r.stdout[r.stdout.index("["):])
    except ValueError:
        raise FlashError("PlatformIO printed a project configuration fswkit cannot read") from None
    want = os.path.realpath(app.path)
    pio_board = app.board.raw.get("platformio", {}).get("board")
    names = []
    for section, options in sections:
        if not section.startswith("env:"):
            continue
        opts = dict(options)
        names.append(section[4:])
        board_ok = (opts.get("custom_fsw_board") == app.board.name if opts.get("custom_fsw_board")
                    else opts.get("board") == pio_board)
        try:
            project = find_app(os.path.join(ini_dir, opts.get("custom_fsw_project") or "."))
        except BuildError:
            continue
        if board_ok and os.path.realpath(project) == want:
            return section[4:]
    raise FlashError(f"no environment of {os.path.join(ini_dir, 'platformio.ini')} builds "
                     f"{os.path.basename(app.path)} for the {app.board.name} (custom_fsw_project and "
                     f"custom_fsw_board; environments: {', '.join(names) or 'none'})", EXIT_CONFIG)


def upload_pio(app, port: str) -> int:
    pio = pio_command()
    ini_dir = find_pio_project(app.path)
    env = pio_env_for(pio, ini_dir, app)
    cmd = [pio, "run", "-d", ini_dir, "-e", env, "-t", "upload", "--upload-port", port]
    sys.stderr.write(f"fsw flash: {shlex.join(cmd)}\n")
    try:
        proc = subprocess.Popen(cmd, process_group=0)
    except OSError as e:
        raise FlashError(f"cannot run PlatformIO: {e.strerror or e}") from None
    try:
        code = proc.wait()
    except BaseException:  # PlatformIO's build and its avrdude end with the command too
        end_group(proc)
        raise
    if code != 0:
        raise FlashError(f"PlatformIO's upload failed (exit status {code}): its messages are above")
    print(f"fsw flash: {os.path.basename(app.path)} is on the {app.board.name} at {port} (PlatformIO `{env}`)")
    return EXIT_OK
