#!/usr/bin/env python3
"""Benchmarks of the generated firmware (make bench): the tank machine's
cost per step on an ATmega2560 in simavr (cycles) and on x86-64 (callgrind
instructions), and the flash and RAM it adds to an Uno sketch. Every number
is a deterministic count, printed next to the reference implementation's
figure and our target (shared/targets.md)."""

from __future__ import annotations

import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.emit.machine import emit_machine
from fswkit.autocode.emit.sv import emit_sv
from fswkit.autocode.numeric import F32MODE, F64MODE
from fswkit.autocode.project import load_machine
from fswkit.sim.board import harness

OUT = os.path.join(ROOT, "build", "bench")
RUNTIME = os.path.join(ROOT, "firmware", "src")
ARDUINO = "/usr/share/arduino/hardware/arduino/avr"
BENCH = os.path.join(ROOT, "tools", "bench")


def sh(cmd, **kw) -> subprocess.CompletedProcess:
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0 and not kw.get("check") is False:
        sys.stderr.write(f"bench: command failed: {' '.join(cmd)}\n{r.stdout[-2000:]}{r.stderr[-4000:]}")
        sys.exit(1)
    return r


def generate(real, folder: str) -> None:
    diags = Diagnostics()
    m = load_machine(os.path.join(ROOT, "examples", "tank", "tank.sm"), diags)
    if m is None:
        sys.exit(diags.render())
    os.makedirs(folder, exist_ok=True)
    files = dict(emit_sv(m.sv))
    files.update(emit_machine(m, real))
    for name, text in files.items():
        with open(os.path.join(folder, name), "w") as f:
            f.write(text)


def avr_flags(mcu: str, variant: str, define: str) -> list[str]:
    return ["-std=gnu++11", "-Os", "-flto", "-ffunction-sections", "-fdata-sections", "-fno-exceptions",
            "-fno-rtti", "-fno-threadsafe-statics", "-DDECIMAL_DIG=__DECIMAL_DIG__", f"-mmcu={mcu}",
            "-DF_CPU=16000000L", "-DARDUINO=10819", f"-D{define}", "-DARDUINO_ARCH_AVR",
            f"-I{ARDUINO}/cores/arduino", f"-I{ARDUINO}/variants/{variant}", f"-I{RUNTIME}"]


def core_and_runtime(mcu: str, variant: str, define: str) -> list[str]:
    """Builds the Arduino core and the runtime for an MCU with mk/build.mk's
    rules (an application with no generated files); returns the archives."""
    out = os.path.join(OUT, f"lib-{mcu}")
    gen = os.path.join(out, "nogen")
    os.makedirs(gen, exist_ok=True)
    args = ["make", "--no-print-directory", "-j2", "-f", os.path.join(ROOT, "mk", "build.mk"), f"GEN={gen}",
            f"OUT={out}", "NAME=x", f"MCU={mcu}", "F_CPU=16000000", f"VARIANT={variant}",
            f"BOARD_DEFINE={define}", os.path.join(out, "libfswkit.a"), os.path.join(out, "core.a")]
    sh(args)
    return [os.path.join(out, "libfswkit.a"), os.path.join(out, "core.a")]


def elf_size(elf: str) -> tuple[int, int]:
    text = sh(["avr-size", "-A", elf]).stdout
    sec = {m.group(1): int(m.group(2)) for m in re.finditer(r"^(\.\w+)\s+(\d+)", text, re.M)}
    return sec.get(".text", 0) + sec.get(".data", 0), sec.get(".data", 0) + sec.get(".bss", 0)


def avr_cycles() -> tuple[int, int]:
    gen = os.path.join(OUT, "tank-f32")
    generate(F32MODE, gen)
    libs = core_and_runtime("atmega2560", "mega", "ARDUINO_AVR_MEGA2560")
    elf = os.path.join(OUT, "tank_mega.elf")
    sh(["avr-g++"] + avr_flags("atmega2560", "mega", "ARDUINO_AVR_MEGA2560") + [f"-I{gen}",
        os.path.join(BENCH, "tank_driver.cpp"), os.path.join(gen, "sv.gen.cpp"), os.path.join(gen, "tank.gen.cpp")]
       + libs + ["-fuse-linker-plugin", "-Wl,--gc-sections", "-o", elf])
    r = subprocess.run([harness(), "-u", "stdout", "-m", "atmega2560", "-t", "10", "-w", "60", elf],
                       capture_output=True, text=True)
    m = re.search(r"cycles (\d+) worst (\d+) overhead (\d+) state (\d+)", r.stdout + r.stderr)
    if not m:
        sys.exit(f"bench: no measurement from simavr:\n{r.stdout}{r.stderr}")
    avg, worst, overhead, state = (int(x) for x in m.groups())
    if state != 1:
        sys.exit("bench: the tank machine left TankVentControl during the measurement")
    return avg - overhead, worst - overhead


def x86_instructions() -> float:
    gen = os.path.join(OUT, "tank-f64")
    generate(F64MODE, gen)
    exe = os.path.join(OUT, "tank_driver")
    srcs = [os.path.join(RUNTIME, n) for n in ("fsw_convert.cpp", "fsw_f64.cpp", "fsw_machine.cpp", "fsw_window.cpp")]
    sh(["g++", "-std=gnu++11", "-O2", "-ffp-contract=off", f"-I{RUNTIME}", f"-I{gen}",
        os.path.join(BENCH, "tank_driver.cpp"), os.path.join(gen, "sv.gen.cpp"), os.path.join(gen, "tank.gen.cpp")]
       + srcs + ["-o", exe])

    # Only instructions inside step() count; 1000 steps all run TankVentControl.
    n = 1000
    r = sh(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null",
            "--toggle-collect=fsw_gen::tank::step()", exe, str(n)])
    return int(re.search(r"refs:\s+([\d,]+)", r.stderr).group(1).replace(",", "")) / n


def avr_footprint() -> tuple[int, int]:
    gen = os.path.join(OUT, "tank-f32")
    generate(F32MODE, gen)
    libs = core_and_runtime("atmega328p", "standard", "ARDUINO_AVR_UNO")
    sizes = []
    for tank in (0, 1):
        elf = os.path.join(OUT, f"size_{tank}.elf")
        extra = [os.path.join(gen, "sv.gen.cpp"), os.path.join(gen, "tank.gen.cpp")] if tank else []
        sh(["avr-g++"] + avr_flags("atmega328p", "standard", "ARDUINO_AVR_UNO") +
           [f"-I{gen}", f"-DFSW_SIZE_TANK={tank}", os.path.join(BENCH, "size_probe.cpp")] + extra + libs +
           ["-fuse-linker-plugin", "-Wl,--gc-sections", "-o", elf])
        sizes.append(elf_size(elf))
    (f0, r0), (f1, r1) = sizes
    return f1 - f0, r1 - r0


def main() -> int:
    os.makedirs(OUT, exist_ok=True)
    avg, worst = avr_cycles()
    instr = x86_instructions()
    flash, ram = avr_footprint()
    rows = [
        ("tank step, ATmega2560 @16 MHz (simavr cycles, avg)", "4,948", "<= 500", f"{avg:,}", avg <= 500),
        ("tank step, ATmega2560, worst", "5,576", "-", f"{worst:,}", True),
        ("tank step, x86-64 -O2 (callgrind instructions)", "639", "<= 64", f"{instr:.1f}", instr <= 64),
        ("tank machine + state vector, Uno flash added", "17,704 B", "<= 3,000 B", f"{flash:,} B", flash <= 3000),
        ("tank machine + state vector, Uno RAM added", "~2.7 KB", "<= 96 B", f"{ram:,} B", ram <= 96),
    ]
    print(f"{'measure':<55} {'reference':>10} {'target':>12} {'measured':>10}")
    for name, ref, target, got, ok in rows:
        print(f"{name:<55} {ref:>10} {target:>12} {got:>10}  {'ok' if ok else 'MISSED'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
