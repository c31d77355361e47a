#!/usr/bin/env python3
"""Benchmarks of the generated firmware (make bench): the tank machine's
cost per step on an ATmega2560 in simavr (cycles) and on x86-64 (callgrind
instructions), and the flash and RAM it adds to an Uno sketch; then the
whole rocket example's footprint on the Uno (flash, data + bss, the stack's
high-water mark measured on the simulated board through the demo flight, and
RAM with the stack) with a breakdown by component from the ELF's symbols.
Every number is a deterministic count, printed next to the reference
implementation's figure or the figure before (shared/targets.md) and our
target.

    tools/bench_firmware.py            # everything
    tools/bench_firmware.py rocket     # the rocket's footprint only
    tools/bench_firmware.py sensors    # the sensor drivers' flash and RAM only
    tools/bench_firmware.py core       # the rocket without what came after its size target
"""

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


# ---- the rocket example's footprint on the Uno ------------------------------------
ROCKET = os.path.join(ROOT, "examples", "rocket")
# shared/targets.md, second wave: "before (2026-11-23)" and the target.
BEFORE = {"flash": 10_400, "ram": 947, "stack": 220, "static": 727}
TARGET = {"flash": 8_192, "ram": 640}

# Components, first match wins: (name, test on a demangled symbol name).
_FLOAT = re.compile(r"^__(\w*sf\w*|fp_\w+|fixuns\w*|fix\w*sf\w*|float\w*|\w*sf3\w*|nan|inf)$")
_CRT = re.compile(r"^(__\w+|_exit|exit|abort|memcpy\w*|memmove|memset\w*|memcmp\w*|strlen\w*|"
                  r"_crc_\w+.*|__vector_default|__bad_interrupt)$")
_ARDUINO = re.compile(r"^(main|init|initVariant|micros|millis|delay\w*|pinMode|digitalWrite|digitalRead|"
                      r"analogRead|analogWrite|analogReference|turnOffPWM|timer0_\w+|__vector_16|"
                      r"(digital_pin|port|analog_pin)_to_\w+|yield|setup|loop)$")


def component(name: str, machines: tuple[str, ...]) -> str:
    """The component a symbol of the rocket's ELF belongs to (demangled name;
    `machines`: the application's machine names)."""
    ms = "|".join(machines)
    bare = re.sub(r" \[clone [^\]]*\]", "", name).replace("(anonymous namespace)::", "")
    bare = re.sub(r"\(.*$", "", bare)  # no argument list
    bare = re.sub(r"^_ZN12_GLOBAL__N_1\d+(\w+?)E.*$", r"\1", bare)  # LTO-private statics
    if bare == "main":
        return "main(): start-up, the loop and what they inline"
    if re.search(rf"fsw_gen::({ms})::|task_({ms})\b|fsw::machine_|fsw::roll_|ext_push|"
                 r"_read_key|fsw::(read|write)_F32|real_from_|round_to_f32|fsw::(\w+)_from_real", bare):
        return "generated machines + their runtime"
    if re.search(r"resume|pyro|time_base", bare, re.I):
        return "pyro gates + resuming after a reset"
    if re.search(r"link|cobs|crc|(^|::)put(_\w+)?$|frame_|send_control|send_batch|take_sample|tx_room|"
                 r"(^|::)apply$|service|pump|executor_owns|g_rx|g_tx|g_at|g_w|g_enc|console|uart|__vector_1[89]$",
                 bare, re.I):
        return "link + UART console"
    if re.search(r"Recorder|LogConfig|fsw::log_|fifo_put|^lround$", name):
        return "flight recorder"
    if re.search(r"ParamStore|ParamConfig|ParamDef|fsw::param_", name):
        return "parameters"
    if re.search(r"fsw::io_|task_(sense|act)|kAnalog|kDigital|fsw::(read|write)_elem|fsw::convert|"
                 r"cal_|adc|g_scan|__vector_21$", bare, re.I):
        return "I/O (sensing, outputs)"
    if _ARDUINO.match(bare):
        return "Arduino core"
    if re.search(r"fsw::executor|fsw_gen::(\w+::)*(ex|stats|kTasks|kConfig|kPeriodUs)$|fsw::pal::|clock|"
                 r"watchdog|fsw_capture_mcusr|fsw_paint_stack|fsw_mcusr|g_\w+_ext|inc16|timer|"
                 r"__vector_(7|11|14)$", bare, re.I):
        return "executor + clock"
    if re.search(r"fsw_gen::", bare):
        return "generated app (state vector, tables)"
    if _FLOAT.match(bare):
        return "float library"
    if _CRT.match(bare):
        return "C runtime (avr-libc, libgcc)"
    return "other"


def symbol_breakdown(elf: str, machines: tuple[str, ...]) -> dict[str, list[int]]:
    """{component: [flash bytes, RAM bytes]} from the ELF's sized symbols;
    flash is code and initialised data's image, RAM is .data + .bss +
    .noinit. What no sized symbol covers (vector table, padding, section
    alignment) is `unattributed`."""
    from fswkit.target.build import elf_symbols  # demangles the names LTO gave a suffix too

    out: dict[str, list[int]] = {}
    for addr, size, kind, name in elf_symbols(elf):
        if kind in "tTwW" and addr < 0x800000:
            row = out.setdefault(component(name, machines), [0, 0])
            row[0] += size
        elif kind in "dD" and addr >= 0x800000:
            row = out.setdefault(component(name, machines), [0, 0])
            row[0] += size
            row[1] += size
        elif kind in "bB" and addr >= 0x800000:
            row = out.setdefault(component(name, machines), [0, 0])
            row[1] += size
    flash, ram = elf_size(elf)
    noinit = elf_noinit(elf)
    out["unattributed (vectors, padding, constants)"] = [flash - sum(r[0] for r in out.values()),
                                                         ram + noinit - sum(r[1] for r in out.values())]
    return out


def elf_noinit(elf: str) -> int:
    text = sh(["avr-size", "-A", elf]).stdout
    m = re.search(r"^\.noinit\s+(\d+)", text, re.M)
    return int(m.group(1)) if m else 0


def rocket_footprint(project: str = ROCKET, out: str = "rocket") -> dict:
    """Builds the rocket (`project`: examples/rocket or a variant of it) as
    `fsw build` does, into OUT/`out`, flies the demo flight on the simulated
    Uno (the plant, seed 1) and reads the stack's high-water mark."""
    from fswkit.plant.run import SetupError, execute, prepare
    from fswkit.sim.command import build as build_for_sim

    built = build_for_sim(project, "uno", os.path.join(OUT, out))
    if isinstance(built, int):
        sys.exit(f"bench: building {project} failed")
    elf, board = built
    try:
        app, layout, sc = prepare(project, "rocket", seed=1)
    except SetupError as e:
        sys.exit(f"bench: {e}")
    flight = execute(sc, elf, board, layout, None, quiet=True)
    ram = flight.run.ram.get("ram_usage")
    if ram is None or isinstance(ram, str):
        sys.exit(f"bench: the rocket's stack was not measured: {ram}")
    flash, _ = elf_size(elf)
    return {"elf": elf, "flash": flash, "static": ram.static, "stack": ram.stack, "ram": ram.total,
            "passed": flight.report.passed,
            "parts": symbol_breakdown(elf, tuple(m.name for m in app.machines))}


def variant_project(tmp: str, edit) -> str:
    """A copy of examples/rocket in `tmp` that `edit(folder)` changed (None:
    as it is); its folder."""
    import shutil

    proj = os.path.join(tmp, "rocket")
    shutil.copytree(ROCKET, proj, ignore=shutil.ignore_patterns("build"))
    if edit is not None:
        edit(proj)
    return proj


def variant_size(edit, what: str) -> tuple[int, int]:
    """(flash, RAM: .data + .bss + .noinit) of a copy of examples/rocket
    that `edit(folder)` changed (None: as it is), built as `fsw sim` builds
    it; `what` names the variant in an error."""
    import tempfile

    from fswkit.sim.command import build as build_for_sim

    with tempfile.TemporaryDirectory(prefix="fsw-bench-variant-") as tmp:
        proj = variant_project(tmp, edit)
        built = build_for_sim(proj, "uno", os.path.join(tmp, "out"))
        if isinstance(built, int):
            sys.exit(f"bench: building the rocket {what} failed")
        flash, ram = elf_size(built[0])
        return flash, ram + elf_noinit(built[0])


def without_pyro(folder: str) -> None:
    app = os.path.join(folder, "rocket.app")
    text = open(app).read()
    open(app, "w").write(text[:text.index("[pyro]")])


def pyro_cost() -> tuple[tuple[int, int], tuple[int, int]]:
    """((flash, RAM) of the rocket, (flash, RAM) of the same rocket without
    its [pyro] section): what its two pyro channels cost with all that comes
    with them -- the gates, the continuity status, the health frame's
    status bytes, and keeping the flight across a reset (docs/safety.md).
    RAM is .data + .bss + .noinit."""
    return variant_size(None, "for the pyro cost"), variant_size(without_pyro, "without its pyro channels")


def without_later_features(folder: str) -> None:
    """Turns the copy of examples/rocket in `folder` into the rocket as the
    speed-and-scale target measured it (10,400 B, 2026-11-23), before the
    flight recorder, the parameters and the pyro channels came: no [log]
    (and no recorder task), no [pyro], the [parameters] as [local]
    constants of the same values."""
    without_pyro(folder)
    app = os.path.join(folder, "rocket.app")
    text = open(app).read()
    text = re.sub(r"(?m)^log\s+recorder\b.*\n", "", text)
    text = re.sub(r"\n\[log\].*?(?=\n\[)", "\n", text, flags=re.S)
    open(app, "w").write(text)
    sm = os.path.join(folder, "mission.sm")
    text = open(sm).read()
    start = text.index("[parameters]")
    end = text.index("\n[", start + 1)
    consts = re.sub(r"@\w+\s+\S+", "", text[start + len("[parameters]"):end]).strip("\n")
    text = text[:start] + text[end + 1:]
    local_end = text.index("\n[", text.index("[local]") + 1)
    open(sm, "w").write(text[:local_end] + "\n" + consts + "\n" + text[local_end:])


def core_footprint() -> dict:
    """rocket_footprint of examples/rocket without what came after the
    target was set (without_later_features), its stack measured through
    its own demo flight."""
    import tempfile

    with tempfile.TemporaryDirectory(prefix="fsw-bench-core-") as tmp:
        return rocket_footprint(variant_project(tmp, without_later_features), "core")


def print_core_size() -> None:
    r = core_footprint()
    print()
    print("the rocket as the 8 KB / 640 B target measured it (10,400 B flash, 727 B static RAM, 947 B with the "
          "stack, 2026-11-23): without the flight recorder, the parameters and the pyro channels that came after "
          f"(its demo flight, seed 1: {'all checks pass' if r['passed'] else 'CHECKS FAIL'})")
    print(f"  flash {r['flash']:,} B (target <= {TARGET['flash']:,} B: "
          f"{'ok' if r['flash'] <= TARGET['flash'] else 'MISSED'}); RAM with the stack {r['ram']:,} B "
          f"(target <= {TARGET['ram']} B: {'ok' if r['ram'] <= TARGET['ram'] else 'MISSED'}): "
          f"{r['static']:,} B static (.data + .bss + .noinit) + {r['stack']:,} B of stack (measured)")
    print(f"  {'component (from the ELF symbols)':<53} {'flash':>10} {'RAM':>8}")
    for name, (f, ram) in sorted(r["parts"].items(), key=lambda kv: -kv[1][0]):
        print(f"  {name:<53} {f:>8,} B {ram:>6,} B")


def print_pyro_cost() -> None:
    (f1, r1), (f0, r0) = pyro_cost()
    print()
    print("the rocket's two pyro channels (gates, continuity, health status, resuming after a reset): "
          f"+{f1 - f0:,} B flash ({f0:,} -> {f1:,}), +{r1 - r0:,} B RAM ({r0:,} -> {r1:,}, data + bss + noinit)")


SENSOR_ROWS = (  # (FSW_SENSOR of tools/bench/sensor_probe.cpp, row, the build it is measured over)
    (1, "TWI master (fsw_twi: ISR, queue of 4)", 0),
    (2, "BMP280 driver (over the TWI master)", 1),
    (3, "MS5611 driver (over the TWI master)", 1),
    (4, "ADXL345 driver on I2C (over the TWI master)", 1),
    (5, "ADXL345 driver on SPI (over the TWI master)", 1),
    (6, "MPU-6050 driver (over the TWI master)", 1),
)


def sensor_costs() -> list[tuple[str, int, int]]:
    """(row, flash, RAM) each sensor driver adds to an Uno sketch that
    steps it (tools/bench/sensor_probe.cpp, LTO as fsw build links), over
    the sketch with the TWI master alone; the TWI master's over an empty
    sketch. RAM is .data + .bss: the driver object and its share of the
    bus's state. The shared step references the TWI (its poll), so the
    SPI driver links the TWI master too: its row is over the TWI master."""
    libs = core_and_runtime("atmega328p", "standard", "ARDUINO_AVR_UNO")
    sizes = {}
    for n in range(7):
        elf = os.path.join(OUT, f"sensor_{n}.elf")
        sh(["avr-g++"] + avr_flags("atmega328p", "standard", "ARDUINO_AVR_UNO") +
           [f"-DFSW_SENSOR={n}", os.path.join(BENCH, "sensor_probe.cpp")] + libs +
           ["-fuse-linker-plugin", "-Wl,--gc-sections", "-o", elf])
        sizes[n] = elf_size(elf)
    return [(name, sizes[n][0] - sizes[base][0], sizes[n][1] - sizes[base][1]) for n, name, base in SENSOR_ROWS]


def print_sensor_costs() -> None:
    print()
    print("sensor drivers on the Uno (a sketch stepping one driver; flash .text + .data, RAM .data + .bss)")
    print(f"{'driver':<55} {'flash':>10} {'RAM':>8}")
    for name, flash, ram in sensor_costs():
        print(f"{name:<55} {flash:>8,} B {ram:>6,} B")


def print_rocket(r: dict) -> None:
    print()
    print("rocket example on the Uno (fsw build; stack measured through the demo flight, fsw sim --plant rocket "
          f"--seed 1: {'all checks pass' if r['passed'] else 'CHECKS FAIL'})")
    print(f"{'measure':<55} {'before':>10} {'target':>12} {'measured':>10}")
    rows = [
        ("flash (.text + .data)", f"{BEFORE['flash']:,} B", f"<= {TARGET['flash']:,} B", f"{r['flash']:,} B",
         r["flash"] <= TARGET["flash"]),
        ("static RAM (.data + .bss + .noinit)", f"{BEFORE['static']:,} B", "-", f"{r['static']:,} B", True),
        ("stack high-water (measured)", f"{BEFORE['stack']:,} B", "-", f"{r['stack']:,} B", True),
        ("RAM incl. stack", f"{BEFORE['ram']:,} B", f"<= {TARGET['ram']:,} B", f"{r['ram']:,} B",
         r["ram"] <= TARGET["ram"]),
    ]
    for name, before, target, got, ok in rows:
        print(f"{name:<55} {before:>10} {target:>12} {got:>10}  {'ok' if ok else 'MISSED'}")
    over_f, over_r = r["flash"] - TARGET["flash"], r["ram"] - TARGET["ram"]
    if over_f > 0 or over_r > 0:
        print(f"  still to find: {max(over_f, 0):,} B of flash, {max(over_r, 0):,} B of RAM")
    print(f"  {'component (from the ELF symbols)':<53} {'flash':>10} {'RAM':>8}")
    parts = sorted(r["parts"].items(), key=lambda kv: -kv[1][0])
    for name, (f, ram) in parts:
        print(f"  {name:<53} {f:>8,} B {ram:>6,} B")
    print(f"  {'stack high-water':<53} {'':>10} {r['stack']:>6,} B")


def main() -> int:
    os.makedirs(OUT, exist_ok=True)
    if sys.argv[1:] == ["rocket"]:
        print_rocket(rocket_footprint())
        return 0
    if sys.argv[1:] == ["pyro"]:
        print_pyro_cost()
        return 0
    if sys.argv[1:] == ["core"]:
        print_core_size()
        return 0
    if sys.argv[1:] == ["sensors"]:
        print_sensor_costs()
        return 0
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
    print_rocket(rocket_footprint())
    print_core_size()
    print_pyro_cost()
    print_sensor_costs()
    return 0


if __name__ == "__main__":
    sys.exit(main())
