"""Generated machines run by the runtime's bytecode VM (firmware/src/fsw_vm.cpp)
under the state-script runner of `fsw test --native`.

The runner (emit/script.py) steps `<ns>::<machine>::step()` and reads the
machine's `loc`/`prm` arrays through the generated header. Here the
header stays as emitted, and the machine's .gen.cpp is replaced by a shim
that holds the compiled image and whose step() calls fsw::vm_step: the
script's own code, report and trace are those of test_generated.py, only
the machine's step differs. Before each step the shim copies the locals
the runner sees (and may write) into the VM's locals, and back after it."""

from __future__ import annotations

import os

import harness as H
from fswkit.autocode import model as M
from fswkit.autocode.cnames import enumerator
from fswkit.autocode.emit.bytecode import compile_machine, local_offsets, window_ram
from fswkit.autocode.emit.common import c_ident
from fswkit.autocode.emit.machine import stored_locals
from fswkit.autocode.emit.script import script_files, script_writes_locals
from fswkit.autocode.numeric import Real
from fswkit.autocode.vmverify import TYPE_CODES
from fswkit.run import native


def _bytes(data: bytes) -> str:
    rows = [", ".join(str(b) for b in data[i:i + 24]) for i in range(0, len(data), 24)]
    return "{\n    " + ",\n    ".join(rows) + "\n}"


def vm_shim(m: M.Machine, real: Real, scriptable: bool, ns: str, avr: bool = False) -> str:
    """The `<machine>.gen.cpp` that steps `m` through the VM. `avr`: for a
    board without stdio (avr_sim.py's runner), where an image vm_verify
    refuses sends `V` and the reason (1 byte) through the runner's byte sink
    and stops the board (sleep, interrupts off) instead of printing."""
    name = c_ident(m.name)
    image = compile_machine(m, real, scriptable)
    stored = stored_locals(m, real, scriptable)
    params = [] if scriptable else [v for v in m.vars if v.param is not None]
    offs = local_offsets(m)
    copies = [(offs[v.index], f"loc + {enumerator('L_', v.name)}", v.type.size) for v in stored]
    copies += [(offs[v.index], f"prm + {enumerator('P_', v.name)}", v.type.size) for v in params]
    elems = ", ".join(f"{{{e.offset}, {TYPE_CODES[e.type.name]}}}" for e in m.sv.elements)
    ram = max(window_ram(m, real), 1)
    if avr:
        c = ['#include <avr/interrupt.h>', '#include <avr/sleep.h>', '#include <string.h>']
        refused = ["        const uint8_t v[2] = {'V', static_cast<uint8_t>(why)};",
                   "        fsw_trace_write(v, 2);",
                   "        cli();", "        sleep_enable();", "        sleep_cpu();"]
    else:
        c = ['#include <stdio.h>', '#include <stdlib.h>']
        refused = [f"        printf(\"vm_verify refused the image of {name}: reason %d\\n\", static_cast<int>(why));",
                   "        exit(9);"]
    c += [f'#include "{name}.gen.h"', '#include "sv.gen.h"', '#include "fsw_vm.h"', ""]
    if avr:
        c += ["void fsw_trace_write(const uint8_t* data, uint16_t len);", ""]
    c += [f"namespace {ns} {{", f"namespace {name} {{", "", "fsw::Machine machine;"]
    if stored:
        c.append("uint8_t loc[kLocSize];")
    if params:
        c.append("uint8_t prm[kPrmSize];")
    c += ["", "namespace {", "", f"const uint8_t kImage[] = {_bytes(image)};",
          f"const fsw::VmElem kElems[] FSW_FLASH = {{{elems}}};",
          f"const fsw::VmLayout kLayout = {{kElems, {len(m.sv.elements)}, kSchemaHash}};",
          f"alignas(fsw::kVmRamAlign) uint8_t ram[{ram}];", "",
          "void to_vm() {", "    uint8_t* l = fsw::vm_locals(kImage, ram);"]
    c += [f"    memcpy(l + {o}, {p}, {n});" for o, p, n in copies]
    if not copies:
        c.append("    (void)l;")
    c += ["}", "", "void from_vm() {", "    const uint8_t* l = fsw::vm_locals(kImage, ram);"]
    if not copies:
        c.append("    (void)l;")
    c += [f"    memcpy({p}, l + {o}, {n});" for o, p, n in copies]
    c += ["}", "", "}  // namespace", "",
          "fsw::Result step() {",
          "    to_vm();",
          "    const fsw::Result r = fsw::vm_step(kImage, kLayout, sv, ram, machine);",
          "    from_vm();",
          "    return r;",
          "}", "",
          "void reset(uint32_t initial) {",
          "    const fsw::VmReason why = fsw::vm_verify(kImage, sizeof kImage, kLayout, sizeof ram);",
          "    if (why != fsw::kVmOk) {", *refused, "    }",
          "    fsw::vm_reset(kImage, ram, machine, initial);",
          "    from_vm();",
          "}", "",
          f"}}  // namespace {name}", f"}}  // namespace {ns}", ""]
    return "\n".join(c)


class VmBatch(H.Batch):
    """H.Batch whose machines step through the VM."""

    kind = "vm"

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.objects.append(self.pool.submit(self._runtime_object, os.path.join(native.RUNTIME, "fsw_vm.cpp")))

    def add(self, k: int, script: M.Script, source_line) -> None:
        ns = f"fsw_c{k}"
        files = script_files(script, self.real, source_line, ns=ns, entry="run")
        name = c_ident(script.machine.name)
        files[f"{name}.gen.cpp"] = vm_shim(script.machine, self.real, script_writes_locals(script), ns)
        self._add_files(k, files, "script_main.cpp")
        self.items.append((k, script))


class VmRawBatch(H.RawBatch):
    """H.RawBatch (machines driven by raw element values) whose machines
    step through the VM."""

    kind = "vmraw"

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.objects.append(self.pool.submit(self._runtime_object, os.path.join(native.RUNTIME, "fsw_vm.cpp")))
        self._shim: tuple[str, str] | None = None

    def add_machine(self, k: int, case, m: M.Machine) -> None:
        self._shim = (f"{c_ident(m.name)}.gen.cpp", vm_shim(m, self.real, False, f"fsw_r{k}"))
        try:
            super().add_machine(k, case, m)
        finally:
            self._shim = None

    def _add_files(self, k: int, files: dict[str, str], last: str) -> None:
        if self._shim is not None:
            files[self._shim[0]] = self._shim[1]
        super()._add_files(k, files, last)
