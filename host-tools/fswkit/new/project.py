"""`fsw new NAME --board BOARD`: a new project that passes `fsw check`,
`fsw test` and `fsw build` as written: a state vector, a starter state
machine, I/O tables with the board's pins in comments, an application
config, a state script from `fsw skeleton`, a platformio.ini and a README
for the team."""

from __future__ import annotations

import os
import re
import shlex
import shutil
import tempfile
import textwrap

from fswkit.autocode.board import Board
from fswkit.autocode.diagnostics import Diagnostics, ranges

from fswkit.autocode.kit import ROOT as KIT_ROOT
KEYWORDS = {"if", "else", "and", "or", "not", "true", "false"}
NAME_RE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
LED_PIN = 13  # the on-board LED of the Uno, Nano and Mega
BAUD = 115200  # the link's rate in the new .app (platformio.ini's monitor_speed follows it)


class ScaffoldError(Exception):
    pass


def check_name(name: str) -> None:
    """A project's name names its files and its machine: an identifier."""
    if not NAME_RE.match(name):
        raise ScaffoldError(f"`{name}` cannot name a project: use ASCII letters (A-Z, a-z), digits and `_`, "
                            "not starting with a digit (it names the files and the state machine)")
    if name in KEYWORDS:
        raise ScaffoldError(f"`{name}` is a keyword of the config languages: choose another name")


def _pins(board: Board) -> tuple[str, int]:
    """The starter's analog input (a name like A0) and digital output pin."""
    analog = min(board.analog_pins, key=lambda k: board.analog_pins[k])
    free = sorted(p for p in board.digital_pins
                  if p not in board.reserved and p not in board.analog_pins.values())
    digital = LED_PIN if LED_PIN in free else free[0]
    return analog, digital


def _board_comment(board: Board) -> str:
    return board.raw.get("board", {}).get("title", board.name)


def files(name: str, board: Board, kit_root: str = KIT_ROOT) -> dict[str, str]:
    """Every file of the new project: {file name: text}."""
    check_name(name)
    analog, led = _pins(board)
    title = _board_comment(board)
    analog_list = " ".join(f"{k}={v}" for k, v in sorted(board.analog_pins.items(), key=lambda kv: kv[1]))
    reserved = "; ".join(f"{p}: {why}" for p, why in sorted(board.reserved.items()))
    analog_only = board.raw.get("pins", {}).get("analog_only", [])
    digital = [p for p in board.digital_pins if p not in board.reserved]
    out: dict[str, str] = {}

    out[f"{name}.sv"] = f"""\
# State vector of {name}: every value the flight software shares, region by
# region. Telemetry streams whole regions ({name}.app, [telemetry]).
# Types: U8..U64, I8..I64, F32, F64, bool (docs/languages.md of fswkit).

[Sensors]
U64  time          # G: milliseconds since boot, written by the executor
U32  state         # S: the machine's current state
F32  pressure      # psi, from the transducer on {analog}

[Effectors]
bool valveOpen     # the vent valve (pin {led})

[Status]
U8   controlMode   # the control task: 0 disabled, 1 safed, 2 enabled
"""

    out[f"{name}.sm"] = f"""\
# The starter machine of {name}: a vent valve that opens when the pressure
# rises above P_Open and closes when it falls below P_Close. Replace it with
# your vehicle's logic (docs/languages.md of fswkit), then run
# `fsw skeleton {name}.sm` for a state script that visits every state.

[state_vector]
U64  time       @alias G
U32  state      @alias S
F32  pressure   @read_only
bool valveOpen

[local]
F32 P_Open  = 800 @read_only    # psi: open the vent above this
F32 P_Close = 700 @read_only    # psi: close it again below this

[Closed]
.entry
    valveOpen = false
.step
    pressure > P_Open: -> Open

[Open]
.entry
    valveOpen = true
.step
    pressure < P_Close: -> Closed
"""

    vref = f"{board.adc_vref:g}"
    # the executor's timer takes its PWM pins from analog outputs (iotables.py refuses them)
    timer_pwm = sorted(board.pwm_pins & board.timer_pins)
    timer_note = (f"\n#   not {' or '.join(str(p) for p in timer_pwm)}: their timer ({board.timer}) paces the executor"
                  if timer_pwm else "")
    out[f"{name}.aio"] = f"""\
# Analog I/O of {name}: one channel per line (docs/application.md of fswkit).
#   i  reads the pin into the element: volts = raw * {vref} / {2 ** board.adc_bits - 1}, then
#      element = volts * scale + offset
#   o  drives a PWM pin from the element's volts (0 .. {vref} V)
#
# {title}
#   analog inputs: {analog_list}
#   PWM pins (analog outputs): {ranges(board.pwm_pins - board.timer_pins, " ") or "none"}{timer_note}
#
# A 0.5-4.5 V transducer reading 0-1000 psi: psi = volts * 250 - 125.
# dir  pin  element    calibration
i      {analog:<4} pressure   scale=250 offset=-125
"""

    only = f"\n#   analog inputs only (no digital I/O): {ranges(analog_only, ' ')}" if analog_only else ""
    names = sorted(board.analog_pins, key=lambda k: board.analog_pins[k])
    as_digital = f"{names[0]}-{names[-1]} are {ranges(board.analog_pins.values(), ' ')}"
    out[f"{name}.dio"] = f"""\
# Digital I/O of {name}: one channel per line (docs/application.md of fswkit).
#   i  reads the pin into a bool element; o drives the pin from one
#
# {title}
#   digital pins: {ranges(digital, " ")} ({as_digital}){only}
#   reserved: {reserved or "none"}
#
# Pin {led} drives the on-board LED, so the valve's state shows without wiring.
# dir  pin  element
o      {led:<4} valveOpen
"""

    out[f"{name}.app"] = f"""\
# {name}: read the sensors, run the machine, drive the outputs 100 times a
# second on the {board.name}; telemetry and uplink over the serial port
# (docs/application.md of fswkit).

[application]
board {board.name}
rate  100
baud  {BAUD}

[configs]
state_vector {name}.sv
machine      {name}.sm
io           {name}.aio
io           {name}.dio

[time]
source clock
unit   ms

[tasks]
uplink   uplink          rate=100
sense    inputs          rate=100
control  machine {name:<8} rate=100  mode=controlMode  start=enabled
act      outputs         rate=100
downlink telemetry       rate=100

[telemetry]              # regions streamed to the ground (fsw monitor)
Sensors    rate=10
Effectors  rate=10
Status     rate=1

[uplink]                 # elements the ground may write (fsw cmd set); none yet:
                         # a task's mode changes only by `fsw cmd mode`
"""

    out[f"{name}.ss"] = _skeleton(name, out)
    out["platformio.ini"] = _platformio_ini(name, board, kit_root, _app_baud(out[f"{name}.app"]))
    out["README.md"] = _readme(name, board)
    out[".gitignore"] = ("# Generated code, builds and PlatformIO's work: all made again from the configs.\nbuild/\n"
                         "# The ground station's archive (fsw ground): recordings, kept beside the project\n"
                         "ground-archive.sqlite*\n")
    return out


def _skeleton(name: str, texts: dict[str, str]) -> str:
    """`fsw skeleton` of the starter machine, as the command writes it
    (its digest in its head line: `fsw skeleton -o` replaces it until edited)."""
    from fswkit.autocode.project import load_machine
    from fswkit.new.script import skeleton
    from fswkit.outputs import stamped

    with tempfile.TemporaryDirectory(prefix="fsw-new-") as tmp:
        for ext in (".sv", ".sm"):
            with open(os.path.join(tmp, name + ext), "w") as f:
                f.write(texts[name + ext])
        diags = Diagnostics()
        m = load_machine(os.path.join(tmp, name + ".sm"), diags)
        if m is None:  # a bug of the templates, never of the user's input
            raise RuntimeError("the starter machine does not compile:\n" + diags.render())
        return stamped(skeleton(m), "skeleton")


def _app_baud(app_text: str) -> int:
    """The `baud` the new .app sets: `pio device monitor` reads the board at it."""
    return int(re.search(r"^baud\s+(\d+)\s*$", app_text, re.M).group(1))


def _platformio_ini(name: str, board: Board, kit_root: str, baud: int) -> str:
    pio = board.raw.get("platformio", {})
    envs = []
    if board.is_avr:
        ard = board.raw.get("arduino", {})
        envs.append(f"""\
[env:{board.name}]
platform = {pio.get("platform", "atmelavr")}
framework = arduino
board = {pio.get("board", board.name)}
custom_fsw_board = {board.name}
; compiled as `fsw build` compiles for the {board.name} (the kit's boards/{board.name}.toml
; and mk/build.mk): its MCU, clock, variant and board define, plus shared
; register save/restore, linker relaxation, two flags that keep an 8-bit
; MCU's registers free (9 % of the tank's flash) and two that trade a
; little CPU for flash
board_build.mcu = {board.mcu}
board_build.f_cpu = {board.f_cpu}L
board_build.variant = {ard.get("variant", "standard")}
board_build.extra_flags = -D{ard.get("board_define", "ARDUINO_AVR_UNO")}
build_flags = -mcall-prologues -mstrict-X -fno-move-loop-invariants -fno-tree-vrp -fira-algorithm=priority -Wl,--relax
""")
    envs.append("""\
[env:native]
; The same application on this computer (simulated clock and pins).
platform = native
custom_fsw_board = native
""")
    default = board.name if board.is_avr else "native"
    usage = (f""";   pio run                 build the firmware for the {board.name}
;   pio run -t upload       ... and flash it
;   pio device monitor      the serial port (fsw monitor decodes telemetry)
""" if board.is_avr else """;   pio run                 build the program for this computer (pio run -e native)
""")
    return f"""\
; PlatformIO for {name} (integrations/platformio/README.md of fswkit).
;
{usage};
; Before every build, fswkit's hook regenerates the C++ from the configs
; into build/pio/src/<environment>/; a config error stops the build with its
; located diagnostic.

[fswkit]
; Where the fswkit checkout is on this machine (written by `fsw new`).
kit = {kit_root}

[platformio]
default_envs = {default}
src_dir = build/pio/src
build_dir = build/pio/build
libdeps_dir = build/pio/libdeps

[env]
extra_scripts = pre:${{fswkit.kit}}/integrations/platformio/pio_hook.py
build_src_filter = +<$PIOENV/>
lib_deps = fswkit=symlink://${{fswkit.kit}}/firmware
; the link's rate: {name}.app's baud
monitor_speed = {baud}

""" + "\n".join(envs)


def _readme(name: str, board: Board) -> str:
    col = 29  # where the comments of the "Every day" block start

    def line(command: str, what: str) -> str:
        return f"    {command:<{col}}# {what}" if len(command) < col else f"    {command}   # {what}"

    if board.is_avr:
        target = f"firmware for the {_board_comment(board)}"
        every_day = [
            line("fsw check .", "every config: located errors and warnings"),
            line(f"fsw test {name}.ss", "the state script against the machine"),
            line("fsw build .", "firmware, with flash and RAM against the board's budget"),
            line("fsw flash .", "build and upload (the board on the only serial port, or --port)"),
            line("fsw monitor .", "live telemetry from the board"),
            line("fsw cmd mode control safed --port PORT", "safe the control task from the ground")]
        pio = "With PlatformIO instead: `pio run`, `pio run -t upload`."
        last = "5. `fsw build .`, then `fsw flash .`."
    else:  # a program for this computer: nothing to upload, no serial port
        target = "a program for this computer (the `native` board: simulated pins and clock)"
        every_day = [
            line("fsw check .", "every config: located errors and warnings"),
            line(f"fsw test {name}.ss", "the state script against the machine"),
            line(f"fsw test --native {name}.ss", "the same, through the generated C++"),
            line("fsw build .", f"the program: build/native/{name}"),
            line(f"build/native/{name} 1000", "1,000 cycles on a simulated clock: the state vector in hex"),
            line("fsw build . --board uno", "firmware for an Arduino Uno (its pin map is this one's)")]
        pio = "With PlatformIO instead: `pio run`."
        last = (f"5. `fsw build .`. To fly it, name your Arduino in `{name}.app` (`board uno`, `nano`\n"
                "   or `mega2560`): `fsw flash .` then builds and uploads it.")
    commands = "\n".join(every_day)
    intro = textwrap.fill(f"Flight software for {name}, made with fswkit: the vehicle is described in the config "
                          f"files below and the kit turns them into {target}. Nobody writes glue code: change "
                          "a config, build again.", 75)
    return f"""\
# {name}

{intro}

| file | what it holds |
|---|---|
| `{name}.sv` | the state vector: every value the software shares, by region |
| `{name}.sm` | the state machine: states, what each does, the transitions |
| `{name}.ss` | a state script that tests the machine (made by `fsw skeleton`) |
| `{name}.aio`, `{name}.dio` | analog and digital pins, each tied to an element |
| `{name}.app` | the application: board, rate, tasks, telemetry, uplink |
| `platformio.ini` | the same project for PlatformIO |

## Every day

Run these in this folder:

{commands}

{pio}

## Where to start

1. Name your vehicle's values in `{name}.sv` (sensors, effectors, status).
2. Tie sensors and effectors to pins in `{name}.aio` and `{name}.dio`; the
   comments there list the board's pins.
3. Write the behaviour in `{name}.sm`.
4. `fsw skeleton {name}.sm -o {name}.ss` writes a new state script that
   visits every state (over the one here until you edit it; an edited
   script is kept unless you add `--force`); replace its TODOs with what
   must hold, and keep it passing with `fsw test {name}.ss`.
{last}
"""


def main(args) -> int:
    """`fsw new NAME --board BOARD`."""
    import sys

    from fswkit.autocode.board import BoardError, load_board

    target = args.name
    if target == "":
        sys.stderr.write("fsw new: NAME: an empty string names nothing: give the new project's folder "
                         "(fsw new myrig)\n")
        return 2
    last = os.path.basename(target.rstrip(os.sep) or os.sep)
    if last in (".", ".."):  # a folder that exists, by a name that names no project
        real = os.path.realpath(target)
        how = (f"from the folder above: cd .. && fsw new {shlex.quote(os.path.basename(real))}"
               if real == os.path.realpath(os.curdir) else f"name the folder itself: fsw new {shlex.quote(real)}")
        sys.stderr.write(f"fsw new: `{target}` names no project: a project is written into a new folder (or an "
                         f"empty one) whose name names its files and machine; {how}\n")
        return 2
    name = os.path.basename(os.path.normpath(target))
    try:
        board = load_board(args.board)
        texts = files(name, board)
    except (BoardError, ScaffoldError) as e:
        sys.stderr.write(f"fsw new: {e}\n")
        return 2
    except OSError as e:  # the starter script is made from the machine in a temporary folder
        sys.stderr.write(f"fsw new: cannot write a temporary file: {e.strerror or e}\n")
        return 1
    if os.path.islink(target.rstrip(os.sep) or target):  # the project would replace the link, not fill its folder
        real = os.path.realpath(target)
        where = f"the folder it names, {real}" if os.path.isdir(real) else "a new name"
        sys.stderr.write(f"fsw new: {target} is a symbolic link{'' if os.path.exists(real) else ' to nothing'}: "
                         f"a project is written into a new folder or an empty one; give {where}\n")
        return 1
    if os.path.exists(target) and (not os.path.isdir(target) or os.listdir(target)):
        sys.stderr.write(f"fsw new: {target} already exists: choose a new folder\n")
        return 1
    # written into a folder beside it that takes its name once every file is whole:
    # a full disk or Ctrl-C leaves no half project in the way of the next `fsw new`
    parent = os.path.dirname(os.path.abspath(target))
    stage = None
    try:
        stage = tempfile.mkdtemp(prefix=f".{name}.", suffix=".part", dir=parent)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(stage, 0o777 & ~umask)
        for fname in sorted(texts):
            with open(os.path.join(stage, fname), "w") as f:
                f.write(texts[fname])
        os.rename(stage, target)  # onto nothing, or onto an empty folder
        stage = None
    except OSError as e:
        inside = e.filename and stage and os.path.dirname(e.filename) == stage  # one file of the project
        where = os.path.join(target, os.path.basename(e.filename)) if inside else target
        sys.stderr.write(f"fsw new: cannot write {where}: {e.strerror or e}\n")
        return 1
    finally:
        if stage is not None:
            shutil.rmtree(stage, ignore_errors=True)
    print(f"fsw new: {name} for the {board.name} in {target}/")
    for fname in sorted(texts):
        print(f"  {fname}")
    print(f"next: cd {shlex.quote(target)} && fsw check . && fsw test {name}.ss && fsw build .")  # pasted as is
    return 0
