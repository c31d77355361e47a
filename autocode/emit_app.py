"""The application's generated C++: I/O channel tables, the task table,
and the entry point (`setup()`/`loop()` on a board, `main` on the host), so
a project made only of configs builds into complete firmware."""

from __future__ import annotations

from .app import MODES, Application, Task
from .emit_cpp import basename, banner, c_ident, emit_machine, emit_sv, real_check, real_literal, version_check
from .numeric import MODES as REALS

TYPE_CODE = {"F32": "fsw::kF32", "F64": "fsw::kF64"}


class GenError(Exception):
    """The application is valid but asks for something the generator
    cannot produce."""


def real_of(app: Application):
    return REALS[app.board.real]


def emit_app(app: Application) -> dict[str, str]:
    """Every generated file of the application: {relative path: text}."""
    real = real_of(app)
    files = dict(emit_sv(app.sv))
    for m in app.machines:
        files.update(emit_machine(m, real))
    files["app.gen.cpp"] = _app_cpp(app)
    return files


def _tables(app: Application, real, out: list[str]) -> dict[str, str]:
    """Channel tables grouped by direction; returns {group: table name}."""
    names = {}
    groups = {
        ("analog", "i"): [c for c in app.channels if c.analog and c.direction == "i"],
        ("analog", "o"): [c for c in app.channels if c.analog and c.direction == "o"],
        ("digital", "i"): [c for c in app.channels if not c.analog and c.direction == "i"],
        ("digital", "o"): [c for c in app.channels if not c.analog and c.direction == "o"],
    }
    vref = real_literal(real.literal(repr(app.board.adc_vref)), real)
    for (kind, d), chans in groups.items():
        if not chans:
            continue
        tag = f"k{kind.capitalize()}{'In' if d == 'i' else 'Out'}"
        direction = "fsw::kIoIn" if d == "i" else "fsw::kIoOut"
        if kind == "analog":
            out.append(f"const fsw::AnalogChannel {tag}Ch[] FSW_FLASH = {{")
            for c in chans:
                scale = real_literal(real.literal(repr(c.scale)), real)
                offset = real_literal(real.literal(repr(c.offset)), real)
                out.append(f"    {{{scale}, {offset}, E_{c.element.name}, {c.pin_number}, {direction}, "
                           f"{TYPE_CODE[c.element.type.name]}}},  // {basename(c.path)}:{c.line} pin {c.pin}")
            out.append("};")
            out.append(f"const fsw::AnalogTable {tag} FSW_FLASH = {{{tag}Ch, sv, {vref}, {len(chans)}, "
                       f"{app.board.adc_bits}, kSvLock}};")
        else:
            out.append(f"const fsw::DigitalChannel {tag}Ch[] FSW_FLASH = {{")
            for c in chans:
                out.append(f"    {{E_{c.element.name}, {c.pin_number}, {direction}}},  "
                           f"// {basename(c.path)}:{c.line} pin {c.pin}")
            out.append("};")
            out.append(f"const fsw::DigitalTable {tag} FSW_FLASH = {{{tag}Ch, sv, {len(chans)}, kSvLock}};")
        out.append("")
        names[(kind, d)] = tag
    return names


def _now(app: Application) -> str:
    """C++ for the value of `G` now."""
    if app.time_source == "cycle":
        per_cycle = (1000 if app.time_unit == "ms" else 1000000) // app.rate
        return f"static_cast<uint64_t>(ex.cycles) * {per_cycle}u"
    return "fsw::pal::millis64()" if app.time_unit == "ms" else "fsw::pal::micros64()"


def _app_cpp(app: Application) -> str:
    real = real_of(app)
    sources = [app.path, app.sv.path] + [m.path for m in app.machines] + sorted({c.path for c in app.channels})
    c = [banner(sources, app.sv), '#include "fswkit.h"', '#include "sv.gen.h"']
    for m in app.machines:
        c.append(f'#include "{c_ident(m.name)}.gen.h"')
    c += ["", version_check("app.gen.cpp"), real_check(basename(app.path), real),
          f"// Board `{app.board.name}`: {app.board.mcu} at {app.board.f_cpu} Hz.",
          "namespace fsw_gen {", "namespace {", ""]
    tables = _tables(app, real, c)
    n = len(app.tasks)
    c.append(f"const uint32_t kPeriodUs = {1000000 // app.rate}UL;  // {app.rate} cycles per second")
    c.append("fsw::Executor ex;")
    c.append(f"fsw::TaskStats stats[{max(n, 1)}];")
    c.append("")
    for t in app.tasks:
        c += _task_fn(app, t, tables)
    c.append(f"const fsw::Task kTasks[{max(n, 1)}] FSW_FLASH = {{")
    for t in app.tasks:
        mode = f"E_{t.mode.name}" if t.mode is not None else "fsw::kNoElement"
        over = f"E_{t.overruns.name}" if t.overruns is not None else "fsw::kNoElement"
        worst = f"E_{t.worst_us.name}" if t.worst_us is not None else "fsw::kNoElement"
        c.append(f"    {{task_{t.name}, 0, 0, {t.divider}, 0, {mode}, {over}, {worst}, "
                 f"{MODES[t.start]}}},  // {basename(app.path)}:{t.line} {t.name}")
    if not app.tasks:
        c.append("    {0, 0, 0, 1, 0, fsw::kNoElement, fsw::kNoElement, fsw::kNoElement, 0},")
    c.append("};")
    cause = f"E_{app.reset_cause.name}" if app.reset_cause is not None else "fsw::kNoElement"
    c.append(f"const fsw::ExecConfig kConfig = {{kTasks, stats, sv, kPeriodUs, {cause}, {n}, kSvLock}};")
    c.append("")
    c.append("}  // namespace")
    c.append("")
    c.append("// Starts the executor and the I/O channels; false on a bad table.")
    c.append("bool begin() {")
    c.append("    if (fsw::executor_begin(ex, kConfig) != fsw::kOk) return false;")
    for (kind, d), tag in tables.items():
        c.append(f"    if (fsw::io_{kind}_begin(&{tag}) != fsw::kOk) return false;")
    c.append("    return true;")
    c.append("}")
    c.append("")
    c.append("// Runs a cycle when one is due.")
    c.append("void poll() { (void)fsw::executor_poll(ex); }")
    c.append("// Runs one cycle now (hosts: simulations and tests).")
    c.append("void run_cycle() { fsw::executor_run_cycle(ex); }")
    c.append("")
    c.append("}  // namespace fsw_gen")
    c.append("")
    c.append("#if FSW_PLATFORM_ARDUINO")
    c.append("#include <Arduino.h>  // declares setup() and loop() with the core's linkage")
    c.append("void setup() {")
    c.append("    if (!fsw_gen::begin()) {")
    c.append("        for (;;) {}  // a table the runtime refused: the watchdog resets the board")
    c.append("    }")
    c.append("}")
    c.append("void loop() { fsw_gen::poll(); }")
    c.append("#elif !defined(FSW_NO_MAIN)")
    c.append("#include <stdio.h>")
    c.append("#include <stdlib.h>")
    c.append('#include "psl_native.h"')
    c.append("// Host build: `app CYCLES` runs that many cycles on the simulated clock, then")
    c.append("// prints the state vector as hex; with no argument it follows the real clock.")
    c.append("int main(int argc, char** argv) {")
    c.append("    if (!fsw_gen::begin()) { fprintf(stderr, \"the runtime refused a table\\n\"); return 3; }")
    c.append("    if (argc < 2) {")
    c.append("        fsw::native::use_real_time(true);")
    c.append("        for (;;) fsw_gen::poll();")
    c.append("    }")
    c.append("    const unsigned long cycles = strtoul(argv[1], 0, 10);")
    c.append("    for (unsigned long i = 0; i < cycles; ++i) {")
    c.append("        fsw_gen::run_cycle();")
    c.append("        fsw::native::sim_advance_us(fsw_gen::kPeriodUs);")
    c.append("    }")
    c.append("    for (uint16_t i = 0; i < fsw_gen::kSvSize; ++i) printf(\"%02x\", fsw_gen::sv[i]);")
    c.append("    printf(\"\\n\");")
    c.append("    return 0;")
    c.append("}")
    c.append("#endif")
    c.append("")
    return "\n".join(c)


def _task_fn(app: Application, t: Task, tables) -> list[str]:
    out = [f"// Task `{t.name}` ({t.kind}), every {t.divider} cycle(s).",
           f"fsw::Result task_{t.name}(void*) {{"]
    if t.kind == "machine":
        m = app.machines[t.machine]
        g = m.vars[m.g].name
        if app.sv.lock:
            out.append(f"    {{ fsw::SvGuard<true> lock; fsw::store<uint64_t>(sv + E_{g}, {_now(app)}); }}")
        else:
            out.append(f"    fsw::store<uint64_t>(sv + E_{g}, {_now(app)});")
        out.append(f"    return {c_ident(m.name)}::step();")
    elif t.kind in ("inputs", "outputs"):
        d = "i" if t.kind == "inputs" else "o"
        calls = [(kind, tables[(kind, d)]) for kind in ("analog", "digital") if (kind, d) in tables]
        if not calls:
            out.append("    return fsw::kOk;  // no channels in this direction")
        for k, (kind, tag) in enumerate(calls):
            call = f"fsw::io_{kind}_task(const_cast<void*>(static_cast<const void*>(&{tag})))"
            if k == len(calls) - 1:
                out.append(f"    return {call};")
            else:
                out.append(f"    const fsw::Result r{k} = {call};")
                out.append(f"    if (r{k} != fsw::kOk) return r{k};")
    else:
        raise GenError(f"{basename(app.path)}:{t.line}: task `{t.name}`: `{t.kind}` tasks cannot be "
                       "generated yet: the telemetry link is not part of this version of the kit")
    out.append("}")
    out.append("")
    return out
