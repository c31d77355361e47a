"""The `fsw` command line: its parser, the dispatch to the command modules
(one per room: front, target, sim, ground, new, tape), and the exit statuses:
0 success, 1 a failure, 2 a configuration or usage error, 3 an internal
error of the kit, 128 + N stopped by signal N, 130 by Ctrl-C."""

from __future__ import annotations

import argparse
import contextlib
import gc
import os
import re
import sys

from fswkit import __version__
from fswkit.autocode.numtext import decimal, integer, non_finite
from fswkit.cli.common import EXIT_CONFIG, EXIT_FAIL, EXIT_INTERNAL, EXIT_OK


def _command(module: str, name: str):
    """The command `name` of fswkit.cli.`module`, imported when it runs:
    a command pays for its own room's imports only."""
    def run(args):
        import importlib

        return getattr(importlib.import_module(f"fswkit.cli.{module}"), name)(args)
    run.__name__ = run.__qualname__ = name
    return run


# ---- argument types -------------------------------------------------------------------

def _number(text: str, what: str = "a number") -> float:
    """A number as written in plain ASCII (fswkit.autocode.numtext): not `1_000`, digits of another script,
    `nan` or `infinity`."""
    value = decimal(text)
    if value is None:
        if non_finite(text) is not None:
            what = f"a finite {what[2:] if what.startswith('a ') else what}"
        raise argparse.ArgumentTypeError(f"expected {what}, found {text!r}")
    return value


def _whole(text: str, what: str) -> int:
    value = integer(text)
    if value is None:
        raise argparse.ArgumentTypeError(f"expected {what}, found {text!r}")
    return value


def _replay_speed(text: str) -> float:
    value = _number(text)
    if value != 0 and not 1e-3 <= value <= 1e6:
        raise argparse.ArgumentTypeError(f"expected 0 (as fast as possible) or a speed from 0.001 to 1000000, "
                                         f"found {text}")
    return value


def _nonneg_float(text: str) -> float:
    value = _number(text)
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"expected a number >= 0, found {text}")
    return value


def _seconds(text: str) -> float:
    """A finite number of seconds, 0 or more (a NaN or an infinity would
    make a wait that never ends)."""
    value = _nonneg_float(text)
    if value == float("inf"):
        raise argparse.ArgumentTypeError(f"expected a finite number of seconds, found {text}")
    return value


def _positive_int(text: str) -> int:
    value = _whole(text, "a positive whole number")
    if value <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive whole number, found {value}")
    return value


def _int_upto(hi: int, what: str):
    """An argparse type: a positive whole number of at most `hi` (what its use can hold)."""
    def parse(text: str) -> int:
        value = _positive_int(text)
        if value > hi:
            raise argparse.ArgumentTypeError(f"expected {what} of at most {hi:,}, found {text}")
        return value
    return parse


_SESSION_HELP = "a session of a ground station's archive (default: the newest; not for a link log)"
_baud = _int_upto(10_000_000, "a serial speed")  # what a UART or a USB serial adapter makes
_delta_t = _int_upto(2**64 - 1, "a time step")  # the script's U64 `delta_t`


def _nonneg_int(text: str) -> int:
    value = _whole(text, "a whole number >= 0")
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0, found {value}")
    return value


def _pad_alt(text: str) -> float:
    """A pad's elevation in m ASL: from -500 (the Dead Sea's shore is -430)
    to 9,000 (the pressure a tape is made from stays in the ISA troposphere)."""
    value = _number(text, "a number of metres")
    if not -500.0 <= value <= 9_000.0:
        raise argparse.ArgumentTypeError(f"expected a pad elevation from -500 to 9,000 m ASL, found {text}")
    return value


def _tcp_port(text: str) -> int:
    """A TCP port to listen on: 0 (any free one) to 65535."""
    value = _nonneg_int(text)
    if value > 65535:
        raise argparse.ArgumentTypeError(f"expected a TCP port from 0 to 65535, found {text}")
    return value


# ---- the parser -------------------------------------------------------------------

def _boards() -> str:
    """The boards the kit knows (its boards/*.toml), for the `--board` helps."""
    from fswkit.autocode.kit import board_names  # not .board: its imports cost every command 20 ms

    names = board_names()
    return f"; boards: {', '.join(names)}" if names else ""


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="fsw", description="fswkit: flight software from configs.")
    p.add_argument("--version", action="version", version=f"fsw {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    boards = _boards()

    c = sub.add_parser("check", help="check configs (.sv .sm .ss .app) or folders of them")
    c.add_argument("paths", nargs="+", metavar="PATH")
    c.add_argument("--strict", action="store_true", help="warnings fail the check too")
    c.add_argument("--sv", help="the state vector config to check machines against")
    c.add_argument("--sm", help="the state machine config to check scripts against")
    c.add_argument("--pyro-report", action="store_true",
                   help="print, for each pyro channel of the applications checked, every state and transition "
                        "that can fire it (docs/safety.md)")
    c.set_defaults(func=_command("front", "cmd_check"))

    t = sub.add_parser("test", help="run a state script against its machine")
    t.add_argument("script", metavar="SCRIPT.ss", nargs="+",
                   help="state scripts, or folders standing for every .ss in them")
    t.add_argument("--sm", help="the machine (default: the .sm beside the script)")
    t.add_argument("--sv", help="the state vector (default: the .sv beside the machine)")
    t.add_argument("--real", choices=("f64", "f32"), default=None,
                   help="evaluation type R: binary64 (hosts, default) or binary32 (AVR boards)")
    t.add_argument("--board", help="run with this board's evaluation type (e.g. uno: binary32)" + boards)
    t.add_argument("--native", action="store_true",
                   help="run the generated C++ compiled for this host instead of the interpreter")
    t.add_argument("--trace", metavar="FILE.csv", help="write every element after every step")
    t.add_argument("--force", action="store_true", help="replace a --trace file that is not an earlier trace "
                   "(a file you wrote): never done unasked")
    t.add_argument("--coverage", action="store_true",
                   help="report the states and transitions the scripts never reached, and fail if any")
    t.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="run with this parameter value (docs/parameters.md); overrides the script's [parameters]; "
                        "repeatable")
    t.set_defaults(func=_command("front", "cmd_test"))

    g = sub.add_parser("graph", help="a machine as Graphviz DOT or Mermaid")
    g.add_argument("machine", metavar="MACHINE.sm")
    g.add_argument("--format", choices=("dot", "mermaid"), default="dot")
    g.add_argument("--sv", help="the state vector (default: the .sv beside the machine)")
    g.add_argument("-o", "--output", help="write here instead of standard output")
    g.add_argument("--force", action="store_true", help="replace an -o file that is not an earlier graph "
                   "(a file you wrote): never done unasked")
    g.set_defaults(func=_command("front", "cmd_graph"))

    cp = sub.add_parser("compile", help="a machine as a bytecode image for the runtime's VM (docs/bytecode.md)")
    cp.add_argument("machine", metavar="MACHINE.sm")
    cp.add_argument("--sv", help="the state vector (default: the .sv beside the machine)")
    cp.add_argument("--real", choices=("f64", "f32"), default=None,
                    help="evaluation type R of the runtime that runs it (default f64)")
    cp.add_argument("--board", help="for this board's evaluation type (e.g. uno: binary32)" + boards)
    cp.add_argument("-o", "--output", required=True, metavar="FILE.fsm", help="the image to write (- for standard output)")
    cp.add_argument("--layout", metavar="FILE", help="also write the state vector's layout and the state names, as "
                    "libfswsm reads them (docs/bytecode.md)")
    cp.add_argument("--force", action="store_true", help="replace an -o or --layout file that holds something else "
                    "than an image (a layout): never done unasked")
    cp.set_defaults(func=_command("compile", "cmd_compile"))

    gn = sub.add_parser("gen", help="generate an application's C++ from its configs")
    gn.add_argument("project", metavar="PROJECT", help="a folder with one .app, or the .app file")
    gn.add_argument("--board", help="build for this board instead of the one the .app names" + boards)
    gn_out = gn.add_mutually_exclusive_group()
    gn_out.add_argument("--out", help="where to write (default PROJECT/build/BOARD/gen)")
    gn_out.add_argument("--sketch", metavar="DIR", help="write an Arduino sketch folder for arduino-cli instead")
    gn.set_defaults(func=_command("front", "cmd_gen"))

    b = sub.add_parser("build", help="build an application's firmware (.elf/.hex, or a host executable)")
    b.add_argument("project", metavar="PROJECT", help="a folder with one .app, or the .app file")
    b.add_argument("--board", help="build for this board instead of the one the .app names" + boards)
    b.add_argument("--out", help="build folder (default PROJECT/build/BOARD)")
    b.set_defaults(func=_command("target", "cmd_build"))

    sm = sub.add_parser("sim", help="build and run the firmware on a simulated board, UART0 on a pty")
    sm.add_argument("project", metavar="PROJECT", help="a folder with one .app, the .app file, or a firmware .elf")
    sm.add_argument("--board", help="simulate this board instead of the one the .app names" + boards)
    sm.add_argument("--duration", type=_number, metavar="SECONDS", help="stop after this much simulated time")
    sm.add_argument("--fast", action="store_true", help="run as fast as the simulator can, not in real time")
    sm.add_argument("--analog", action="append", metavar="PIN=VOLTS", help="an analog input's voltage, e.g. A0=3.2")
    sm.add_argument("--link", metavar="PATH", help="also make PATH a symbolic link to the serial port")
    sm.add_argument("--eeprom-file", metavar="FILE", help="the board alone: keep its EEPROM (parameters, the flight "
                    "recorder's records) in FILE between runs; read at start when it exists")
    sm.add_argument("--out", help="build folder (default PROJECT/build/BOARD); with --plant or --tape, the folder "
                    "the flight's log, CSV, plot and summary go to (default PROJECT/build/BOARD/PLANT-flight, "
                    "PROJECT/build/BOARD/tape-NAME)")
    sm.add_argument("--plant", choices=("rocket", "tank"),
                    help="fly the firmware in closed loop against this plant model (docs/sim.md)")
    sm.add_argument("--params", metavar="FILE.toml", help="with --plant: the plant's parameters "
                    "(default PROJECT/plant.toml); a file of top-level NAME = value lines only is the firmware's "
                    "parameters instead (as --fw-params)")
    sm.add_argument("--fw-params", metavar="FILE.toml", help="the firmware's parameters (docs/parameters.md): the "
                    "file's values are programmed into the board's EEPROM before boot, so one image flies another "
                    "rocket (--params names the plant's or the tape's config)")
    sm.add_argument("--seed", type=_nonneg_int, metavar="N", help="with --plant: the sensor noise's seed; with "
                    "--tape --perturb: the perturbations' seed (default 1)")
    sm.add_argument("--tape", metavar="FLIGHT.csv", help="replay a real flight's sensor tape through the firmware, "
                    "open loop, and check its events against FLIGHT.truth.toml (docs/sim.md, Replaying real flights); "
                    "--params names the tape config (default PROJECT/tape.toml, else plant.toml's channels and pins)")
    sm.add_argument("--perturb", type=_nonneg_int, metavar="N", help="with --tape: replay it N times with seeded "
                    "sensor noise, spikes, dropouts and bias, and report the distribution of the event errors")
    sm.add_argument("--runs", type=_positive_int, metavar="N", help="with --plant rocket: a dispersion study of N "
                    "flights, each with its own draw of --dispersion (docs/sim.md, Dispersion studies)")
    sm.add_argument("--jobs", type=_positive_int, metavar="J", help="with --runs: flights at a time (default: the "
                    "number of cores)")
    sm.add_argument("--dispersion", metavar="FILE.toml", help="with --runs or --run: how each flight of a study "
                    "differs from plant.toml's (motor, mass, drag, gusts, sensor errors, brown-outs)")
    sm.add_argument("--run", type=_nonneg_int, metavar="I", help="with --plant rocket: fly run I of the study with "
                    "--seed and --dispersion again, alone, writing its files")
    sm.add_argument("--fault", metavar="FAULT",
                    help="with --plant rocket: a fault (stuck-baro: the barometer freezes at ignition; "
                    "pinned-accel, pinned-baro: reads 5 V from boot, the motor is not lit; open-igniter: the "
                    "drogue's igniter is open from boot, the motor is not lit and the vehicle must refuse to arm; "
                    "with digital sensor parts, baro-nack, baro-stuck, baro-noisy, accel-nack, accel-stuck, "
                    "accel-noisy, each at ignition or @SECONDS: the part stops answering, its results stop changing, "
                    "or they turn noisy)")
    sm.set_defaults(func=_command("sim", "cmd_sim"))

    fl = sub.add_parser("flash", help="build the firmware and upload it to a board (avrdude or PlatformIO)")
    fl.add_argument("project", metavar="PROJECT", help="a folder with one .app, or the .app file")
    fl.add_argument("--port", help="the board's serial port (default: the only serial port connected)")
    fl.add_argument("--board", help="flash for this board instead of the one the .app names" + boards)
    fl.add_argument("--via", choices=("avrdude", "pio"), default="avrdude",
                    help="upload with avrdude (default) or with `pio run -t upload`")
    fl.add_argument("--out", help="build folder (default PROJECT/build/BOARD)")
    fl.add_argument("--force", action="store_true", help="flash even when the port's USB IDs say another board")
    fl.add_argument("-v", "--verbose", action="store_true", help="show avrdude's output as it runs")
    fl.set_defaults(func=_command("target", "cmd_flash"))

    po = sub.add_parser("ports", help="list serial ports, with the board each one seems to be")
    po.add_argument("--all", action="store_true", help="also ports without USB IDs (built-in UARTs)")
    po.set_defaults(func=_command("target", "cmd_ports"))

    nw = sub.add_parser("new", help="scaffold a new project that builds as it stands")
    nw.add_argument("name", metavar="NAME", help="the project's folder; its name names the files and machine")
    nw.add_argument("--board", default="uno", help="the board it runs on (default uno)" + boards)
    nw.set_defaults(func=_command("new", "cmd_new"))

    s = sub.add_parser("skeleton", help="a state-script skeleton that visits every state")
    s.add_argument("machine", metavar="MACHINE.sm")
    s.add_argument("--sv", help="the state vector (default: the .sv beside the machine)")
    s.add_argument("--delta-t", type=_delta_t, default=10, help="time step of the script (default 10)")
    s.add_argument("-o", "--output", help="write here instead of standard output")
    s.add_argument("--force", action="store_true", help="replace an -o file that is not an earlier skeleton "
                   "(a state script you wrote): never done unasked")
    s.set_defaults(func=_command("front", "cmd_skeleton"))

    m = sub.add_parser("monitor", help="decode a target's telemetry live (docs/telemetry.md)")
    m.add_argument("project", metavar="PROJECT", help="the project the firmware was built from (folder or .app)")
    m.add_argument("--port", help="serial device (/dev/ttyACM0, a pty) or pyserial URL "
                   "(default: the only serial port connected)")
    m.add_argument("--baud", type=_baud, help="link speed (default: the application's `baud`)")
    m.add_argument("--log", metavar="FILE", help="record every byte of the link to FILE (a new file)")
    m.add_argument("--force", action="store_true", help="let --log replace an existing FILE")
    m.add_argument("--headless", action="store_true", help="print decoded frames as lines, no live view")
    m.add_argument("--ignore-schema", action="store_true", help="decode even when the schema hash differs")
    m.add_argument("--duration", type=_nonneg_float, metavar="S", help="stop after S seconds")
    m.add_argument("--frames", type=_positive_int, metavar="N", help="stop after N frames")
    m.add_argument("--spark", action="append", default=[], metavar="ELEMENT",
                   help="a sparkline of ELEMENT's last 60 values in the live view (repeatable)")
    m.set_defaults(func=_command("ground", "cmd_monitor"))

    cm = sub.add_parser("cmd", help="send a command over the uplink and wait for its acknowledgement")
    cm.add_argument("what", choices=("set", "mode", "ping", "hello", "snapshot"), metavar="COMMAND",
                    help="set ELEMENT VALUE | mode TASK disabled|safed|enabled | ping | hello | snapshot")
    cm.add_argument("args", nargs="*", metavar="ARG")
    cm.add_argument("--port", required=True, help="serial device or pyserial URL")
    cm.add_argument("-p", "--project", default=".", help="the project the firmware was built from (default .)")
    cm.add_argument("--baud", type=_baud, help="link speed (default: the application's `baud`)")
    cm.add_argument("--ignore-schema", action="store_true", help="send even when the schema hash differs")
    # `set x -3.4028235e38`, `-inf`, `-0x7f`: a value, not an unknown option (argparse
    # takes only `-5` and `-.5` for numbers); no option of `cmd` starts with a digit, `.`, inf or nan
    cm._negative_number_matcher = re.compile(r"^-(\d|\.\d|inf|nan)", re.IGNORECASE)
    cm.set_defaults(func=_command("ground", "cmd_cmd"))

    for name, what in (("ground", "the ground station: owns a target's serial port, archives the link, serves "
                                  "the terminal tools and the web page at once (docs/ground.md)"),
                       ("web", "the same as `fsw ground` (its older name)")):
        wb = sub.add_parser(name, help=what)
        wb.add_argument("project", metavar="PROJECT", help="the project the firmware was built from")
        wb.add_argument("--port", help="serial device or pyserial URL (default: the only serial port found)")
        wb.add_argument("--baud", type=_baud, help="link speed (default: the application's `baud`)")
        kept = wb.add_mutually_exclusive_group()
        kept.add_argument("--archive", metavar="FILE.sqlite",
                          help="the SQLite archive the session is added to (default PROJECT/ground-archive.sqlite)")
        kept.add_argument("--no-archive", action="store_true", help="archive nothing")
        wb.add_argument("--no-web", action="store_true", help="serve the local clients only, no web page")
        wb.add_argument("--http-port", type=_tcp_port, default=8000, metavar="N",
                        help="the web server's TCP port on localhost (default 8000; 0: any free one)")
        wb.add_argument("--host", default="127.0.0.1",
                        help="the address to serve on (default 127.0.0.1: this machine only)")
        wb.add_argument("--ignore-schema", action="store_true", help="decode even when the schema hash differs")
        wb.set_defaults(func=_command("web", "cmd_ground"))

    pa = sub.add_parser("param", help="a target's parameters over the link: list, get, set, save, load, diff "
                                      "(docs/parameters.md)")
    pa.add_argument("project", metavar="PROJECT", help="the project the firmware was built from")
    pa.add_argument("action", choices=("list", "get", "set", "save", "load", "diff"), metavar="ACTION",
                    help="list [-o FILE.toml] | get NAME... | set NAME=VALUE... | save | load FILE.toml | "
                         "diff [FILE.toml]")
    pa.add_argument("args", nargs="*", metavar="ARG")
    pa.add_argument("--port", required=True, help="serial device or pyserial URL")
    pa.add_argument("--baud", type=_baud, help="link speed (default: the application's `baud`)")
    pa.add_argument("-o", "--output", metavar="FILE.toml", help="list: also write the values as a parameter file")
    pa.add_argument("--force", action="store_true", help="list -o: replace an existing file")
    pa.add_argument("--ignore-schema", action="store_true", help="talk to the target even when the schema differs")
    pa._negative_number_matcher = re.compile(r"^-(\d|\.\d|inf|nan)", re.IGNORECASE)
    pa.set_defaults(func=_command("param", "cmd_param"))

    mc = sub.add_parser("machine", help="replace a running target's machine over the link without reflashing: "
                                        "list, upload, activate, revert (docs/reload.md)")
    mc.add_argument("project", metavar="PROJECT", help="the project the firmware was built from (its [reload])")
    mc.add_argument("action", choices=("list", "upload", "activate", "revert"), metavar="ACTION",
                    help="list | upload MACHINE.sm [--activate] | activate 1|2|builtin | revert")
    mc.add_argument("args", nargs="*", metavar="ARG")
    mc.add_argument("--port", required=True, help="serial device or pyserial URL")
    mc.add_argument("--baud", type=_baud, help="link speed (default: the application's `baud`)")
    mc.add_argument("--activate", action="store_true", help="upload: activate the image once it is committed")
    mc.add_argument("--restart", action="store_true", help="upload: start over instead of resuming an interrupted "
                    "upload of the same image")
    mc.add_argument("--wait", type=_seconds, metavar="S", help="activate, revert, upload --activate: seconds to wait "
                    "for the machine to reach a state that allows the switch (default 10)")
    mc.add_argument("--ignore-schema", action="store_true", help="talk to the target even when the schema differs")
    mc.set_defaults(func=_command("machine", "cmd_machine"))

    du = sub.add_parser("dump", help="a target's flight record over the link, each flight as a link log "
                                     "(docs/recorder.md)")
    du.add_argument("project", metavar="PROJECT", help="the project the firmware was built from")
    du.add_argument("--port", required=True, help="serial device or pyserial URL")
    du.add_argument("--baud", type=_baud, help="link speed (default: the application's `baud`)")
    du.add_argument("-o", "--output", required=True, metavar="DIR", help="the folder for flight-N.log files")
    du.add_argument("--flight", type=_int_upto(255, "a flight number"), metavar="N",
                    help="this flight, 1 to 255 (default: the newest)")
    du.add_argument("--all", action="store_true", help="every flight in the record")
    du.add_argument("--force", action="store_true", help="replace existing flight-N.log files")
    du.add_argument("--erase", action="store_true", help="after the dump, erase the record (asks first; only in the "
                    "states `[log] erase` names)")
    du.add_argument("--yes", action="store_true", help="--erase without asking")
    du.add_argument("--ignore-schema", action="store_true", help="talk to the target even when the schema differs")
    du.set_defaults(func=_command("dump", "cmd_dump"))

    lc = sub.add_parser("log2csv", help="a link log as CSV: one row per sample")
    lc.add_argument("log", metavar="LOG")
    lc.add_argument("-o", "--output", metavar="FILE", help="write here instead of standard output")
    lc.add_argument("--force", action="store_true", help="replace FILE if it exists")
    lc.add_argument("--ignore-schema", action="store_true")
    lc.add_argument("--session", type=_positive_int, metavar="N", help=_SESSION_HELP)
    lc.set_defaults(func=_command("ground", "cmd_log2csv"))

    rp = sub.add_parser("replay", help="the monitor's view of a link log")
    rp.add_argument("log", metavar="LOG")
    rp.add_argument("--headless", action="store_true", help="print decoded frames as lines")
    rp.add_argument("--speed", type=_replay_speed, default=1.0,
                    help="1 = as recorded, 2 twice as fast (0.001 to 1000000), 0 = as fast as possible")
    rp.add_argument("--ignore-schema", action="store_true")
    rp.add_argument("--session", type=_positive_int, metavar="N", help=_SESSION_HELP)
    rp.add_argument("--spark", action="append", default=[], metavar="ELEMENT",
                    help="a sparkline of ELEMENT's last 60 values in the view (repeatable)")
    rp.set_defaults(func=_command("ground", "cmd_replay"))

    pl = sub.add_parser("plot", help="time series of elements from a link log, state transitions marked")
    pl.add_argument("log", metavar="LOG")
    pl.add_argument("-e", "--element", nargs="+", required=True, metavar="ELEMENT")
    pl.add_argument("-o", "--output", required=True, metavar="OUT.png")
    pl.add_argument("--force", action="store_true", help="replace OUT if it exists")
    pl.add_argument("--ignore-schema", action="store_true")
    pl.add_argument("--session", type=_positive_int, metavar="N", help=_SESSION_HELP)
    pl.set_defaults(func=_command("ground", "cmd_plot"))

    ar = sub.add_parser("archive", help="a ground station's SQLite archive: list its sessions, export one "
                        "(docs/ground.md)")
    asub = ar.add_subparsers(dest="archive_command", metavar="list|export")
    asub.required = True
    al = asub.add_parser("list", help="the archive's sessions: port, times, frames, commands, bytes")
    al.add_argument("archive", metavar="FILE")
    al.set_defaults(func=_command("ground", "cmd_archive_list"))
    ae = asub.add_parser("export", help="a session's samples as CSV or Parquet, one row per sample")
    ae.add_argument("archive", metavar="FILE")
    ae.add_argument("--session", type=_positive_int, metavar="N", help="this session (default: the newest)")
    ae.add_argument("--from", dest="t_from", type=_seconds, metavar="SECONDS",
                    help="rows from SECONDS after the session began (host clock)")
    ae.add_argument("--to", dest="t_to", type=_seconds, metavar="SECONDS",
                    help="rows up to SECONDS after the session began")
    ae.add_argument("-o", "--output", required=True, metavar="OUT.csv|OUT.parquet",
                    help="the file to write; its extension says the format")
    ae.add_argument("--force", action="store_true", help="replace OUT if it exists")
    ae.add_argument("--ignore-schema", action="store_true", help="decode even when the schema hash differs")
    ae.set_defaults(func=_command("ground", "cmd_archive_export"))

    tp = sub.add_parser("tape", help="sensor tapes of real flights: import a recorder's log, work out its truth, "
                        "show a tape (docs/tapes.md)")
    tsub = tp.add_subparsers(dest="tape_command", metavar="import|truth|show")
    tsub.required = True
    ti = tsub.add_parser("import", help="convert an altimeter's CSV log into a sensor tape")
    ti.add_argument("format", choices=("altos", "cats", "raven", "eggtimer", "rrc3"), metavar="FORMAT",
                    help="altos | cats | raven | eggtimer | rrc3")
    ti.add_argument("log", metavar="LOG")
    ti.add_argument("-o", "--output", required=True, metavar="TAPE.csv", help="the tape to write (- for "
                    "standard output)")
    ti.add_argument("--pad-alt", type=_pad_alt, metavar="M", help="pad elevation in m ASL, for pressure made "
                    "from a log's altitude (default 0)")
    ti.add_argument("--alt-unit", choices=("ft", "m"), help="eggtimer, rrc3: the unit of the log's altitude "
                    "(default ft, the recorders' default; m for one set to metres)")
    ti.add_argument("--force", action="store_true", help="replace TAPE.csv if it exists")
    ti.set_defaults(func=_command("tape", "cmd_import"))
    tt = tsub.add_parser("truth", help="work out a tape's truth (liftoff, burnout, apogee, landing) from the "
                         "tape, for fsw sim --tape")
    tt.add_argument("tape", metavar="TAPE.csv")
    tt.add_argument("-o", "--output", metavar="FILE", help="the truth file to write (default TAPE.truth.toml "
                    "beside the tape; - for standard output)")
    tt.add_argument("--force", action="store_true", help="replace the truth file if it exists")
    tt.set_defaults(func=_command("tape", "cmd_truth"))
    ts = tsub.add_parser("show", help="a tape's header, span, rates, columns, and its truth events")
    ts.add_argument("tape", metavar="TAPE.csv")
    ts.set_defaults(func=_command("tape", "cmd_show"))
    return p


# ---- entry point ------------------------------------------------------------------

# Commands that read configs and write what they give, then end: what they
# make lives to the end of the command (_fewer_collections).
_READ_AND_END = frozenset({"check", "gen"})


@contextlib.contextmanager
def _fewer_collections(process_ends: bool, command: str):
    """The front end makes a million small objects that live to the end and
    hardly any cycles; at the collector's default thresholds it walks that
    growing heap again and again (a third of `fsw check` of a big machine).
    Young collections every 100,000 allocations instead of 700, for the
    command only (fswkit.autocode.collect, as the loaders have it). When
    the process ends with the command (`fsw`, `python -m fswkit.cli`),
    what is left is frozen first: the interpreter's last
    collection at exit would walk it all once more for nothing (another
    0.4 s of CPU after a big machine). `fsw check` and `fsw gen` in such a
    process run without the collector: even every 100,000 allocations it
    finds nothing among their objects (a 20,000-line machine leaves the
    same memory without it), for a tenth of their CPU."""
    from fswkit.autocode.collect import fewer_collections

    enabled = gc.isenabled()
    if process_ends and command in _READ_AND_END:
        gc.disable()
    try:
        with fewer_collections():
            yield
    finally:
        if process_ends:
            gc.freeze()
        if enabled:
            gc.enable()


def _quiet_stdout() -> None:
    from fswkit.outputs import discard_stdout

    discard_stdout()


def _stdout_failed() -> bool:
    try:
        sys.stdout.flush()
    except OSError:
        return True
    except ValueError:  # closed
        return False
    return False


def _empty_option(p: argparse.ArgumentParser, args) -> str | None:
    """The long name of an option given as an empty string (a path, a port,
    a board), or None."""
    sub = next(a for a in p._actions if isinstance(a, argparse._SubParsersAction)).choices.get(args.command)
    for action in sub._actions if sub is not None else ():
        if action.option_strings and getattr(args, action.dest, None) == "":
            return max(action.option_strings, key=len)
    return None


_TO_STDOUT = " (standard output replaces no file)"

# Options that can take effect only with another (command, option, whether it
# was given without what it needs, what it goes with): refused, not ignored,
# as `fsw machine` refuses an option its action means nothing to.
_IDLE_OPTIONS = (
    ("test", "--force", lambda a: a.force and not a.trace, "--trace FILE"),
    ("graph", "--force", lambda a: a.force and a.output in (None, "-"), "-o FILE" + _TO_STDOUT),
    ("skeleton", "--force", lambda a: a.force and a.output in (None, "-"), "-o FILE" + _TO_STDOUT),
    ("log2csv", "--force", lambda a: a.force and a.output in (None, "-"), "-o FILE" + _TO_STDOUT),
    ("compile", "--force", lambda a: a.force and a.output == "-" and a.layout is None,
     "-o FILE or --layout FILE" + _TO_STDOUT),
    ("tape import", "--force", lambda a: a.force and a.output == "-", "-o FILE" + _TO_STDOUT),
    ("tape truth", "--force", lambda a: a.force and a.output == "-", "a file" + _TO_STDOUT),
    ("monitor", "--force", lambda a: a.force and a.log is None, "--log FILE"),
    ("param", "--force", lambda a: a.force and a.output is None, "`list -o FILE`"),
    ("dump", "--yes", lambda a: a.yes and not a.erase, "--erase (it answers the question before erasing)"),
)


def _idle_option(args) -> str | None:
    """The message for an option given without the one it works with (it
    would do nothing, leaving the user believing it did something), or None."""
    command = " ".join(filter(None, (args.command, getattr(args, "tape_command", None))))
    for name, option, idle, needs in _IDLE_OPTIONS:
        if name == command and idle(args):
            return f"fsw {command}: {option} goes with {needs}"
    return None


_parser: argparse.ArgumentParser | None = None


def main(argv: list[str] | None = None) -> int:
    """Runs the command `argv` (None: this process's arguments, the process
    ending with it) and returns its exit status."""
    from fswkit import outputs
    from fswkit.outputs import Stream

    global _parser
    if _parser is None:  # built once a process: `fsw` run in-process again and again (the tests) reuses it
        _parser = parser()
    p = _parser
    args = p.parse_args(argv)
    empty = _empty_option(p, args)
    if empty is not None:  # `--trace ""` is no trace, `--out ""` not the default folder
        sys.stderr.write(f"fsw {args.command}: {empty}: an empty string names nothing: give a path or name, "
                         "or leave the option out\n")
        return EXIT_CONFIG
    idle = _idle_option(args)
    if idle is not None:
        sys.stderr.write(idle + "\n")
        return EXIT_CONFIG
    # every print of every command: a failed write says it was standard output
    saved = sys.stdout
    out = sys.stdout = Stream(saved, "standard output")
    outputs.stopped_by = None
    try:
        # SIGTERM and SIGHUP stop a command as Ctrl-C does (its temporary files removed,
        # its outputs whole or as they were), with status 128 + the signal's number
        try:
            with outputs.stopped_by_signals(), _fewer_collections(argv is None, args.command):
                code = _main(args, out)
        except outputs.Stopped:  # the signal came as the command returned
            code = EXIT_FAIL
        return 128 + outputs.stopped_by if outputs.stopped_by else code
    finally:
        if sys.stdout is out:
            sys.stdout = saved


def _main(args, out) -> int:
    from fswkit.outputs import OutputError

    try:
        code = args.func(args)
        if out.failed:  # the command stopped at it and said so
            _quiet_stdout()
            return code or EXIT_FAIL
        sys.stdout.flush()  # a full or closed standard output fails here, not after exit
        return code
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:  # the reader went away (`fsw ... | head`): not a failure
        _quiet_stdout()
        return EXIT_OK
    except OutputError as e:
        sys.stderr.write(f"fsw {args.command}: {e}\n")
        _quiet_stdout()
        return EXIT_FAIL
    except OSError as e:  # an input or output the command could not use: its system error
        if out.failed or _stdout_failed():
            sys.stderr.write(f"fsw {args.command}: cannot write standard output: {e.strerror or e}\n")
            _quiet_stdout()
        else:
            where = f"{e.filename}: " if e.filename else ""
            sys.stderr.write(f"fsw {args.command}: {where}{e.strerror or e}\n")
        return EXIT_FAIL
    except RecursionError:
        sys.stderr.write("fsw: input nested too deeply to process\n")
        return EXIT_INTERNAL
    except Exception as e:  # a bug of the kit, never the user's input: no traceback
        if os.environ.get("FSW_DEBUG"):
            raise
        sys.stderr.write(f"fsw: internal error: {type(e).__name__}: {e}\n"
                         "  (this is a bug in fswkit; run with FSW_DEBUG=1 for details)\n")
        return EXIT_INTERNAL
