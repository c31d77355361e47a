"""Generated machines and scripts on a simulated ATmega2560 (simavr):
binary32 R with avr-libc's and libgcc's own float code, the way a board runs
them. Each case is the machine's generated C++ plus emit_script_avr's
runner; several cases link into one ELF, whose `main` runs them in turn and
sends everything over UART0 at 2 Mbaud:

    'C' key(uint16)   a case starts
    'R' row           after each step: every variable, 8 bytes (see emit_script_avr)
    'E' outcome(1) failed_assert(int16) steps(uint64) asserts(uint64)
    'Z'               all cases done (then the firmware sleeps, interrupts off)

The kit's simulated board (host-tools/fswkit/sim/harness.c, free-running
with `-u stdout -x done`) runs the ELF and copies those bytes out."""

from __future__ import annotations

import hashlib
import os
import shutil
import struct
import subprocess
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Callable

from fswkit.run import native, windows
from fswkit.autocode import model as M
from fswkit.autocode.check import failure_diagnostics
from fswkit.autocode.emit.common import c_ident
from fswkit.autocode.emit.machine import emit_machine
from fswkit.autocode.emit.script import emit_script_avr, script_writes_locals
from fswkit.autocode.emit.sv import emit_sv
from fswkit.autocode.numeric import F32MODE

from fswkit.sim.board import harness as sim_harness
import harness as H
from harness import cache_dir

HERE = os.path.dirname(os.path.abspath(__file__))
MCU = "atmega2560"
AVR_CXX = os.environ.get("AVR_CXX", "avr-g++")
AVR_FLAGS = ["-mmcu=" + MCU, "-DF_CPU=16000000L", "-DARDUINO=10819", "-DARDUINO_AVR_MEGA2560",
             "-DARDUINO_ARCH_AVR", "-std=gnu++11", "-Os", "-ffp-contract=off", "-fno-exceptions", "-fno-rtti",
             "-fno-threadsafe-statics", "-ffunction-sections", "-fdata-sections",
             "-Wall", "-Wextra", "-Werror", "-Wno-unused-function"]
# The runtime files a machine and its runner use (no PSL: no Arduino core).
RUNTIME_FILES = ("fsw_convert.cpp", "fsw_element.cpp", "fsw_f64.cpp", "fsw_machine.cpp", "fsw_window.cpp")


def available() -> str | None:
    """None when the AVR toolchain and simavr are here, else what is missing."""
    for tool in (AVR_CXX, "avr-ar", "avr-size", "gcc"):
        if shutil.which(tool) is None:
            return f"{tool} not installed"
    if not os.path.exists("/usr/include/simavr/sim_avr.h"):
        return "libsimavr-dev not installed"
    return None


def _run(cmd: list[str]) -> str:
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise native.NativeError(" ".join(cmd) + "\n" + r.stderr[-6000:])
    return r.stdout


def run_uart(elf: str, out: str, *, sim_s: float = 600, wall: float = 120) -> None:
    """Runs an ELF on the simulated board until the firmware stops itself
    (sleeps with interrupts off), every byte it sends on UART0 copied
    unchanged into the file `out`; NativeError if it crashed or a limit
    (simulated seconds, wall-clock seconds) ended the run first."""
    with open(out, "wb") as f:
        r = subprocess.run([sim_harness(), "-u", "stdout", "-x", "done", "-m", MCU, "-t", str(sim_s), "-w", str(wall),
                            elf], stdout=f, stderr=subprocess.PIPE)
    if r.returncode != 0:
        raise native.NativeError(f"simavr run failed (status {r.returncode}): {r.stderr.decode()[-2000:]}")


def _cached_object(text: str, name: str, workdir: str, include: list[str], key: bytes) -> str:
    h = hashlib.sha256(key + text.encode() + " ".join([AVR_CXX] + AVR_FLAGS).encode()).hexdigest()[:24]
    obj = os.path.join(cache_dir(), "avr", h + ".o")
    if os.path.exists(obj):
        os.utime(obj)  # recently used: kept by harness.prune_cache
        return obj
    os.makedirs(os.path.dirname(obj), exist_ok=True)
    src = os.path.join(workdir, name)
    with open(src, "w") as f:
        f.write(text)
    # test_simavr.py and test_bytecode_avr.py share the runtime's objects and may build them at once
    tmp = f"{obj}.{os.getpid()}.{threading.get_ident()}.tmp"
    _run([AVR_CXX] + AVR_FLAGS + ["-I", native.RUNTIME] + [x for d in include for x in ("-I", d)]
         + ["-c", src, "-o", tmp])
    os.replace(tmp, obj)
    return obj


def _runtime_key() -> bytes:
    h = hashlib.sha256()
    for n in sorted(os.listdir(native.RUNTIME)):
        with open(os.path.join(native.RUNTIME, n), "rb") as f:
            h.update(n.encode() + b"\0" + f.read())
    return h.digest()


@dataclass
class AvrOutcome:
    rows: bytes  # the trace rows, concatenated (emit_script's raw trace format)
    outcome: int  # 0 passed, 1 assert failed, 2 max_steps, 3 step error
    failed_assert: int
    steps: int
    asserts: int


def _main_cpp(keys: list[int]) -> str:
    c = ["#include <avr/interrupt.h>", "#include <avr/io.h>", "#include <avr/sleep.h>", "#include <stdint.h>", "",
         "void fsw_trace_write(const uint8_t* data, uint16_t len) {",
         "    for (uint16_t i = 0; i < len; ++i) {",
         "        while ((UCSR0A & (1 << UDRE0)) == 0) {}",
         "        UDR0 = data[i];",
         "    }",
         "}", ""]
    c += [f"namespace fsw_c{k} {{ int run_script(); }}" for k in keys]
    c += ["", "static void begin_case(uint16_t key) {",
          "    uint8_t b[3] = {'C', static_cast<uint8_t>(key), static_cast<uint8_t>(key >> 8)};",
          "    fsw_trace_write(b, 3);", "}", "",
          "int main() {",
          "    UBRR0 = 0;  // 2 Mbaud at 16 MHz with U2X0",
          "    UCSR0A = 1 << U2X0;",
          "    UCSR0B = 1 << TXEN0;",
          "    UCSR0C = 3 << UCSZ00;"]
    for k in keys:
        c += [f"    begin_case({k});", f"    fsw_c{k}::run_script();"]
    c += ["    const uint8_t z[4] = {'Z', 0, 0, 0};  // the padding leaves while the Z is on the wire",
          "    fsw_trace_write(z, 4);",
          "    cli();", "    sleep_enable();", "    sleep_cpu();", "    return 0;", "}", ""]
    return "\n".join(c)


def build_elf(workdir: str, items: list[tuple[int, M.Script]], pool: ThreadPoolExecutor,
              per_tu: int = 4, machine_cpp: Callable[[M.Script, str], str] | None = None) -> str:
    """One ELF running every case of `items` in turn. `machine_cpp(script,
    ns)`, when given, writes the `<machine>.gen.cpp` that replaces the
    generated one (the header stays as emitted), and the runtime's VM
    (fsw_vm.cpp) is linked in: vm_harness.vm_shim with avr=True."""
    key = _runtime_key()
    runtime = RUNTIME_FILES + (("fsw_vm.cpp",) if machine_cpp is not None else ())
    rt = [pool.submit(_cached_object, open(os.path.join(native.RUNTIME, n)).read(), "rt_" + n, workdir,
                      [native.RUNTIME], key) for n in runtime]
    tus = []
    for start in range(0, len(items), per_tu):
        lines, tkey = [], hashlib.sha256(key)
        for k, script in items[start:start + per_tu]:
            m = script.machine
            files = {}
            files.update(emit_sv(m.sv, f"fsw_c{k}"))
            files.update(emit_machine(m, F32MODE, scriptable=script_writes_locals(script), ns=f"fsw_c{k}"))
            files.update(emit_script_avr(script, F32MODE, ns=f"fsw_c{k}"))
            if machine_cpp is not None:
                files[f"{c_ident(m.name)}.gen.cpp"] = machine_cpp(script, f"fsw_c{k}")
            d = os.path.join(workdir, f"c{k}")
            os.makedirs(d, exist_ok=True)
            for name in sorted(files):
                with open(os.path.join(d, name), "w") as f:
                    f.write(files[name])
                tkey.update(f"c{k}/{name}\0".encode() + files[name].encode())
            machine = [n for n in sorted(files) if n.endswith(".gen.cpp") and n != "sv.gen.cpp"][0]
            lines += [f'#include "c{k}/sv.gen.cpp"', f'#include "c{k}/{machine}"', f'#include "c{k}/script_avr.cpp"']
        tus.append(pool.submit(_cached_object, "\n".join(lines) + "\n", f"tu{start}.cpp", workdir, [workdir],
                               tkey.digest()))
    main_cpp = _main_cpp([k for k, _ in items])
    if machine_cpp is not None:  # a VM with every feature (fsw_vm.h)
        main_cpp += '#include "fsw_vm.h"\nextern const uint16_t fsw::vm_features = fsw::kVmAllFeatures;\n'
    main = pool.submit(_cached_object, main_cpp, "main.cpp", workdir, [], key if machine_cpp else b"")
    objs = [f.result() for f in tus] + [main.result()]
    lib = os.path.join(workdir, "libfsw.a")
    if os.path.exists(lib):
        os.remove(lib)
    _run(["avr-ar", "rcs", lib] + [f.result() for f in rt])
    elf = os.path.join(workdir, "cases.elf")
    _run([AVR_CXX, "-mmcu=" + MCU, "-Os", "-Wl,--gc-sections", "-o", elf] + objs + [lib])
    return elf


def memory(elf: str) -> tuple[int, int]:
    """(flash, RAM) bytes of an ELF: text + data, data + bss."""
    out = _run(["avr-size", "-A", elf])
    sizes = {}
    for line in out.splitlines():
        parts = line.split()
        if len(parts) >= 2 and parts[0].startswith(".") and parts[1].isdigit():
            sizes[parts[0]] = int(parts[1])
    return sizes.get(".text", 0) + sizes.get(".data", 0), sizes.get(".data", 0) + sizes.get(".bss", 0)


def run_elf(elf: str, items: list[tuple[int, M.Script]], wall: float = 120) -> dict[int, AvrOutcome]:
    """Runs the ELF under simavr; each case's outcome, decoded."""
    path = elf + ".uart"
    run_uart(elf, path, wall=wall)
    with open(path, "rb") as f:
        data = f.read()
    pos = 0
    nvars = {k: len(s.machine.vars) for k, s in items}
    out: dict[int, AvrOutcome] = {}
    while True:
        tag = data[pos:pos + 1]
        if tag == b"Z":
            break
        if tag != b"C":
            raise native.NativeError(f"bad AVR output at byte {pos}: {data[pos:pos + 16]!r}")
        k = struct.unpack_from("<H", data, pos + 1)[0]
        pos += 3
        size = 8 * nvars[k]
        rows = bytearray()
        while data[pos:pos + 1] == b"R":
            rows += data[pos + 1:pos + 1 + size]
            pos += 1 + size
        if data[pos:pos + 1] == b"V":  # vm_harness.vm_shim: the board's vm_verify refused the image
            raise native.NativeError(f"case {k}: vm_verify refused the image on the board: reason {data[pos + 1]}")
        if data[pos:pos + 1] != b"E":
            raise native.NativeError(f"case {k}: no end record at byte {pos}: {data[pos:pos + 16]!r}")
        outcome, failed, steps, asserts = struct.unpack_from("<BhQQ", data, pos + 1)
        pos += 20
        out[k] = AvrOutcome(bytes(rows), outcome, failed, steps, asserts)
    return out


# ---- a sample of generated cases against the interpreter ----------------------------

TINY = 2.0 ** -126  # the smallest normal binary32


class SubnormalQuotients:
    """Counts the divisions of an interpreter run whose exact quotient is a
    non-zero value below 2^-126 in magnitude: expression `/`, roll_avg's
    sum / count and roll_median's (b - a) / 2."""

    def __init__(self, monkeypatch):
        from fswkit.run import interp
        self.n = 0
        div = interp.GLOBALS["_div"]

        def counting_div(a, b):
            self.note(a, b)
            return div(a, b)
        monkeypatch.setitem(interp.GLOBALS, "_div", counting_div)
        avg_push, med_push = windows.AvgWindow.push, windows.MedianWindow.push

        def avg(w, x):
            v = avg_push(w, x)
            self.note(w.real.rnd(w.base + w.fresh), w.count)
            return v

        def med(w, x):
            v = med_push(w, x)
            if len(w.sorted) % 2 == 0:
                a, b = w.sorted[len(w.sorted) // 2 - 1], w.sorted[len(w.sorted) // 2]
                self.note(w.real.rnd(b - a), 2.0)
            return v
        monkeypatch.setattr(windows.AvgWindow, "push", avg)
        monkeypatch.setattr(windows.MedianWindow, "push", med)

    def note(self, a, b) -> None:
        if b != 0 and a == a and b == b and abs(a) != float("inf") and abs(b) != float("inf"):
            q = abs(Fraction(a) / Fraction(b))
            if 0 < q < TINY:
                self.n += 1


def run_sample(work: str, loaded: list, pool: ThreadPoolExecutor, per_elf: int,
               machine_cpp: Callable[[M.Script, str], str] | None = None) -> tuple[dict[int, AvrOutcome], list[str]]:
    """Builds and runs `loaded` ((case, script, source_line) of gen_programs)
    on simavr, `per_elf` cases an ELF (`machine_cpp`: see build_elf); each
    case's outcome and each ELF's size."""
    outcomes, sizes = {}, []
    for start in range(0, len(loaded), per_elf):
        chunk = loaded[start:start + per_elf]
        d = os.path.join(work, f"elf{start}")
        os.makedirs(d)
        items = [(c.index, s) for c, s, _ in chunk]
        elf = build_elf(d, items, pool, machine_cpp=machine_cpp)
        flash, ram = memory(elf)
        assert flash < 240 * 1024 and ram < 7 * 1024, (flash, ram)  # ATmega2560: 256 KB, 8 KB
        sizes.append(f"{flash} B flash, {ram} B RAM")
        outcomes.update(run_elf(elf, items))
    return outcomes, sizes


@dataclass
class Comparison:
    bad: list = field(default_factory=list)  # (case, difference)
    documented: list = field(default_factory=list)  # the same, for a run dividing into the subnormal range
    dividing: int = 0  # cases whose interpreter run divides into the subnormal range
    steps: int = 0  # trace rows compared


def compare(loaded: list, outcomes: dict[int, AvrOutcome], work: str, monkeypatch) -> Comparison:
    """Each case's AVR outcome against the interpreter's binary32 run: the
    per-step trace, the ending, steps and asserts. A difference in a case
    whose run divides into the subnormal range is `documented` (avr-libc's
    division there, test_simavr.py), any other `bad`."""
    r = Comparison()
    for c, s, sl in loaded:
        quotients = SubnormalQuotients(monkeypatch)
        res = H.interp_run(s, F32MODE, trace_path=os.path.join(work, "i.csv"), source_line=sl)
        monkeypatch.undo()
        r.dividing += quotients.n > 0
        with open(os.path.join(work, "i.csv")) as f:
            it = H.Outcome(0 if res.passed else 1, res.report(), f.read())
        r.steps += it.trace.count("\n") - 1
        o = outcomes[c.index]
        raw = os.path.join(work, "a.raw")
        with open(raw, "wb") as f:
            f.write(o.rows)
        native._raw_to_csv(s.machine, raw, os.path.join(work, "a.csv"))
        # The ending, as the report would show it.
        fails = failure_diagnostics(s, sl)
        ending = {0: None, 1: fails["asserts"][o.failed_assert].render() if o.outcome == 1 else None,
                  2: fails["max_steps"].render(), 3: fails["step_error"].render()}[o.outcome]
        mine = (res.passed, res.steps, res.asserts, res.failure.render() if res.failure else None)
        theirs = (o.outcome == 0, o.steps, o.asserts, ending)
        with open(os.path.join(work, "a.csv")) as f:
            d = H.first_difference(it, H.Outcome(it.code, it.report, f.read()))
        if d is None and mine != theirs:
            d = f"ending: interpreter {mine}, AVR {theirs}"
        if d is not None:
            (r.documented if quotients.n else r.bad).append((c, d))
    return r
