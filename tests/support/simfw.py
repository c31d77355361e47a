"""Firmware for the simulated-board tests, and the host builds of the link
tests, built into build/sim-tests/ (kept between runs, so rebuilds are
incremental, and shared by the test files that build the same project),
and the fixtures that build it once per session."""

from __future__ import annotations

import hashlib
import os
import subprocess
from pathlib import Path

import pytest

from conftest import ROOT, run_fsw

OUT = ROOT / "build" / "sim-tests"
BUILD_MK = ROOT / "mk" / "build.mk"
BOARD_MAKE = {
    "uno": ["MCU=atmega328p", "F_CPU=16000000", "VARIANT=standard", "BOARD_DEFINE=ARDUINO_AVR_UNO"],
    "mega2560": ["MCU=atmega2560", "F_CPU=16000000", "VARIANT=mega", "BOARD_DEFINE=ARDUINO_AVR_MEGA2560"],
}

# An Arduino sketch that exercises the board's I/O: a banner and an echo on
# the serial port, PWM on pins 3 and 9, pin 5 driven high, pin 8 mirroring
# input pin 7.
PROBE_SKETCH = r"""
#include <Arduino.h>
void setup() {
    Serial.begin(115200);
    analogWrite(3, 64);
    analogWrite(9, 200);
    pinMode(5, OUTPUT);
    digitalWrite(5, HIGH);
    pinMode(7, INPUT);
    pinMode(8, OUTPUT);
    Serial.print("probe ready\n");
}
void loop() {
    digitalWrite(8, digitalRead(7));
    int c = Serial.read();
    if (c >= 0) Serial.write((uint8_t)c);
}
"""

# A sketch that recurses DEPTH levels, 32 bytes of locals a level, then
# stops itself: its stack high-water mark grows by one frame a level.
DIVE_SKETCH = r"""
#include <Arduino.h>
#include <avr/sleep.h>
#include "fswkit.h"
volatile uint8_t sink;
__attribute__((noinline)) static uint8_t dive(uint8_t n) {
    volatile uint8_t local[32];
    local[0] = n;
    local[31] = n;
    const uint8_t below = n == 0 ? 0 : dive(static_cast<uint8_t>(n - 1));
    return static_cast<uint8_t>(below + local[0] + local[31]);
}
void setup() {
    fsw::pal::begin();  // links the fswkit platform layer, and with it the boot-time stack paint
    sink = dive(DEPTH);
    cli();
    sleep_enable();
    sleep_cpu();
}
void loop() {}
"""

SPIN_C = "int main(void) { for (;;) { __asm__ volatile(\"nop\"); } }\n"
HALT_C = "#include <avr/interrupt.h>\n#include <avr/sleep.h>\n" \
         "int main(void) { cli(); sleep_enable(); sleep_cpu(); for (;;) {} }\n"


def project_elf(project: str, board: str) -> str:
    """`fsw build PROJECT --board BOARD` into build/sim-tests/; the ELF."""
    name = os.path.basename(project.rstrip("/"))
    out = OUT / f"{name}-{board}"
    r = run_fsw("build", str(project), "--board", board, "--out", str(out))
    assert r.code == 0, r.err
    return str(out / f"{name}.elf")


def kept_folder(project, board: str) -> Path:
    """The folder in build/sim-tests/ that keeps `project`'s build for
    `board` ("own": the board its configs name), named by the project's
    folder and its real path (two projects of one name, two folders)."""
    path = Path(project).resolve()
    return OUT / f"{path.name}-{board}-{hashlib.sha1(str(path).encode()).hexdigest()[:8]}"


def kept_native(project) -> Path:
    """`fsw build PROJECT --board native` into build/sim-tests/ (kept
    between runs: make rebuilds what changed, the firmware's sources, the
    generated code or the flags; the build holds its folder, so test
    files and xdist workers building the same project take turns and the
    later finds it up to date); the build folder, which holds the
    executable named after the application file."""
    out = kept_folder(project, "native")
    r = run_fsw("build", str(project), "--board", "native", "--out", str(out))
    assert r.code == 0, r.err
    return out


def kept_sim(project):
    """`project`'s firmware for its own board as `fsw sim` builds it
    (fswkit.sim.command.build), into build/sim-tests/ as `kept_native`
    keeps its builds; (its ELF, its board)."""
    from fswkit.sim.command import build

    built = build(str(project), out=str(kept_folder(project, "own")))
    assert not isinstance(built, int), f"{project} did not build"
    return built


def sketch_elf(name: str, source: str, board: str = "uno", defines: tuple[str, ...] = ()) -> str:
    """An Arduino sketch built with mk/build.mk (the Arduino core's flags),
    with `defines` (`FSW_X=1`) for the core, the runtime and the sketch.
    Without `defines` it links the board's Arduino core and runtime from
    the kit's cache (fswkit.target.libcache), as `fsw build` does: the
    archives compiled once for every build of the board, not again in
    each sketch's folder (about 1.5 s of CPU a sketch on a fresh clone)."""
    from fswkit.target.build import ARDUINO, build_lock
    from fswkit.target.libcache import avr_tools_key, make_vars

    out = OUT / (f"{name}-{board}" + "".join(f"-{d.lower().replace('=', '')}" for d in defines))
    gen = out / "src"
    with build_lock(str(out), "test"):  # another test session may build the same sketch
        gen.mkdir(parents=True, exist_ok=True)
        path = gen / f"{name}.cpp"
        if not path.exists() or path.read_text() != source:
            path.write_text(source)
        avr = dict(arg.split("=", 1) for arg in BOARD_MAKE[board])
        cached = [f"AVR_TOOLS_KEY={avr_tools_key(avr['MCU'])}"]  # as `fsw build` passes it
        if not defines:  # the cache's archives are the board's without EXTRA_DEFS
            cached += [f"LIBS={out / v[5:]}" if v.startswith("LIBS=") else v  # make runs outside `out` here
                       for v in make_vars(str(out), dict(avr, F_CPU=int(avr["F_CPU"]), ARDUINO=ARDUINO), 2)]
        r = subprocess.run(["make", "--no-print-directory", "-j2", "-f", str(BUILD_MK), f"GEN={gen}", f"OUT={out}",
                            f"NAME={name}", "avr", "EXTRA_DEFS=" + " ".join(f"-D{d}" for d in defines)]
                           + BOARD_MAKE[board] + cached, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-4000:]
    return str(out / f"{name}.elf")


def c_elf(name: str, source: str, mcu: str = "atmega328p") -> str:
    """A bare C program for the MCU, no Arduino core."""
    from fswkit.target.build import build_lock

    src = OUT / f"{name}.c"
    elf = OUT / f"{name}-{mcu}.elf"
    with build_lock(str(OUT), "test"):
        src.write_text(source)
        r = subprocess.run(["avr-gcc", f"-mmcu={mcu}", "-Os", "-o", str(elf), str(src)], capture_output=True,
                           text=True)
    assert r.returncode == 0, r.stderr
    return str(elf)


@pytest.fixture(scope="session")
def tank_uno() -> str:
    return project_elf(str(ROOT / "examples" / "tank"), "uno")


@pytest.fixture(scope="session")
def tank_mega() -> str:
    return project_elf(str(ROOT / "examples" / "tank"), "mega2560")


@pytest.fixture(scope="session")
def toggle_uno() -> str:
    return project_elf(str(ROOT / "tests" / "sim" / "toggle"), "uno")


@pytest.fixture(scope="session")
def probe_uno() -> str:
    return sketch_elf("probe", PROBE_SKETCH)


@pytest.fixture(scope="session")
def dive_uno() -> dict[int, str]:
    """The recursion sketch at two depths: {depth: ELF}."""
    return {d: sketch_elf(f"dive{d}", DIVE_SKETCH.replace("DEPTH", str(d))) for d in (8, 16)}


@pytest.fixture(scope="session")
def spin_uno() -> str:
    return c_elf("spin", SPIN_C)


@pytest.fixture(scope="session")
def halt_uno() -> str:
    return c_elf("halt", HALT_C)
