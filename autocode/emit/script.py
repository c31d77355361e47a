"""The state-script runners (host and test only, never firmware):
`script_main.cpp` for `fsw test --native`, which prints the report `fsw
test` prints byte for byte, and `script_avr.cpp`, the same run for a board
without stdio (the differential tests run it on a simulated AVR)."""

from __future__ import annotations

import struct

from .. import model as M
from ..check import failure_diagnostics
from ..numeric import Real, to_type
from .common import banner, basename, c_ident, c_string, parens, real_check, value_bytes, version_check, window_type
from .expr import ExprEmitter
from .machine import emit_machine
from .sv import emit_sv


def script_writes_locals(script: M.Script) -> bool:
    m = script.machine
    return any(m.vars[a.var].kind == M.LOCAL
               for sec in script.sections for g in sec.inputs for a in g.inputs)


def emit_script(script: M.Script, real: Real, source_line, ns: str = "fsw_gen",
                entry: str = "main") -> dict[str, str]:
    """`script_main.cpp`: runs the script against the generated machine and
    prints the report `fsw test` prints, byte for byte. With a file name as
    its argument it also writes a binary trace: after every step, every
    variable in report order as 8 bytes (int64, uint64 or binary64 bits).
    `ns` is the generated code's outer namespace (see emit_sv); with an
    `entry` other than `main` the runner is `int <ns>::<entry>(argc, argv)`,
    so that many runners link into one program."""
    m = script.machine
    name = c_ident(m.name)
    outer = ns
    ns = f"{outer}::{name}::"
    ex = ExprEmitter(m, real, script_writes_locals(script), prefix=ns, windows="sw", ns=outer)
    order = sorted(m.vars, key=lambda v: v.display.encode())
    folded = {i: value_bytes(m.vars[i].type, to_type(m.vars[i].type, x)) for i, x in ex.consts.items()}
    c = [banner([script.path, m.path, m.sv.path], m.sv), "#include <inttypes.h>", "#include <stdio.h>", "",
         '#include "fswkit.h"', '#include "sv.gen.h"', f'#include "{name}.gen.h"', "",
         version_check("script_main.cpp"), real_check(basename(script.path), real)]
    if entry != "main":
        c.append(f"namespace {outer} {{")
    c += ["namespace {", ""]
    for w in script.windows:
        c.append(f"{window_type(w)} sw{w.index};  // {basename(script.path)}:{w.line}")
    c.append("")
    fails = failure_diagnostics(script, source_line)
    c.append(f"const char kMaxSteps[] = {c_string(fails['max_steps'].render())};")
    c.append(f"const char kStepError[] = {c_string(fails['step_error'].render())};")
    for k, d in enumerate(fails["asserts"]):
        c.append(f"const char kAssert{k}[] = {c_string(d.render())};")
    texts = [f"kAssert{k}" for k in range(len(fails["asserts"]))]
    c.append("const char* const kAssertText[] = {" + (", ".join(texts) if texts else "0") + "};")
    c.append("")
    c.append("void print_value(const char* name, const uint8_t* p, int kind) {")
    c.append("    // kind: 0 signed, 1 unsigned, 2 F32, 3 F64, 4 bool; p holds the element's bytes")
    c.append("    switch (kind) {")
    c.append("    case 2: { float f; memcpy(&f, p, 4); printf(\"  %s = %.6f\\n\", name, (double)f); break; }")
    c.append("    case 3: { double d; memcpy(&d, p, 8); printf(\"  %s = %.6f\\n\", name, d); break; }")
    c.append("    case 4: printf(\"  %s = %s\\n\", name, *p ? \"true\" : \"false\"); break;")
    c.append("    default: break;")
    c.append("    }")
    c.append("}")
    c.append("")
    c.append("int64_t as_signed(const uint8_t* p, int size) {")
    c.append("    switch (size) { case 1: return (int8_t)p[0]; case 2: { int16_t v; memcpy(&v, p, 2); return v; }")
    c.append("    case 4: { int32_t v; memcpy(&v, p, 4); return v; } default: { int64_t v; memcpy(&v, p, 8); return v; } }")
    c.append("}")
    c.append("uint64_t as_unsigned(const uint8_t* p, int size) {")
    c.append("    uint64_t v = 0; memcpy(&v, p, (size_t)size); return v;  // little-endian host")
    c.append("}")
    c.append("")
    # variable bytes for printing and tracing
    c.append("void varvalue_bytes(uint8_t out[8], int which) {")
    c.append("    memset(out, 0, 8);")
    c.append("    switch (which) {")
    for k, v in enumerate(order):
        if v.kind == M.TIME_IN_STATE:
            c.append(f"    case {k}: {{ const uint64_t t = fsw::machine_T({ns}machine); memcpy(out, &t, 8); break; }}")
        elif v.index in folded:  # a local folded into the code: its constant bytes
            data = ", ".join(str(b) for b in folded[v.index])
            c.append(f"    case {k}: {{ static const uint8_t b[] = {{{data}}}; memcpy(out, b, {v.type.size}); break; }}")
        else:
            c.append(f"    case {k}: memcpy(out, {ex.ptr(v)}, {v.type.size}); break;")
    c.append("    default: break;")
    c.append("    }")
    c.append("}")
    c.append("")
    kinds = []
    for v in order:
        t = v.type
        kinds.append(4 if t.is_bool else (2 if t.size == 4 else 3) if t.is_float else (0 if t.signed else 1))
    c.append(f"const int kKind[] = {{{', '.join(str(k) for k in kinds)}}};")
    c.append(f"const int kSize[] = {{{', '.join(str(v.type.size) for v in order)}}};")
    c.append("const char* const kName[] = {" + ", ".join(c_string(v.display) for v in order) + "};")
    c.append(f"const int kVars = {len(order)};")
    c.append("")
    c.append("void write_trace(FILE* f) {")
    c.append("    uint8_t row[8 * (kVars > 0 ? kVars : 1)];")
    c.append("    for (int k = 0; k < kVars; ++k) {")
    c.append("        uint8_t b[8];")
    c.append("        varvalue_bytes(b, k);")
    c.append("        if (kKind[k] == 0) { int64_t v = as_signed(b, kSize[k]); memcpy(row + 8 * k, &v, 8); }")
    c.append("        else if (kKind[k] == 2) { float x; memcpy(&x, b, 4); double d = x; memcpy(row + 8 * k, &d, 8); }")
    c.append("        else if (kKind[k] == 4) { uint64_t v = b[0] != 0; memcpy(row + 8 * k, &v, 8); }")
    c.append("        else memcpy(row + 8 * k, b, 8);")
    c.append("    }")
    c.append("    fwrite(row, 8, (size_t)kVars, f);")
    c.append("}")
    c.append("")
    c.append("}  // namespace")
    c.append("")
    c.append(f"int {entry}(int argc, char** argv) {{")
    c.append("    FILE* trace = argc > 1 ? fopen(argv[1], \"wb\") : 0;")
    c.append("    if (argc > 1 && trace == 0) { fprintf(stderr, \"cannot write trace %s\\n\", argv[1]); return 3; }")
    c += _script_loop(script, ex, outer, ns, "        if (trace) write_trace(trace);")
    c.append("    if (trace) fclose(trace);")
    c.append("    printf(\"state script ran for %\" PRIu64 \" step%s\\n\", steps, steps == 1 ? \"\" : \"s\");")
    c.append("    printf(\"%\" PRIu64 \" assert%s passed\\n\", asserts, asserts == 1 ? \"\" : \"s\");")
    c.append("    if (outcome == 1) printf(\"%s\\n\", kAssertText[failed_assert]);")
    c.append("    if (outcome == 2) printf(\"%s\\n\", kMaxSteps);")
    c.append("    if (outcome == 3) printf(\"%s\\n\", kStepError);")
    c.append("    printf(\"final state vector:\\n\");")
    c.append("    for (int k = 0; k < kVars; ++k) {")
    c.append("        uint8_t b[8];")
    c.append("        varvalue_bytes(b, k);")
    c.append("        if (kKind[k] == 0) printf(\"  %s = %\" PRId64 \"\\n\", kName[k], as_signed(b, kSize[k]));")
    c.append("        else if (kKind[k] == 1) printf(\"  %s = %\" PRIu64 \"\\n\", kName[k], as_unsigned(b, kSize[k]));")
    c.append("        else print_value(kName[k], b, kKind[k]);")
    c.append("    }")
    c.append("    return outcome == 0 ? 0 : 1;")
    c.append("}")
    if entry != "main":
        c.append(f"}}  // namespace {outer}")
    c.append("")
    return {"script_main.cpp": "\n".join(c)}


def _script_loop(script: M.Script, ex: ExprEmitter, outer: str, ns: str, trace: str) -> list[str]:
    """The run loop of spec §5 shared by the script runners: declares `g`,
    `steps`, `asserts`, `outcome` and `failed_assert`, and leaves them set;
    `trace` is the statement that records a step."""
    m = script.machine
    c: list[str] = []
    checks: list = []
    c.append(f"    {ns}reset({m.states[script.init_state].id});")
    c.append("    uint64_t g = 0, steps = 0, asserts = 0;")
    c.append("    int outcome = -1;  // -1 running, 0 passed, 1 assert failed, 2 max_steps, 3 step error")
    c.append("    int failed_assert = -1;")
    ncheck = sum(len(grp.checks) for sec in script.sections for grp in sec.checks)
    c.append(f"    int rem[{max(ncheck, 1)}];")
    c.append("    while (outcome < 0) {")
    c.append(f"        if (steps >= {script.max_steps}ULL) {{ outcome = 2; break; }}")
    c.append(f"        fsw::store<uint64_t>({outer}::sv + {outer}::E_{m.vars[m.g].name}, g);")
    c.append(f"        fsw::store<uint32_t>({outer}::sv + {outer}::E_{m.vars[m.s].name}, {ns}machine.state);")
    # T as the step will take it, for the inputs, the windows and the guards before it (0 on a
    # state's first step): the machine's times set for it, and set back before the step
    c.append(f"        const uint64_t last_g = {ns}machine.last_g, entry_g = {ns}machine.entry_g;")
    c.append(f"        {ns}machine.last_g = g;")
    c.append(f"        if ({ns}machine.pending != 0) {ns}machine.entry_g = g;")
    for w in script.windows:
        c.append(f"        sw{w.index}.push({ex.value(w.arg)});")
    if any(sec.state is not None for sec in script.sections):
        c.append(f"        const uint32_t state = {ns}machine.state;")
    c.append("        int nrem = 0;")
    assert_ids: dict[int, int] = {}
    for sec in script.sections:
        ind = "        "
        if sec.state is not None:
            c.append(f"        if (state == {m.states[sec.state].id}) {{")
            ind = "            "
        for grp in sec.inputs:
            for a in grp.inputs:  # the guard again before each input: an earlier one may change it (spec §5)
                c.append(f"{ind}if {parens(ex.cond(grp.guard))} {{")
                c.append(f"{ind}    {ex.assign(a.var, a.expr)}  // {basename(script.path)}:{a.line}")
                c.append(f"{ind}}}")
        for grp in sec.checks:
            ids = []
            for chk in grp.checks:
                ids.append(len(checks))
                checks.append(chk)
            c.append(f"{ind}if {parens(ex.cond(grp.guard))} {{")
            c.append(f"{ind}    " + " ".join(f"rem[nrem++] = {i};" for i in ids))
            c.append(f"{ind}}}")
        if sec.state is not None:
            c.append("        }")
    c.append(f"        {ns}machine.last_g = last_g;")
    c.append(f"        {ns}machine.entry_g = entry_g;")
    # a refused step changes nothing: T stays what it was taken as before it (the interpreter's)
    c.append(f"        if ({ns}step() != fsw::kOk) {{")
    c.append(f"            {ns}machine.last_g = g;")
    c.append(f"            if ({ns}machine.pending != 0) {ns}machine.entry_g = g;")
    c.append("            ++steps;")
    c.append("            outcome = 3;")
    c.append("            break;")
    c.append("        }")
    c.append("        ++steps;")
    c.append(trace)
    c.append("        for (int k = 0; k < nrem && outcome < 0; ++k) {")
    c.append("            switch (rem[k]) {")
    na = 0
    for i, chk in enumerate(checks):
        if isinstance(chk, M.Stop):
            c.append(f"            case {i}: outcome = 0; break;")
        else:
            assert_ids[i] = na
            c.append(f"            case {i}: if {parens(ex.cond(chk.expr))} ++asserts; "
                     f"else {{ outcome = 1; failed_assert = {na}; }} break;")
            na += 1
    c.append("            default: break;")
    c.append("            }")
    c.append("        }")
    c.append("        if (outcome >= 0) break;")
    c.append(f"        g += {script.delta_t}ULL;")
    c.append("    }")
    return c


def emit_script_avr(script: M.Script, real: Real, ns: str = "fsw_gen", entry: str = "run_script") -> dict[str, str]:
    """`script_avr.cpp`: the same run as emit_script's runner for a board
    without stdio (the differential tests run it on a simulated AVR). It
    writes only the trace and the outcome, through a byte sink the board
    code defines, `void fsw_trace_write(const uint8_t* data, uint16_t len)`:
    after every step `R` and the row of emit_script's binary trace (every
    variable in report order as 8 bytes: int64, uint64 or binary64 bits,
    F32 widened in software), at the end `E`, the outcome (1 byte: 0
    passed, 1 assert failed, 2 max_steps, 3 step error), the failed assert's
    number (int16, -1 for none), steps and asserts passed (uint64 each).
    All little-endian. The runner is `int <ns>::<entry>()`, returning 0 when
    the script passed."""
    m = script.machine
    name = c_ident(m.name)
    outer = ns
    ns = f"{outer}::{name}::"
    ex = ExprEmitter(m, real, script_writes_locals(script), prefix=ns, windows="sw", ns=outer)
    order = sorted(m.vars, key=lambda v: v.display.encode())
    src = basename(script.path)
    c = [banner([script.path, m.path, m.sv.path], m.sv),
         '#include "fswkit.h"', '#include "sv.gen.h"', f'#include "{name}.gen.h"', "",
         version_check("script_avr.cpp"), real_check(src, real),
         "// The board's byte sink (a UART): the trace and the outcome leave through it.",
         "void fsw_trace_write(const uint8_t* data, uint16_t len);", "",
         f"namespace {outer} {{", "namespace {", ""]
    for w in script.windows:
        c.append(f"{window_type(w)} sw{w.index};  // {src}:{w.line}")
    c += ["", "void put64(uint64_t v) { fsw_trace_write(reinterpret_cast<const uint8_t*>(&v), 8); }", "",
          "// One row: every variable in report order, 8 bytes each.",
          "void trace_row() {", "    const uint8_t mark = 'R';", "    fsw_trace_write(&mark, 1);"]
    for v in order:
        t = v.type
        if v.kind == M.TIME_IN_STATE:
            c.append(f"    put64(fsw::machine_T({ns}machine));  // T")
            continue
        if v.index in ex.consts:  # folded into the code: its value, widened now
            x = to_type(t, ex.consts[v.index])
            if t.is_float:
                row = struct.unpack("<Q", struct.pack("<d", float(x)))[0]
            else:
                row = int(x) & ((1 << 64) - 1)
            c.append(f"    put64(0x{row:016x}ULL);  // {v.display} (folded)")
            continue
        p = ex.ptr(v)
        if t.is_bool:
            c.append(f"    put64(fsw::load_bool({p}) ? 1u : 0u);  // {v.display}")
        elif t.is_float and t.size == 4:
            c.append(f"    put64(fsw::f64_bits_from_f32(fsw::load<float>({p})));  // {v.display}")
        elif t.is_float or t.size == 8:
            c.append(f"    fsw_trace_write({p}, 8);  // {v.display}")
        elif t.signed:
            c.append(f"    put64(static_cast<uint64_t>(static_cast<int64_t>(fsw::load<int{t.size * 8}_t>({p}))));"
                     f"  // {v.display}")
        else:
            c.append(f"    put64(fsw::load<uint{t.size * 8}_t>({p}));  // {v.display}")
    c += ["}", "", "}  // namespace", "", f"int {entry}() {{"]
    c += _script_loop(script, ex, outer, ns, "        trace_row();")
    c += ["    uint8_t end[20];", "    end[0] = 'E';", "    end[1] = static_cast<uint8_t>(outcome);",
          "    const int16_t failed = static_cast<int16_t>(failed_assert);",
          "    memcpy(end + 2, &failed, 2);", "    memcpy(end + 4, &steps, 8);", "    memcpy(end + 12, &asserts, 8);",
          "    fsw_trace_write(end, sizeof end);", "    return outcome == 0 ? 0 : 1;", "}",
          f"}}  // namespace {outer}", ""]
    return {"script_avr.cpp": "\n".join(c)}


def script_files(script: M.Script, real: Real, source_line, ns: str = "fsw_gen",
                 entry: str = "main") -> dict[str, str]:
    """Everything `fsw test --native` compiles: state vector, machine,
    runner (`ns` and `entry`: see emit_script)."""
    files = {}
    files.update(emit_sv(script.machine.sv, ns))
    files.update(emit_machine(script.machine, real, scriptable=script_writes_locals(script), ns=ns))
    files.update(emit_script(script, real, source_line, ns, entry))
    return files
