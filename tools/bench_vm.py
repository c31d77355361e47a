#!/usr/bin/env python3
"""What the bytecode VM costs on an AVR (not a test): the tank example
stepped as generated code and as an image through fsw::vm_step.

    .venv/bin/python tools/bench_vm.py   (make bench)

Flash and RAM of an Uno sketch (empty / generated tank / VM + tank image,
image in RAM as a loader receives it), and the tank step's cycles on an
ATmega2560 in simavr, with tools/bench_firmware.py's builds and flags."""

from __future__ import annotations

import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)

import bench_firmware as B  # noqa: E402
from fswkit.autocode.emit.bytecode import compile_machine, window_ram  # noqa: E402
from fswkit.autocode.numeric import F32MODE  # noqa: E402
from fswkit.autocode.vmverify import TYPE_CODES, feature_names, features_of  # noqa: E402
from fswkit.target.build import elf_symbols  # noqa: E402


def image_header(folder: str) -> tuple[int, int, int]:
    """Writes the tank's image and layout for vm_probe.cpp, and the VM's
    features as a board with the tank's layout and machine has them
    (examples/stand's); (the image's bytes, the state vector's bytes, the
    features)."""
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.project import load_machine

    m = load_machine(os.path.join(ROOT, "examples", "tank", "tank.sm"), Diagnostics())
    im = compile_machine(m, F32MODE)
    elems = ", ".join(f"{{{e.offset}, {TYPE_CODES[e.type.name]}}}" for e in m.sv.elements)
    with open(os.path.join(folder, "tank_image.h"), "w") as f:
        f.write(f"uint8_t kImage[] = {{{', '.join(str(b) for b in im)}}};\n"
                f"const fsw::VmElem kElems[] FSW_FLASH = {{{elems}}};\n"
                f"const uint16_t kElemCount = {len(m.sv.elements)};\n"
                f"const uint16_t kRam = {window_ram(m, F32MODE, idx_bytes=2, align=1)};\n"
                f"extern const uint16_t fsw::vm_features = {features_of(m.sv, m)};\n")
    return len(im), max(e.offset + e.type.size for e in m.sv.elements), features_of(m.sv, m)


def build(mcu: str, variant: str, define: str, probe: int, timing: bool, gen: str) -> str:
    libs = B.core_and_runtime(mcu, variant, define)
    elf = os.path.join(B.OUT, f"vm_{mcu}_{probe}_{int(timing)}.elf")
    extra = [os.path.join(gen, "sv.gen.cpp")] + ([os.path.join(gen, "tank.gen.cpp")] if probe == 1 else [])
    B.sh(["avr-g++"] + B.avr_flags(mcu, variant, define) +
         [f"-I{gen}", f"-DFSW_VM_PROBE={probe}", f"-DFSW_VM_TIMING={int(timing)}",
          os.path.join(HERE, "bench", "vm_probe.cpp")] + extra + libs +
         ["-fuse-linker-plugin", "-Wl,--gc-sections", "-o", elf])
    return elf


def cycles(elf: str) -> tuple[int, int, int]:
    r = subprocess.run([B.harness(), "-u", "stdout", "-m", "atmega2560", "-t", "20", "-w", "60", elf],
                       capture_output=True, text=True)
    m = re.search(r"cycles (\d+) worst (\d+) overhead (\d+) state (\d+)", r.stdout + r.stderr)
    if not m:
        sys.exit(f"bench_vm: no measurement:\n{r.stdout}{r.stderr}")
    avg, worst, over, state = (int(x) for x in m.groups())
    return avg - over, worst - over, state


def main() -> int:
    gen = os.path.join(B.OUT, "vm-tank-f32")
    B.generate(F32MODE, gen)
    size, sv, feats = image_header(gen)
    uno = ("atmega328p", "standard", "ARDUINO_AVR_UNO")
    elfs = [build(*uno, p, False, gen) for p in (0, 1, 2)]
    s = [B.elf_size(elf) for elf in elfs]
    print(f"tank image: {size} bytes; the VM's features: {', '.join(feature_names(feats)) or 'none'}")
    print(f"Uno, empty sketch:          flash {s[0][0]:6,}  RAM {s[0][1]:5,}")
    print(f"Uno, generated tank:        flash {s[1][0]:6,}  RAM {s[1][1]:5,}  "
          f"(+{s[1][0] - s[0][0]:,} / +{s[1][1] - s[0][1]:,})")
    print(f"Uno, VM + tank image (RAM): flash {s[2][0]:6,}  RAM {s[2][1]:5,}  "
          f"(+{s[2][0] - s[0][0]:,} / +{s[2][1] - s[0][1]:,}; the image itself {size} of each)")
    mega = ("atmega2560", "mega", "ARDUINO_AVR_MEGA2560")
    avgs = []
    for p, what in ((1, "generated"), (2, "VM")):
        avg, worst, state = cycles(build(*mega, p, True, gen))
        avgs.append(avg)
        print(f"tank step, {what:9} ATmega2560: avg {avg:,} cycles, worst {worst:,} (state {state})")
    vm_flash = s[2][0] - s[0][0] - size
    vm_ram = s[2][1] - s[0][1] - size
    # what the VM probe's RAM holds beyond the bare sketch's, by symbol
    ram_syms = {i: {name: size for _addr, size, kind, name in elf_symbols(elfs[i]) if kind in "bBdD"}
                for i in (0, 2)}
    extra = {k.replace("(anonymous namespace)::", ""): v for k, v in ram_syms[2].items() if k not in ram_syms[0]}
    legend = {"machine": "the machine's record, as generated code has", "ram": "the image's windows and locals",
              "kLayout": "the state vector's layout the image is checked against"}
    print("  the VM probe's RAM beyond the bare sketch's, by symbol: "
          + ", ".join(f"{k} {v}" for k, v in sorted(extra.items(), key=lambda kv: -kv[1]))
          + " (" + "; ".join(f"{k}: {what}" for k, what in legend.items() if any(k in name for name in extra)) + ")")
    beyond, gen_ram = vm_ram - sv, s[1][1] - s[0][1]
    print(f"VM against its targets: flash {vm_flash:,} B without the image (target <= 3,072: "
          f"{'met' if vm_flash <= 3072 else 'MISSED'}), RAM {vm_ram:,} B: {beyond:,} B beyond the tank's {sv} B state "
          f"vector (target <= 64: {'met' if beyond <= 64 else 'MISSED'}; the generated tank's machine, locals and "
          f"state vector take {gen_ram} B, the VM {vm_ram - gen_ram:,} B more), tank step {avgs[1] / avgs[0]:.1f}x "
          f"the generated code's (target <= 3x: {'met' if avgs[1] <= 3 * avgs[0] else 'MISSED'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
