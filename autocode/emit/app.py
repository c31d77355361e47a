"""The application's generated C++: I/O channel tables, the task table,
and the entry point (`setup()`/`loop()` on a board, `main` on the host), so
a project made only of configs builds into complete firmware."""

from __future__ import annotations

import math

from ..app import TASK_MODES, Application, Task
from ..cnames import comment, enumerator
from ..iotables import analog_gain
from ..limits import link_load
from ..numeric import REALS
from ..params import app_parameters
from ..schema import app_schema_hash, link_plan, link_text, schema_hash
from ..unparse import model_expr
from ..version import __version__
from ..types import TYPES
from .common import basename, banner, c_ident, c_string, real_check, real_literal, version_check
from .expr import ExprEmitter, float_key_test
from .machine import cached_sums, declared_windows, emit_machine, stored_locals
from .resume import resume_spans, resume_watches
from .sv import emit_sv

# each element type's fsw::ElemType enumerator (firmware/src/fsw_types.h;
# tests/link/test_protocol_matches_firmware.py holds the two lists equal)
ELEM_CODE = {name: "fsw::kBool" if name == "bool" else f"fsw::k{name}" for name in TYPES}
TYPE_CODE = {name: ELEM_CODE[name] for name in ("F32", "F64")}  # the types an analog channel holds


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
        files.update(emit_machine(m, real, leave=app.reload is not None and app.machines[app.reload.machine] is m,
                                  kept=resumes(app)))
    files["app.gen.cpp"] = _app_cpp(app)
    return files


def _direct_digital(app: Application, chans) -> bool:
    """Digital channels become one call each, on pins the generator resolved
    to their port and bit (`FSW_PIN`), when the board file maps every pin."""
    return all(c.pin_number in app.board.ports for c in chans)


def _pyro_direct(app: Application) -> bool:
    """Pyro pins and their arming pins by port and bit, like other digital
    channels, when the board file maps them all; else through the PAL."""
    return _direct_digital(app, [c for p in app.pyro for c in (p.output, *p.arm)])


def _pin(app: Application, c) -> str:
    port, bit = app.board.ports[c.pin_number]
    return f"FSW_PIN({c.pin_number}, {port}, {bit})"


class _Scan:
    """Analog inputs served from a background scan of `tag`Pins into
    `tag`Raw (fsw_io.h, "analog inputs, one call each"): one call each, or
    with `rows` one loop over the table `tag`Rows (_input_rows)."""

    def __init__(self, tag: str, chans, rows: bool = False):
        self.tag, self.chans, self.rows = tag, chans, rows


def _input_rows(app: Application, chans) -> bool:
    """Whether the analog inputs are converted by one loop over a flash
    table (fsw::io_analog_inputs) rather than a call each with its
    constants inline: two inputs or more, every element F32 and no `lock`
    (the loop writes F32 elements unguarded). The same values bit for bit;
    the loop's one copy of the conversion takes less flash from the second
    input on (about 110 B an input on AVR)."""
    return len(chans) >= 2 and not app.sv.lock and all(c.element.type.name == "F32" for c in chans)


def _inputs_kept(app: Application) -> bool:
    """Whether the analog inputs' elements keep their values between runs
    (fsw::analog_count_new: a count that did not change neither converted
    nor written, 2 bytes of RAM an input) rather than a memo of the value
    written at every run (fsw::AnalogMemo, 6 bytes): when nothing else
    writes them. fsw check lets neither a machine nor the uplink write an
    input's element; a machine replaced at run time ([reload]) is a
    bytecode image the board's verifier lets store to any element."""
    return app.reload is None


def _input_constants(app: Application, real, c) -> tuple[str, str]:
    """An analog input's gain and offset as R literals: iotables.analog_gain
    folds the converter into the .aio's scale (no division on the MCU)."""
    gain = real_literal(analog_gain(c.scale, app.board.adc_vref, app.board.adc_bits, real), real)
    return gain, real_literal(real.literal(repr(c.offset)), real)


def _analog_inputs(app: Application, real, scan: _Scan) -> list[str]:
    """The inputs task's lines for its analog inputs: each element takes its
    count * gain + offset, then the next scan starts."""
    out = []
    kept = _inputs_kept(app)
    if scan.rows and kept:
        out.append(f"    fsw::io_analog_inputs_kept({scan.tag}Rows, {len(scan.chans)}, {scan.tag}Key, {scan.tag}Raw, sv);  "
                   "// each element: count * gain + offset (the rows above), when its count is new")
    elif scan.rows:
        out.append(f"    fsw::io_analog_inputs({scan.tag}Rows, {len(scan.chans)}, {scan.tag}Memo, {scan.tag}Raw, sv);  "
                   "// each element: count * gain + offset (the rows above)")
    for k, c in enumerate(scan.chans if not scan.rows else ()):
        gain, offset = _input_constants(app, real, c)
        where = f"// {basename(c.path)}:{c.line} pin {c.pin}: {c.scale!r} per volt"
        if kept:
            write = (f"fsw::write_{c.element.type.name}(sv + E_{c.element.name}, "
                     f"fsw::analog_value(n, {gain}, {offset}));")
            if app.sv.lock:
                write = "{ fsw::SvGuard<true> lock; " + write + " }"
            out.append(f"    {{ const uint16_t n = fsw::io_analog_count({scan.tag}Raw, {k}); "
                       f"if (fsw::analog_count_new({scan.tag}Key[{k}], n)) {write} }}  {where}")
            continue
        write = (f"fsw::write_{c.element.type.name}(sv + E_{c.element.name}, "
                 f"fsw::analog_value_memo({scan.tag}Memo[{k}], fsw::io_analog_count({scan.tag}Raw, {k}), "
                 f"{gain}, {offset}));")
        if app.sv.lock:
            write = "{ fsw::SvGuard<true> lock; " + write + " }"
        out.append(f"    {write}  {where}")
    out.append(f"    fsw::io_analog_scan({scan.tag}Pins, {len(scan.chans)}, {scan.tag}Raw);  "
               "// the next run's counts, converted in the background")
    return out


def _tables(app: Application, real, out: list[str]) -> dict:
    """Channel tables grouped by direction; returns {group: table name}, or
    for digital channels served one call each {group: [channels]}."""
    names = {}
    pyro = {p.element.name for p in app.pyro}
    groups = {
        ("analog", "i"): [c for c in app.channels if c.analog and c.direction == "i"],
        ("analog", "o"): [c for c in app.channels if c.analog and c.direction == "o"],
        ("digital", "i"): [c for c in app.channels if not c.analog and c.direction == "i"],
        ("digital", "o"): [c for c in app.channels if not c.analog and c.direction == "o"
                           and c.element.name not in pyro],  # pyro pins: driven through the gate
    }
    vref = real_literal(real.literal(repr(app.board.adc_vref)), real)
    for (kind, d), chans in groups.items():
        if not chans:
            continue
        tag = f"k{kind.capitalize()}{'In' if d == 'i' else 'Out'}"
        direction = "fsw::kIoIn" if d == "i" else "fsw::kIoOut"
        if kind == "analog" and d == "i":
            # one call per channel on counts an ADC scan of this pin list
            # converted in the background, read one run later (fsw_io.h)
            out.append(f"const uint8_t {tag}Pins[{len(chans)}] FSW_FLASH = {{"
                       + ", ".join(str(c.pin_number) for c in chans) + "};  // "
                       + ", ".join(f"{basename(c.path)}:{c.line} {c.pin}" for c in chans))
            out.append(f"volatile uint16_t {tag}Raw[{len(chans)}];  // counts the ADC's interrupt stores")
            if _inputs_kept(app):
                out.append(f"uint16_t {tag}Key[{len(chans)}];  // each input's last count: converted and written "
                           "again when it changed (the element keeps the value)")
            else:
                out.append(f"fsw::AnalogMemo {tag}Memo[{len(chans)}];  // each input's last count and value: "
                           "converted again when the count changed")
            rows = _input_rows(app, chans)
            if rows:
                out.append(f"const fsw::AnalogInput {tag}Rows[{len(chans)}] FSW_FLASH = {{")
                for c in chans:
                    gain, offset = _input_constants(app, real, c)
                    out.append(f"    {{{gain}, {offset}, E_{c.element.name}}},  "
                               f"// {basename(c.path)}:{c.line} pin {c.pin}: {c.scale!r} per volt")
                out.append("};")
            out.append("")
            names[(kind, d)] = _Scan(tag, chans, rows)
            continue
        if kind == "analog":
            out.append(f"const fsw::AnalogChannel {tag}Ch[] FSW_FLASH = {{")
            for c in chans:
                offset = real_literal(real.literal(repr(c.offset)), real)
                out.append(f"    {{{real_literal(1.0, real)}, {offset}, E_{c.element.name}, {c.pin_number}, "
                           f"{direction}, {TYPE_CODE[c.element.type.name]}}},  "
                           f"// {basename(c.path)}:{c.line} pin {c.pin}")
            out.append("};")
            out.append(f"const fsw::AnalogTable {tag} FSW_FLASH = {{{tag}Ch, sv, {vref}, {len(chans)}, "
                       f"{app.board.adc_bits}, kSvLock, 0}};")
            if all(c.element.type.name == "F32" for c in chans):
                # no binary64 element: the task that links no F64 conversion
                names[("task", tag)] = "io_analog_task_f32"
        elif _direct_digital(app, chans):
            names[(kind, d)] = chans
            continue
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
    """C++ for the value of `G` now: after a resume, from the time base."""
    if app.time_source == "cycle":
        per_cycle = (1000 if app.time_unit == "ms" else 1000000) // app.rate
        now = f"fsw::executor_cycles(ex) * {per_cycle}u"
    else:
        now = "fsw::pal::millis64()" if app.time_unit == "ms" else "fsw::pal::micros64()"
    return f"plus_time_base({now})" if resumes(app) else now


def resumes(app: Application) -> bool:
    """Whether the firmware keeps its flight's state across a brown-out or
    a watchdog reset (docs/safety.md): an application with pyro channels."""
    return bool(app.pyro)


def _resume(app: Application) -> list[str]:
    """The spans a resume keeps (resume_spans) in the two banks in RAM the
    C runtime leaves alone, and their configuration."""
    spans = resume_spans(app)
    c = ["// ---- resuming the flight after a reset (docs/safety.md) ----",
         f"const fsw::ResumeSpan kResumeSpans[{len(spans)}] FSW_FLASH = {{"]
    for p, n, what in spans:
        c.append(f"    {{{p}, {n}}},  // {what}")
    c.append("};")
    if app.log is not None:
        c.append("static_assert(offsetof(fsw::Recorder, mode) == offsetof(fsw::Recorder, flight) + 1, "
                 "\"the recorder's flight and mode are kept as one span\");")
    # a strided span keeps its count of bytes (fsw::resume_strided(COUNT, stride))
    c.append("const uint16_t kResumeSize = " + " + ".join(
        f"static_cast<uint16_t>({n.split('(')[1].split(',')[0] if n.startswith('fsw::resume_strided(') else n})"
        for _, n, _ in spans) + ";")
    if any(n.startswith("fsw::resume_strided(") for _, n, _ in spans):
        c.append("static_assert(sizeof(fsw::TaskStats) < 128, \"a strided span's stride is at most 127 bytes\");")
    c.append("uint8_t resume_banks[2 * (kResumeSize + 3)] FSW_NOINIT;  // two banks: the bytes, a sequence number, a check")
    watches = resume_watches(app)
    if watches:
        c.append(f"uint8_t resume_watch_state[{len(watches)}][3];  // saves since each watched span changed, its sums")
        c.append(f"const fsw::ResumeWatch kResumeWatch[{len(watches)}] FSW_FLASH = {{")
        for k, (i, flag, what) in enumerate(watches):
            c.append(f"    {{{i}, {flag}, resume_watch_state[{k}]}},  // {what}")
        c.append("};")
    watch = f"kResumeWatch, {len(watches)}" if watches else "0, 0"
    c.append(f"const fsw::ResumeConfig kResumeConfig FSW_FLASH = {{kResumeSpans, resume_banks, "
             f"0x{resume_hash(app):08x}UL, kResumeSize, {len(spans)}, {watch}}};  // the check's seed: resume_hash")
    c.append("fsw::Resume resume;")
    c.append("")
    return c


def resume_hash(app: Application) -> int:
    """The seed of the banks' check: what gives the kept bytes their
    meaning. The link schema (the state vector's layout, the machines'
    state numbers, the pyro channels), and beyond it each machine's stored
    locals (types and names, in their order) and rolling windows, the
    evaluation type, the runtime's version, the recorder's flight and an
    uploaded machine's RAM: a bank of a build that lays them out otherwise
    does not check."""
    real = real_of(app)
    lines = [f"resume {__version__} {app.board.real}"]
    for m in app.machines:
        lines.append(f"locals {m.name} " + " ".join(f"{v.type.name}:{v.name}" for v in stored_locals(m, real)))
        sums = cached_sums(m, real)
        if sums:  # the sums kept after the locals (none: the lines, and the check, as before them)
            lines.append(f"sums {m.name} " + " ".join(model_expr(node, m).replace(" ", "") for _, node, _ in sums))
        lines.append(f"windows {m.name} " + " ".join(t for _, t in declared_windows(m, ExprEmitter(m, real, False))))
    if app.log is not None:
        lines.append("recorder")
    if app.reload is not None:
        lines.append(f"reload {app.machines[app.reload.machine].name} {app.reload.ram}")
    return schema_hash(app.sv, link_text(app) + "\n".join(lines) + "\n")


def _resume_begin(app: Application) -> list[str]:
    """begin()'s lines after a resume: no pulse started again, the clock
    going on from the kept G plus a cycle, the tasks' modes as kept, the
    reset cause's resumed bit."""
    per_cycle = -(-(1000 if app.time_unit == "ms" else 1000000) // app.rate)  # at least a cycle has passed
    gs = sorted({m.vars[m.g].name for m in app.machines})
    c = ["    if (resumed) {",
         f"        fsw::pyro_resumed(Pyro, {len(app.pyro)});"]
    for g in gs:
        c.append(f"        if (fsw::load<uint64_t>(sv + E_{g}) + {per_cycle}u > time_base) "
                 f"time_base = fsw::load<uint64_t>(sv + E_{g}) + {per_cycle}u;")
    c.append("        time_based = true;")
    if app.tasks:  # the ground's modes go on, as the last cycle left them
        c.append(f"        for (uint8_t i = 0; i < {len(app.tasks)}; ++i) fsw::executor_set_task_mode(ex, i, kept_modes[i]);")
    c.append("        ex.reset_cause = static_cast<uint8_t>(ex.reset_cause | fsw::kResetResumed);")
    if app.reset_cause is not None:
        c.append(f"        sv[E_{app.reset_cause.name}] = ex.reset_cause;")
    c.append("    }")
    return c


def _app_cpp(app: Application) -> str:
    real = real_of(app)
    sources = [app.path, app.sv.path] + [m.path for m in app.machines] + sorted({c.path for c in app.channels})
    sources += sorted({p.path for p in app.sensors})
    c = [banner(sources, app.sv), '#include "fswkit.h"']
    if app.sensors:  # the drivers (firmware/src/fsw_sensor.h, fsw_accel.h)
        c.append('#include "fsw_sensor.h"')
    if any(p.part in ACCEL_PARTS for p in app.sensors):
        c.append('#include "fsw_accel.h"')
    c.append('#include "sv.gen.h"')
    for m in app.machines:
        c.append(f'#include "{c_ident(m.name)}.gen.h"')
    c += ["", version_check("app.gen.cpp"), real_check(basename(app.path), real),
          comment(f"// Board `{app.board.name}`: {app.board.mcu} at {app.board.f_cpu} Hz.")]
    c += _app_features(app)
    if any(t.kind in ("telemetry", "uplink") for t in app.tasks):
        c += _console_rx(app, any(t.kind == "uplink" for t in app.tasks))
    c += ["namespace fsw_gen {", "namespace {", ""]
    tables = _tables(app, real, c)
    if app.sensors:
        c += _sensor_objects(app)
    if app.pyro:
        c.append(f"fsw::PyroGate Pyro[{len(app.pyro)}];  // the pyro channels' pulses (docs/safety.md), in [pyro] order")
    if resumes(app):
        c.append(f"uint64_t time_base;  // G when the flight resumed ({app.time_unit}): the clock goes on from there")
        # the 64-bit addition only after a resume: on an 8-bit MCU a library
        # routine whose operands take sixteen registers, half of them saved
        # and restored around it in every caller of the clock
        c.append("bool time_based;  // a resume set time_base")
        c.append("FSW_NOINLINE uint64_t add_time_base(uint64_t t) { return time_base + t; }")
        c.append("inline uint64_t plus_time_base(uint64_t t) { return time_based ? add_time_base(t) : t; }")
    if app.pyro:
        c.append("")
    n = len(app.tasks)
    c.append(f"const uint32_t kPeriodUs = {1000000 // app.rate}UL;  // {app.rate} cycles per second")
    c.append("fsw::Executor ex;")
    c.append(f"fsw::TaskStats stats[{max(n, 1)}];")
    slow = any(t.divider > 1 for t in app.tasks)
    if slow:  # a task slower than every cycle counts down to its runs (else none is kept: kAppSlowTasks)
        c.append(f"uint16_t countdowns[{n}];  // base cycles until each task's next run")
    c.append("")
    has_link = any(t.kind in ("telemetry", "uplink") for t in app.tasks)
    params = app_parameters(app)
    if params:
        c += _params(app, params)
    if app.log is not None:
        c += _recorder(app)
    if app.reload is not None:
        c += _reload(app)
    if has_link:
        c += _link(app)
    if resumes(app):
        c += _resume(app)
    steps = {}
    if _shared_time_store(app):
        # G written by one function for every machine task (8 stores a call
        # on AVR); capitalised, so no machine's or task's name can be it.
        # With a link, through the link's clock function: one copy of the
        # clock's code (the 64-bit extension, the time base) for both.
        now = "link_now()" if has_link else _now(app)
        c.append(f"FSW_NOINLINE void store_G_now(uint8_t* g) {{ fsw::store<uint64_t>(g, {now}); }}")
        c.append("")
    for t in app.tasks:
        steps[t.name] = (None if (app.pyro and t is pyro_task(app)) or (app.sensors and t is sensor_task(app))
                         else _direct_step(t, tables))
        if steps[t.name] is None:
            c += _task_fn(app, t, tables)
    c.append(f"const fsw::Task kTasks[{max(n, 1)}] FSW_FLASH = {{")
    for t in app.tasks:
        mode = f"E_{t.mode.name}" if t.mode is not None else "fsw::kNoElement"
        over = f"E_{t.overruns.name}" if t.overruns is not None else "fsw::kNoElement"
        worst = f"E_{t.worst_us.name}" if t.worst_us is not None else "fsw::kNoElement"
        step, ctx = steps[t.name] or (f"task_{t.name}", "0")
        c.append(f"    {{{step}, 0, {ctx}, {t.divider}, 0, {mode}, {over}, {worst}, "
                 f"{TASK_MODES[t.start]}}},  // {basename(app.path)}:{t.line} {t.name} ({t.kind})")
    if not app.tasks:
        c.append("    {0, 0, 0, 1, 0, fsw::kNoElement, fsw::kNoElement, fsw::kNoElement, 0},")
    c.append("};")
    cause = f"E_{app.reset_cause.name}" if app.reset_cause is not None else "fsw::kNoElement"
    c.append(f"const fsw::ExecConfig kConfig FSW_FLASH = {{kTasks, stats, sv, kPeriodUs, {cause}, {n}, kSvLock, {'countdowns' if slow else '0'}}};")
    rows = " && ".join(f"fsw::exec_task_ok({t.divider}, 0)" for t in app.tasks) or "true"
    c.append(f"static_assert(fsw::exec_config_ok(kPeriodUs) && {rows}, "
             "\"a task table executor_begin refuses\");  // checked here, not at run time (fsw_app.h)")
    c.append("")
    c.append("}  // namespace")
    c.append("")
    c.append("// Starts the executor and the I/O channels; false on a bad table.")
    c.append("bool begin() {")
    if params:
        c.append("    fsw::param_begin(params, &kParamConfig);  // the newest valid EEPROM bank, else the defaults")
    if resumes(app):
        c.append("    // after a brown-out or a watchdog reset: the flight's state as the last cycle left it")
        c.append("    const bool resumed = fsw::resume_begin(resume, &kResumeConfig, fsw::pal::reset_cause());")
    if app.log is not None and resumes(app):
        c.append("    const uint8_t log_flight = rec.flight, log_mode = rec.mode;  // as kept")
    if app.reload is not None and resumes(app):
        c.append("    const uint8_t reload_active = reload.active;  // as kept")
        c.append("    // the newest activated image, else the generated machine; after a resume the one that ran, as kept")
        c.append("    fsw::reload_begin(reload, &kReloadConfig, resumed ? reload_active : fsw::kReloadNone);")
    elif app.reload is not None:
        c.append("    fsw::reload_begin(reload, &kReloadConfig);  // the newest activated image, else the generated machine")
    if app.log is not None:
        c.append("    fsw::log_begin(rec, &kLogConfig);  // goes on after the newest whole record")
    if app.log is not None and resumes(app):
        c.append("    if (resumed) fsw::log_resume(rec, log_flight, log_mode);  // the flight goes on being recorded")
    if resumes(app) and app.tasks:  # the kept modes, which the executor's start sets to each task's start=
        modes = ", ".join(f"sv[E_{t.mode.name}]" if t.mode is not None else f"stats[{i}].mode"
                          for i, t in enumerate(app.tasks))
        c.append(f"    const uint8_t kept_modes[{len(app.tasks)}] = {{{modes}}};  // as kept, if resumed")
    c.append("    if (fsw::executor_begin(ex, &kConfig) != fsw::kOk) return false;")
    if resumes(app):
        c += _resume_begin(app)
    for (kind, d), tag in tables.items():
        if kind in ("analog", "digital") and isinstance(tag, list):
            for ch in tag:
                c.append(f"    fsw::io_pin_begin({_pin(app, ch)}, {'fsw::kIoIn' if d == 'i' else 'fsw::kIoOut'});  "
                         f"// {basename(ch.path)}:{ch.line} {ch.element.name}")
        elif isinstance(tag, _Scan):  # the first scan, waited for: the first run reads it
            c.append(f"    fsw::io_analog_scan_begin({tag.tag}Pins, {len(tag.chans)}, {tag.tag}Raw);")
        elif kind in ("analog", "digital"):
            c.append(f"    if (fsw::io_{kind}_begin(&{tag}) != fsw::kOk) return false;")
    for p in app.pyro:
        o = p.output
        pin = (f"fsw::io_pin_begin({_pin(app, o)}, fsw::kIoOut);" if _pyro_direct(app)
               else f"fsw::pal::pin_mode({o.pin_number}, fsw::pal::kOutput);")
        c.append(f"    {pin}  // {basename(o.path)}:{o.line} {o.element.name} (pyro, low until fired)")
    if app.sensors:
        i2c, spi = (int(any(p.bus == bus for p in app.sensors)) for bus in ("i2c", "spi"))
        c.append(f"    fsw::sensors_begin({i2c}, {spi});  // the buses the parts are on: I2C {'yes' if i2c else 'no'}, "
                 f"SPI {'yes' if spi else 'no'}")
    if has_link:
        c.append(f"    fsw::pal::console_begin({app.baud}UL);")
        c.append("    fsw::link_begin(link, &kLinkConfig);  // its tables are checked where they are defined")
    c.append("    return true;")
    c.append("}")
    c.append("")
    if has_link or params or app.log is not None or app.reload is not None:
        c.append("// Runs a cycle when one is due; between cycles, feeds the serial link"
                 + (" and writes\n// the next parameter, image or record byte to the EEPROM when it is ready."
                    if params or app.log is not None or app.reload is not None else "."))
        c.append("void poll() {")
        busy = ([("fsw::link_busy(link)")] if has_link else []) + (["fsw::param_busy(params)"] if params else []) \
            + (["fsw::reload_writing(reload)"] if app.reload is not None else []) \
            + (["fsw::log_busy(rec)"] if app.log is not None else [])
        c.append(f"    const bool background = {' || '.join(busy)};  // else the CPU sleeps on until the cycle")
        if resumes(app):
            c.append("    if (fsw::executor_poll(ex, background)) fsw::resume_save(resume);  // the cycle's state, kept")
        else:
            c.append("    (void)fsw::executor_poll(ex, background);")
        if has_link:
            c.append("    fsw::link_poll(link);")
        if params:
            c.append("    fsw::param_poll(params);")
        if app.reload is not None:
            c.append("    fsw::reload_poll(reload);")
        if app.log is not None:
            c.append("    fsw::log_poll(rec);")
        c.append("}")
    else:
        c.append("// Runs a cycle when one is due.")
        c.append("void poll() { if (fsw::executor_poll(ex, false)) fsw::resume_save(resume); }" if resumes(app)
                 else "void poll() { (void)fsw::executor_poll(ex, false); }")
    c.append("// Runs one cycle now (hosts: simulations and tests).")
    c.append("void run_cycle() { fsw::executor_run_cycle(ex);" + (" fsw::resume_save(resume);" if resumes(app) else "")
             + " }")
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
    if not any(ch.analog and ch.direction == "o" for ch in app.channels):
        # No PWM output: nothing uses the core's timers, and the sleeping
        # executor's timer keeps the clock, so the core's init() (Timer0's
        # millis() tick and its interrupt, the PWM timers) is not needed.
        c.append("#if defined(__AVR__) && FSW_SLEEP")
        c.append("// The kit's start-up in place of the core's main() and init() (docs/runtime.md):")
        c.append("// no PWM output, and the executor's timer keeps the clock.")
        c.append("__attribute__((OS_main)) int main() {  // never returns: no register saved for its caller")
        c.append("    fsw::pal::boot();  // the ADC on, the UART's pins released, interrupts on")
        c.append("    setup();")
        c.append("    for (;;) loop();")
        c.append("}")
        c.append("#endif")
    c.append("#elif !defined(FSW_NO_MAIN)")
    c += _native_main(app)
    c.append("#endif")
    c.append("")
    return "\n".join(c)


# fsw_app.h AppFeature: (bit, name, whether the application uses it). The
# task table always passes no safe function (kAppSafeFns) and is checked
# here, when compiled (kAppTableChecks: the static_assert of its rows); the
# link is begun once, right after the reset, and polled only after
# (kAppBeginAgain: begin() and the main loop below).
APP_FEATURES = (
    (0x01, "kAppParams", lambda app: bool(app_parameters(app))),
    (0x02, "kAppLog", lambda app: app.log is not None),
    (0x04, "kAppReload", lambda app: app.reload is not None),
    (0x08, "kAppPyro", lambda app: bool(app.pyro)),
    (0x10, "kAppSensors", lambda app: bool(app.sensors)),
    (0x20, "kAppSvLock", lambda app: bool(app.sv.lock)),
    (0x40, "kAppModeElems", lambda app: any(t.mode is not None for t in app.tasks)),
    (0x80, "kAppMirrors", lambda app: any(t.overruns is not None or t.worst_us is not None for t in app.tasks)),
    (0x400, "kAppSlowTasks", lambda app: any(t.divider > 1 for t in app.tasks)),
    # where the uplink reads a command: in the console's receive ring, or a buffer the ring is emptied into
    (0x800, "kAppRxRing", lambda app: _has_uplink(app) and not _pipelined(app)),
    (0x1000, "kAppRxBuffer", lambda app: _has_uplink(app) and _pipelined(app)),
)


def _has_uplink(app: Application) -> bool:
    return any(t.kind == "uplink" for t in app.tasks)


def _pipelined(app: Application) -> bool:
    """Whether the application's ground pipelines its commands: the
    parameter client, which the reload commands go through too, keeps up to
    90 bytes in flight (docs/parameters.md). The link then takes a command's
    bytes off the receive ring each run into a buffer of its own
    (`link_rx`, fsw_app.h kAppRxBuffer), and the ring is the runtime's 64
    bytes; else one command is in flight, and the link decodes it where the
    ring (of 32) holds it (kAppRxRing)."""
    return bool(app_parameters(app)) or app.reload is not None


def _app_features(app: Application) -> list[str]:
    """The runtime's constants for this application (fsw_app.h): the
    features it uses and its base period, which LTO folds into the runtime
    (the code of the others dropped, the cycle timer's settings worked out
    when compiling)."""
    used = [(bit, name) for bit, name, test in APP_FEATURES if test(app)]
    bits = sum(bit for bit, _ in used)
    names = " | ".join(f"fsw::{name}" for _, name in used) or "none"
    return ["namespace fsw {",
            "// What this application uses of the runtime's optional paths (fsw_app.h): LTO drops the rest",
            f"extern const uint16_t app_features = 0x{bits:04x};  // {names}",
            f"extern const uint32_t app_period_us = {1000000 // app.rate}UL;  // the executor's base period",
            "}  // namespace fsw", ""]


def _direct_step(t: Task, tables) -> tuple[str, str] | None:
    """(step function, context) of a task that is one runtime call: the task
    table points at the runtime's function itself, so no generated wrapper
    copies it (LTO would inline each runtime task into its wrapper)."""
    if t.kind == "telemetry":
        return "fsw::link_telemetry_task", "&link"
    if t.kind == "uplink":
        return "fsw::link_uplink_task", "&link"
    if t.kind == "recorder":
        return "fsw::log_task", "&rec"
    if t.kind in ("inputs", "outputs"):
        d = "i" if t.kind == "inputs" else "o"
        calls = [(kind, tables[(kind, d)]) for kind in ("analog", "digital") if (kind, d) in tables]
        if len(calls) == 1 and not isinstance(calls[0][1], (list, _Scan)):
            kind, tag = calls[0]
            fn = tables.get(("task", tag), f"io_{kind}_task")
            return f"fsw::{fn}", f"const_cast<void*>(static_cast<const void*>(&{tag}))"
    return None


def pyro_task(app: Application) -> Task | None:
    """The outputs task that drives the pyro pins and counts their pulses:
    the fastest (the first of the fastest), as autocode/pyrocheck.py holds
    `pulse=` to at least one of its periods."""
    outputs = [t for t in app.tasks if t.kind == "outputs"]
    return max(outputs, key=lambda t: t.rate) if outputs else None


def pyro_pulse_runs(p, task: Task) -> int:
    """A channel's pulse in runs of the task that drives it: pulse x the
    task's rate, rounded up (the host's replay counts the same)."""
    return math.ceil(p.pulse * task.rate)  # exact: both are Fractions


def _pyro_lines(app: Application, t: Task) -> list[str]:
    """The outputs task's pyro pins, each through fsw::pyro_gate: the arming
    pins read now, the machine's state, the pulse in runs of this task, the
    continuity reading against its minimum. When a pulse starts, the
    flight's state is kept (fsw::resume_save) before any pin goes high: a
    reset from then on, the firing current's brown-out first of all, finds
    the channel fired and does not fire it again."""
    direct = _pyro_direct(app)
    name = basename(app.path)
    real = real_of(app)
    out = []
    for k, p in enumerate(app.pyro):
        runs = pyro_pulse_runs(p, t)
        if runs > 0xFFFF:
            raise GenError(f"{name}:{p.line}: pyro channel `{p.element.name}`: a pulse of {float(p.pulse):g} s is "
                           f"{runs} runs of `{t.name}`, more than 65535")
        m = app.machines[p.machine]
        ns = c_ident(m.name)
        fires = [next(st.name for st in m.states if st.id == s) for s in p.fire]
        arm = " && ".join(f"fsw::io_pin_read({_pin(app, a)})" if direct else f"fsw::pal::digital_read({a.pin_number})"
                          for a in p.arm)
        fire = " || ".join(f"{ns}::machine.state == {ns}::S_{st}" for st in fires)
        if p.continuity is not None:
            el = p.continuity.element
            # binary32 R: a float reading against its minimum as an integer
            # test of the element's key (as the machines test literals: no
            # float compare routine, each cycle, for each channel)
            intact = (float_key_test(">=", float(p.continuity_min), el.type.size, f"sv + E_{el.name}")
                      if real.bits == 32 and el.type.kind == "float" and not app.sv.lock else None)
            if intact is None:
                intact = f"fsw::read_{el.type.name}(sv + E_{el.name}) >= {real_literal(float(p.continuity_min), real)}"
            sense = f"({intact} ? fsw::kPyroContinuity : 0)"
        else:
            sense = "fsw::kPyroNoSense"
        gate = f"fsw::pyro_gate(Pyro[{k}], sv[E_{p.element.name}] != 0, {arm}, {fire}, {runs}u, {sense})"
        out.append(f"    // {name}:{p.line} pyro {p.element.name}, pin {p.output.pin}: armed by "
                   + ", ".join(a.element.name for a in p.arm) + ", fires in "
                   + ", ".join(fires) + f", {runs} runs ({float(p.pulse):g} s)"
                   + (f", intact at {p.continuity.element.name} >= {float(p.continuity_min):g}"
                      if p.continuity is not None else ""))
        out.append(f"    const bool pyro{k} = {gate};")
    if resumes(app):
        rose = " | ".join(f"Pyro[{k}].status" for k in range(len(app.pyro)))
        out.append(f"    if ((({rose}) & fsw::kPyroRose) != 0) fsw::resume_save(resume);  "
                   "// kept fired before the pin goes high")
    for k, p in enumerate(app.pyro):
        o = p.output
        if direct:
            out.append(f"    fsw::io_pin_write({_pin(app, o)}, pyro{k});")
        else:
            out.append(f"    fsw::pal::digital_write({o.pin_number}, pyro{k});")
    return out


# ---- sensor parts (`.sns` tables; docs/sensor-table.md) ----

ACCEL_PARTS = ("adxl345", "mpu6050")  # drivers of firmware/src/fsw_accel.h
DRIVER = {"bmp280": "Bmp280", "ms5611": "Ms5611", "adxl345": "Adxl345", "mpu6050": "Mpu6050"}
READING = {"pressure": "pressure_pa()", "temperature": "temp_c()", "x": "x_g()", "y": "y_g()", "z": "z_g()"}
_OSRS = {1: 1, 2: 2, 4: 3, 8: 4, 16: 5}  # BMP280 ctrl_meas oversampling codes
_MS_OSR = {256: 0, 512: 1, 1024: 2, 2048: 3, 4096: 4}
_RANGE = {2: 0, 4: 1, 8: 2, 16: 3}  # ADXL345 DATA_FORMAT range, MPU6050 AFS_SEL
_BW_RATE = {25: 0x8, 50: 0x9, 100: 0xA, 200: 0xB, 400: 0xC, 800: 0xD, 1600: 0xE, 3200: 0xF}  # ADXL345 BW_RATE


def sensor_task(app: Application) -> Task | None:
    """The inputs task that steps the sensor parts: the fastest (the first
    of the fastest)."""
    inputs = [t for t in app.tasks if t.kind == "inputs"]
    return max(inputs, key=lambda t: t.rate) if inputs else None


def sensor_args(p) -> str:
    """The driver's constructor arguments (firmware/src/fsw_sensor.h): the
    table's settings as the driver's codes."""
    st = dict(p.settings)
    tail = f"{st['stuck']}, {st['timeout']}"
    if p.part == "bmp280":
        return f"0x{p.address:02X}, {_OSRS[st['osrs_t']]}, {_OSRS[st['osrs_p']]}, {tail}"
    if p.part == "ms5611":
        return f"0x{p.address:02X}, {_MS_OSR[st['osr']]}, {tail}"
    if p.part == "adxl345":
        where, spi = (f"0x{p.address:02X}", 0) if p.bus == "i2c" else (str(p.cs_pin), 1)
        return f"{where}, {spi}, {_RANGE[st['range']]}, 0x{_BW_RATE[st['rate']]:X}, {tail}"
    return f"0x{p.address:02X}, {_RANGE[st['range']]}, {st['dlpf']}, {tail}"


def _sensor_objects(app: Application) -> list[str]:
    from ..sensors import sensor_name

    out = ["// The sensor parts (docs/sensor-table.md), in table order: the inputs task steps each"]
    for k, p in enumerate(app.sensors):
        settings = " ".join(f"{key}={v}" for key, v in p.settings)
        out.append(f"fsw::{DRIVER[p.part]} sensor{k}({sensor_args(p)});  "
                   f"// {basename(p.path)}:{p.line} {sensor_name(p)}: {settings}")
    out.append(f"uint8_t sensor_health[{len(app.sensors)}];  // their health codes (kSensor*) as the last step left "
               "them: the health frame's")
    out.append("")
    return out


def _sensor_lines(app: Application) -> list[str]:
    """The inputs task's lines for the sensor parts: each steps (never
    waits), then each reading goes to its element once the part has one,
    and the health code to the fault and health elements."""
    out = []
    for k, p in enumerate(app.sensors):
        out.append(f"    sensor{k}.step();  // {basename(p.path)}:{p.line} {p.part}")
    guard = "fsw::SvGuard<true> lock; " if app.sv.lock else ""
    for k, p in enumerate(app.sensors):
        out.append(f"    {{  // {basename(p.path)}:{p.line} {p.part}")
        out.append(f"        {guard}const uint8_t h = sensor{k}.health();")
        out.append(f"        sensor_health[{k}] = h;")
        if p.outputs:
            out.append(f"        if (sensor{k}.readings() != 0) {{  // before its first reading: the initial values")
            for q, el in p.outputs:
                value = ("-" if q.startswith("-") else "") + f"sensor{k}.{READING[q.lstrip('-')]}"
                if el.type.name == "F32":
                    write = f"fsw::store<float>(sv + E_{el.name}, {value});"
                else:
                    write = f"fsw::write_F64(sv + E_{el.name}, {value});"
                out.append(f"            {write}  // {q}")
            out.append("        }")
        if p.fault is not None:
            out.append(f"        fsw::store_bool(sv + E_{p.fault.name}, h >= fsw::kSensorNoAnswer);  // fault")
        if p.health is not None:
            out.append(f"        sv[E_{p.health.name}] = h;  // health")
        out.append("    }")
    return out


def _shared_time_store(app: Application) -> bool:
    """Whether machine tasks write G through one out-of-line function: two
    or more of them, no lock."""
    return not app.sv.lock and sum(t.kind == "machine" for t in app.tasks) >= 2


def _task_fn(app: Application, t: Task, tables) -> list[str]:
    out = [f"// Task `{t.name}` ({t.kind}), every {t.divider} cycle(s).",
           f"fsw::Result task_{t.name}(void*) {{"]
    if t.kind == "machine":
        m = app.machines[t.machine]
        g = m.vars[m.g].name
        if app.sv.lock:
            out.append(f"    {{ fsw::SvGuard<true> lock; fsw::store<uint64_t>(sv + E_{g}, {_now(app)}); }}")
        elif _shared_time_store(app):
            out.append(f"    store_G_now(sv + E_{g});")
        else:
            out.append(f"    fsw::store<uint64_t>(sv + E_{g}, {_now(app)});")
        same_tick = f"fsw::machine_same_tick({c_ident(m.name)}::machine, sv + E_{g})"
        if app.reload is not None and app.reload.machine == t.machine:
            if app.time_source != "cycle":  # a clock may not have ticked since the last run (docs/runtime.md)
                out.append(f"    if ({same_tick}) return fsw::kOk;  // the same tick as its last step: the next run steps")
            out.append("    return fsw::reload_step(reload);  // the generated machine, or an uploaded image")
        elif app.time_source != "cycle":
            # The step first: it refuses a G that is not above its last step's
            # (kErrTime) before it changes anything (machine_begin), so the
            # same tick is asked about only then, not on every run.
            out.append(f"    const fsw::Result r = {c_ident(m.name)}::step();")
            out.append(f"    return r == fsw::kErrTime && {same_tick} ? fsw::kOk : r;"
                       "  // the same tick as its last step: the next run steps")
        else:
            out.append(f"    return {c_ident(m.name)}::step();")
    elif t.kind in ("inputs", "outputs"):
        d = "i" if t.kind == "inputs" else "o"
        calls = [(kind, tables[(kind, d)]) for kind in ("analog", "digital") if (kind, d) in tables]
        if app.pyro and t is pyro_task(app):
            out += _pyro_lines(app, t)
            if not calls:
                out.append("    return fsw::kOk;")
        elif app.sensors and t is sensor_task(app):
            out += _sensor_lines(app)
            if not calls:
                out.append("    return fsw::kOk;")
        elif not calls:
            out.append("    return fsw::kOk;  // no channels in this direction")
        for k, (kind, tag) in enumerate(calls):
            if isinstance(tag, _Scan):
                out += _analog_inputs(app, real_of(app), tag)
                if k == len(calls) - 1:
                    out.append("    return fsw::kOk;")
                continue
            if isinstance(tag, list):
                for ch in tag:
                    fn = "io_digital_in" if d == "i" else "io_digital_out"
                    out.append(f"    fsw::{fn}({_pin(app, ch)}, sv + E_{ch.element.name});  "
                               f"// {basename(ch.path)}:{ch.line} pin {ch.pin}")
                if k == len(calls) - 1:
                    out.append("    return fsw::kOk;")
                continue
            fn = tables.get(("task", tag), f"io_{kind}_task")
            call = f"fsw::{fn}(const_cast<void*>(static_cast<const void*>(&{tag})))"
            if k == len(calls) - 1:
                out.append(f"    return {call};")
            else:
                out.append(f"    const fsw::Result r{k} = {call};")
                out.append(f"    if (r{k} != fsw::kOk) return r{k};")
    elif t.kind == "telemetry":
        out.append("    return fsw::link_telemetry_task(&link);")
    elif t.kind == "uplink":
        out.append("    return fsw::link_uplink_task(&link);")
    elif t.kind == "recorder":
        out.append("    return fsw::log_task(&rec);")
    else:
        raise GenError(f"{basename(app.path)}:{t.line}: task `{t.name}`: unknown task kind `{t.kind}`")
    out.append("}")
    out.append("")
    return out


LINK_BUFFER2_LOAD = 0.8  # the share of the line above which the link gets two frames' buffer
LINK_BUFFER2_SLACK = 64  # and this much more: the UART's transmit ring that once held it (docs/telemetry.md)


def _link(app: Application) -> list[str]:
    """The serial link's tables (docs/telemetry.md): streams, writable
    elements, buffers and the configuration, all constant data."""
    plan = link_plan(app)
    name = basename(app.path)
    c = ["// ---- the serial link (docs/telemetry.md) ----",
         f"// Link schema: the layout, the tasks, {len(plan.streams)} stream(s) and "
         f"{len(plan.writable)} writable element(s).",
         f"const uint32_t kLinkSchema = 0x{app_schema_hash(app):08x}UL;",
         f"const uint16_t kLinkTxSize = {plan.tx_cap};  // the longest encoded frame"]
    # A link loaded near its line rate gets a transmit buffer of two longest
    # frames and the LINK_BUFFER2_SLACK bytes the UART's transmit ring held
    # before the UART sent the frames from this buffer: a sample frame then
    # waits behind the rest of the one before (a health frame pushes the
    # next sample past its turn) instead of being dropped. Below
    # LINK_BUFFER2_LOAD of the line, one frame's buffer.
    load, capacity = link_load(app)  # the checker refuses a link that cannot carry it (autocode/limits.py)
    two = 2 * plan.tx_cap + LINK_BUFFER2_SLACK
    tx_buffer = (two if plan.streams and load > LINK_BUFFER2_LOAD * capacity and two <= 0xFFFF else plan.tx_cap)
    c.append(f"uint8_t link_tx[{tx_buffer}];  // " + ("two longest frames and 64 B: the link is loaded near its line rate"
                                                    if tx_buffer != plan.tx_cap else "one longest frame"))
    for s in plan.streams:
        if s.batch > 1:
            c.append(f"uint8_t link_store_{s.index}[{(s.batch - 1) * s.region.size}];  "
                     f"// the first {s.batch - 1} sample(s) of a {s.region.name} frame")
    if plan.streams:
        c.append(f"const fsw::LinkStream kLinkStreams[{len(plan.streams)}] FSW_FLASH = {{")
        for s in plan.streams:
            st = next(x for x in app.telemetry if x.region is s.region)
            store = f"link_store_{s.index}" if s.batch > 1 else "0"
            c.append(f"    {{R_{s.region.name}_off, R_{s.region.name}_size, {s.every}, {s.batch}, {store}}},  "
                     f"// {name}:{st.line} {s.region.name} at {s.rate} Hz, {s.batch} per frame")
        c.append("};")
        c.append(f"fsw::LinkStreamState link_streams[{len(plan.streams)}];")
    index = {e.name: i for i, e in enumerate(app.sv.elements)}
    rows = sorted(plan.writable, key=lambda e: index[e.name])
    for s in plan.streams:
        st = next(x for x in app.telemetry if x.region is s.region)
        why = c_string(f"{name}:{st.line}: stream {s.region.name} does not fit the link's buffers")
        c.append(f"static_assert(fsw::link_stream_ok(R_{s.region.name}_off, R_{s.region.name}_size, {s.every}, "
                 f"{s.batch}, {'true' if s.batch > 1 else 'false'}, kSvSize, kLinkTxSize), {why});")
    if rows:
        c.append(f"const fsw::LinkWritable kLinkWritable[{len(rows)}] FSW_FLASH = {{")
        for e in rows:
            c.append(f"    {{{index[e.name]}, E_{e.name}, {ELEM_CODE[e.type.name]}}},  // {e.name} ({e.type.name})")
        c.append("};")
        for e in rows:
            c.append(f"static_assert(fsw::link_writable_ok(E_{e.name}, {ELEM_CODE[e.type.name]}, kSvSize), "
                     f"\"writable element {e.name} lies outside the state vector\");")
    # Out of line where the machine tasks' store_G_now calls it too (one copy).
    noinline = "FSW_NOINLINE " if _shared_time_store(app) else ""
    c.append(f"{noinline}uint64_t link_now() {{ return {_now(app)}; }}  // the time `G` is written from, "
             f"{app.time_unit}")
    c.append(f"// Link load: about {round(load)} B/s of {round(capacity)} B/s at {app.baud} baud "
             f"({100 * load / capacity:.0f} %).")
    if load > capacity:
        raise GenError(f"{name}: the telemetry streams need about {round(load)} B/s but the link carries "
                       f"{round(capacity)} B/s at {app.baud} baud: lower the stream rates or raise `baud`")
    up = plan.uplink_task if plan.uplink_task is not None else 0xFF
    rx = _has_uplink(app) and _pipelined(app)
    if rx:
        c.append("uint8_t link_rx[FSW_LINK_RX_CAP];  // a command's bytes, taken off the receive ring each run "
                 "(the ground pipelines its commands)")
    c.append("const fsw::LinkConfig kLinkConfig FSW_FLASH = {")
    c.append(f"    sv, {'kLinkStreams' if plan.streams else '0'}, {'link_streams' if plan.streams else '0'}, "
             f"{'kLinkWritable' if rows else '0'}, &ex, link_now, link_tx, kLinkSchema, kSvSize,")
    c.append(f"    kLinkTxSize, {plan.health_every}, {plan.snapshot_chunk}, {len(plan.streams)}, {len(rows)}, "
             f"{plan.hello_every}, {up}, kSvLock"
             f"{_link_stores(app)}, {tx_buffer if tx_buffer != plan.tx_cap else 0}"
             + (", &reload, fsw::link_reload_apply, fsw::link_reload_ack" if app.reload is not None else ", 0, 0, 0")
             + (", link_rx" if rx else ", 0")
             + (f", sensor_health, {len(app.sensors)}" if app.sensors else ", 0, 0") + "};")
    c.append(f"static_assert(fsw::link_config_ok(kLinkTxSize, {plan.snapshot_chunk}, {len(plan.streams)}, "
             f"{len(app.tasks)}, {len(app.pyro) + len(app.sensors)}), "
             "\"the link's transmit buffer is too small for its control frames\");")
    c.append("fsw::Link link;")
    c.append("")
    return c


# The UART driver's receive ring (psl_arduino_console.cpp) of an application
# whose ground has one command in flight at a time: a command's bytes, a
# lone delimiter the ground's handshake sends first, the command's leading
# delimiter, its encoded frame of at most FSW_LINK_RX_CAP (24) bytes and its
# closing delimiter, 27 in all, wait there for the uplink task's next run; a
# ring of 32 holds 31. (Between two runs, 10 ms apart at 100 Hz, 118 bytes
# could arrive at 115200 baud: no ring short of 128 absorbs a ground that
# sends without waiting; the ground's clients wait for each ack: docs/telemetry.md.)
CONSOLE_RX_ONE_COMMAND = 32


def _console_rx(app: Application, uplink: bool) -> list[str]:
    """The UART driver's receive ring, sized for what the ground keeps in
    flight (docs/runtime.md, "The console"): the runtime's default
    (FSW_CONSOLE_RX_SIZE, 64) where the ground pipelines commands (the
    parameter client, which the reload commands go through too: its window
    keeps up to 90 bytes in flight); CONSOLE_RX_ONE_COMMAND where it sends
    one at a time; 4 bytes (the smallest ring) without an uplink task,
    where nothing reads it. On a board whose console is the core's Serial,
    nothing references it and the linker drops it."""
    if uplink and _pipelined(app):
        return ["// The UART's receive ring: the runtime's (FSW_CONSOLE_RX_SIZE): the ground pipelines commands "
                "(parameters, reload)", ""]
    size = CONSOLE_RX_ONE_COMMAND if uplink else 4
    why = ("one command in flight (the ground waits for each ack): its 27 bytes at most" if uplink
           else "no uplink task reads it")
    return [f"// The UART's receive ring (psl_arduino_console.cpp): {why}",
            "extern \"C\" {",
            f"uint8_t fsw_console_rx[{size}];",
            f"extern const uint8_t fsw_console_rx_mask = {size - 1};",
            "}", ""]


def _link_stores(app: Application) -> str:
    """The LinkConfig's last fields: the parameter store and the recorder
    (every field written: a partial initializer warns under -Wextra)."""
    out = ", &params, fsw::link_param_apply, fsw::link_param_ack" if app_parameters(app) else ", 0, 0, 0"
    out += ", &rec, fsw::link_log_apply, fsw::link_log_ack" if app.log is not None else ", 0, 0, 0"
    # the outputs task that ends the pulses: the target refuses a MODE that would stop it (LOCKED)
    out += f", Pyro, {len(app.pyro)}, {app.tasks.index(pyro_task(app))}" if app.pyro else ", 0, 0, 0xFF"
    return out


def _recorder(app: Application) -> list[str]:
    """The flight recorder's tables (docs/recorder.md): the fields and their
    encodings, the sample divider and erase permission of each state, RAM
    for the ring, the fifo and the previous sample."""
    from ..recorder import plan as log_plan
    from ..schema import app_schema_hash

    p = log_plan(app)
    name = basename(app.path)
    enc = {"raw": "fsw::kLogRaw", "hold": "fsw::kLogHold", "delta": "fsw::kLogDelta", "quant": "fsw::kLogQuant"}
    c = ["// ---- the flight recorder (docs/recorder.md) ----",
         f"const fsw::LogField kLogFields[{len(p.fields)}] FSW_FLASH = {{"]
    for f, lf in zip(p.fields, app.log.fields):
        scale = f"{float(1 / f.step)!r}f" if f.step is not None else "0.0f"
        c.append(f"    {{E_{f.name}, {ELEM_CODE[f.type.name]}, {enc[f.enc]}, {f.width}, {scale}}},  "
                 f"// {name}:{lf.line} {f.name} {f.enc}{'=' + str(f.step) if f.step is not None else ''}")
    c.append("};")
    c.append(f"const uint8_t kLogDividers[{len(p.dividers)}] FSW_FLASH = {{{', '.join(map(str, p.dividers))}}};"
             "  // by state id: task runs between samples (0: none)")
    c.append(f"const uint8_t kLogEraseOk[{len(p.erase_ok)}] FSW_FLASH = {{{', '.join(map(str, p.erase_ok))}}};")
    c.append(f"uint8_t log_ring[{p.ring_cap * p.sample_size}];  // {p.ring_cap} samples of {p.sample_size} B")
    c.append(f"uint8_t log_fifo[{p.fifo_cap}];")
    c.append(f"uint8_t log_last[{p.sample_size - 2}];")
    time_us = "true" if app.time_unit == "us" else "false"
    c.append(f"const fsw::LogConfig kLogConfig FSW_FLASH = {{sv, kLogDividers, E_{p.state_element}, {p.runs_mod}, "
             f"{len(p.dividers)}, {p.trigger}, kLogFields, kLogEraseOk, log_ring, log_fifo, log_last, "
             f"0x{app_schema_hash(app):08x}UL, 0x{p.hash:08x}UL, {p.before_ms}UL, E_{p.time_element}, {p.base}UL, "
             f"{p.slots}, {int(p.period_ms)}, {p.record}, {len(p.fields)}, {p.sample_size}, {p.ring_cap}, "
             f"{p.fifo_cap}, {p.n_hold}, {'true' if p.escape else 'false'}, {'true' if p.newest else 'false'}, "
             f"{time_us}}};")
    c.append(f"static_assert(fsw::log_config_ok({p.record}, {p.opening}, {p.worst}, {p.ring_cap}, {p.fifo_cap}, "
             f"{p.slots}), \"{name}: the recorder's tables\");")
    c.append("fsw::Recorder rec;")
    if p.store == "spi_nor":
        c.append(f"// {name}: {p.slots} records of {p.record} B on an SPI NOR flash of {p.flash_size} B, "
                 f"chip select on pin {p.cs_pin}; RAM {p.ram} B (docs/recorder.md, on an SPI NOR flash chip)")
    else:
        c.append(f"// {name}: {p.slots} records of {p.record} B from EEPROM byte {p.base}; "
                 f"RAM {p.ram} B (docs/recorder.md)")
    c += ["}  // namespace", "}  // namespace fsw_gen", "namespace fsw {"]
    if p.store == "spi_nor":
        c += [f"extern const uint8_t log_nor_cs = {p.cs_pin};  // the recorder's store: an SPI NOR flash (fsw_log.h)",
              "void log_read(const Recorder& r, uint16_t slot, uint8_t off, uint8_t n, uint8_t* out) {",
              "    log_nor_read(r, slot, off, n, out);",
              "}"]
    else:
        c += ["extern const uint8_t log_nor_cs = kLogEeprom;  // the recorder's store: the EEPROM (fsw_log.h)"]
    c += ["}  // namespace fsw", "namespace fsw_gen {", "namespace {", ""]
    return c


def _reload(app: Application) -> list[str]:
    """The reload store (docs/reload.md): the layout the VM checks images
    against, the generated machine's state mask, RAM for the running image
    and its windows and locals, and the slots' place in the EEPROM."""
    from ..params import HEADER as PHEADER
    from ..reloadcheck import eeprom_bytes
    from ..vmverify import board_features, feature_names

    rl = app.reload
    m = app.machines[rl.machine]
    ns = c_ident(m.name)
    name = basename(app.path)
    params = app_parameters(app)
    base = 2 * (PHEADER + sum(p.type.size for p in params)) if params else 0
    mask = bytearray((len(m.states) + 7) // 8)
    for st in m.states:
        if st.name in rl.activate:
            mask[(st.id - 1) // 8] |= 1 << ((st.id - 1) % 8)
    elems = ", ".join(f"{{E_{e.name}, {ELEM_CODE[e.type.name]}}}" for e in app.sv.elements)
    feats = board_features(app)
    have = ", ".join(feature_names(feats) + ["U32, U64 and bool"])
    return ["// ---- machines replaced at run time (docs/reload.md) ----",
            "}  // namespace", "}  // namespace fsw_gen", "namespace fsw {",
            f"// The VM's features (fsw_vm.h): {have}; LTO drops the code of the others, and an image",
            "// that needs one of them is refused (kVmNoFeature)",
            f"extern const uint16_t vm_features = 0x{feats:04x};",
            "}  // namespace fsw", "namespace fsw_gen {", "namespace {",
            f"// {name}:{rl.line}: machine {m.name}; two slots of {rl.size} B in the EEPROM from byte {base} "
            f"({eeprom_bytes(rl.size)} B); another machine may take over in " + ", ".join(rl.activate),
            f"const fsw::VmElem kReloadElems[{len(app.sv.elements)}] FSW_FLASH = {{{elems}}};",
            f"const fsw::VmLayout kReloadLayout = {{kReloadElems, {len(app.sv.elements)}, kSchemaHash}};",
            f"const uint8_t kReloadAllow[{len(mask)}] FSW_FLASH = {{{', '.join(f'0x{b:02x}' for b in mask)}}};"
            f"  // {' '.join(rl.activate)}",
            f"uint8_t reload_image[{rl.size}];  // the running image and its state mask (read a byte at a time)",
            f"alignas(fsw::kVmRamAlign) uint8_t reload_ram[{max(rl.ram, 1)}];  // its windows and locals",
            "const fsw::ReloadConfig kReloadConfig FSW_FLASH = {",
            f"    reload_image, reload_ram, sv, &kReloadLayout, &{ns}::machine, {ns}::step, {ns}::leave, {ns}::reset,",
            f"    kReloadAllow, {rl.size}, {rl.ram}, {base}, {len(mask)}}};",
            "fsw::ReloadStore reload;",
            ""]


def _params(app: Application, params) -> list[str]:
    """The parameter table (docs/parameters.md): where each value lives (its
    machine's `prm` block), its place in the value block, its range and
    states, the defaults, and the store."""
    from ..params import default_block, param_hash

    name = basename(app.path)
    pool = bytearray()
    defs, whens, when_rows = [], [], {}
    for p in params:
        rng = 0
        if not p.type.is_bool:
            rng = len(pool)
            pool += p.pack(p.min) + p.pack(p.max)
        key = (p.machine, p.when_ids)
        if key not in when_rows:
            n = (max(p.when_ids) + 7) // 8 if p.when_ids else 0
            mask = bytearray(n)
            for sid in p.when_ids:
                mask[(sid - 1) // 8] |= 1 << ((sid - 1) % 8)
            when_rows[key] = len(whens)
            whens.append((p.state_element, len(pool), n, p.machine, p.when))
            pool += mask
        defs.append((p, rng, when_rows[key]))
    size = sum(p.type.size for p in params)
    c = ["// ---- parameters (docs/parameters.md) ----",
         f"const fsw::ParamDef kParamDefs[{len(params)}] FSW_FLASH = {{"]
    for p, rng, w in defs:
        m = c_ident(p.machine)
        c.append(f"    {{{m}::prm + {m}::{enumerator('P_', p.name)}, {p.off}, {rng}, {ELEM_CODE[p.type.name]}, {w}}},  "
                 f"// {basename(p.path)}:{p.line} {p.name} ({p.type.name}, {p.range_text()}{' ' + p.unit if p.unit else ''})")
    c.append("};")
    c.append(f"const fsw::ParamWhen kParamWhens[{len(whens)}] FSW_FLASH = {{")
    for st, off, n, m, when in whens:
        c.append(f"    {{E_{st}, {off}, {n}}},  // {m}: {' '.join(when)}")
    c.append("};")
    c.append(f"const uint8_t kParamPool[{max(len(pool), 1)}] FSW_FLASH = {{{', '.join(str(b) for b in pool) or '0'}}};"
             "  // ranges, then state sets")
    c.append(f"const uint8_t kParamDefaults[{size}] FSW_FLASH = {{{', '.join(str(b) for b in default_block(params))}}};")
    c.append(f"uint8_t param_staged[{(len(params) + 7) // 8}];")
    c.append(f"const fsw::ParamConfig kParamConfig FSW_FLASH = {{kParamDefs, kParamWhens, kParamPool, kParamDefaults, "
             f"param_staged, sv, 0x{param_hash(params):08x}UL, {size}, 0, {len(params)}, kSvLock}};")
    c.append("fsw::ParamStore params;")
    c.append(f"// {name}: {len(params)} parameter(s), {size} B of values; their two banks take EEPROM bytes "
             f"0..{2 * (9 + size) - 1} (fsw::param_eeprom_end), the machine slots and the recorder follow")
    c.append("")
    return c


def _native_main(app: Application) -> list[str]:
    has_link = any(t.kind in ("telemetry", "uplink") for t in app.tasks)
    params = bool(app_parameters(app))
    nor = app.log is not None and getattr(app.log, "store", "eeprom") == "spi_nor"
    between = (['fsw::link_poll(fsw_gen::link);'] if has_link else []) + \
        (['fsw::param_poll(fsw_gen::params);'] if params else []) + \
        (['fsw::reload_poll(fsw_gen::reload);'] if app.reload is not None else []) + \
        (['fsw::log_poll(fsw_gen::rec);'] if app.log is not None else [])
    c = ['#include <stdio.h>',
         '#include <stdlib.h>',
         '#include <string.h>',
         '#include <time.h>',
         '#include <unistd.h>',
         '#include "psl_native.h"',
         '// Host build:',
         '//   app [PINS]             runs in step with the wall clock; the link on stdin/stdout',
         '//   app CYCLES [PINS]      runs CYCLES cycles on the simulated clock, then prints',
         '//                          the state vector as hex (link output discarded)',
         '//   app CYCLES --link [--uart BAUD] [PINS]',
         "//                          the same, with the link's bytes on stdout instead of the",
         "//                          hex; --uart models the UART's speed on the simulated clock",
         '//   PINS: aPIN=RAW sets an ADC reading, dPIN=0|1 a digital input level.',
         '//   --first-cycle N        starts the cycle count at N (with `[time] source cycle`,',
         '//                          G too): a long run\'s 2^32 wrap without the wait',
         '//   --eeprom FILE          the EEPROM model is loaded from FILE and written through to it']
    if nor:
        c += ['//   --flash FILE           the SPI NOR flash model (the flight recorder\'s store) is loaded',
              '//                          from FILE and written through to it']
    c += ['int main(int argc, char** argv) {']
    if nor:
        c += [f'    fsw::native::sim_flash_set_size({app.log.flash_size}UL);']
    c += ['    unsigned long cycles = 0, baud = 0;',
          '    unsigned long long first_cycle = 0;',
          '    bool simulated = false, link_out = false;',
          '    for (int i = 1; i < argc; ++i) {',
          '        unsigned pin = 0, value = 0;',
          '        char tail = 0;',
          '        if (strcmp(argv[i], "--link") == 0) {',
          '            link_out = true;',
          '        } else if (strcmp(argv[i], "--uart") == 0 && i + 1 < argc) {',
          '            baud = strtoul(argv[++i], 0, 10);',
          '        } else if (strcmp(argv[i], "--first-cycle") == 0 && i + 1 < argc) {',
          '            first_cycle = strtoull(argv[++i], 0, 10);',
          '        } else if (strcmp(argv[i], "--eeprom") == 0 && i + 1 < argc) {',
          '            if (!fsw::native::sim_eeprom_file(argv[++i])) {',
          '                fprintf(stderr, "cannot open the EEPROM file %s\\n", argv[i]);',
          '                return 2;',
          '            }',
          ] + ([
          '        } else if (strcmp(argv[i], "--flash") == 0 && i + 1 < argc) {',
          '            if (!fsw::native::sim_flash_file(argv[++i])) {',
          '                fprintf(stderr, "cannot open the flash file %s\\n", argv[i]);',
          '                return 2;',
          '            }',
          ] if nor else []) + [
          '        } else if (sscanf(argv[i], "a%u=%u%c", &pin, &value, &tail) == 2 && pin < 256 && value < 65536) {',
          '            fsw::native::sim_set_analog(static_cast<uint8_t>(pin), static_cast<uint16_t>(value));',
          '        } else if (sscanf(argv[i], "d%u=%u%c", &pin, &value, &tail) == 2 && pin < 256 && value < 2) {',
          '            fsw::native::sim_set_digital(static_cast<uint8_t>(pin), value != 0);',
          "        } else if (argv[i][0] >= '0' && argv[i][0] <= '9') {",
          '            cycles = strtoul(argv[i], 0, 10);',
          '            simulated = true;',
          '        } else {',
          '            fprintf(stderr, "usage: %s [CYCLES [--link] [--uart BAUD]] [--first-cycle N] [--eeprom FILE] '
          + ('[--flash FILE] ' if nor else '') + '[aPIN=RAW] [dPIN=0|1]\\n",',
          '                    argv[0]);',
          '            return 2;',
          '        }',
          '    }',
          '    static uint8_t discard[1];',
          '    static uint16_t discarded;',
          '    if (simulated && !link_out) fsw::native::console_capture(discard, 0, &discarded);',
          '    if (baud != 0) fsw::native::console_model_uart(static_cast<uint32_t>(baud), 64);',
          '    if (!fsw_gen::begin()) { fprintf(stderr, "the runtime refused a table\\n"); return 3; }',
          '    fsw_gen::ex.cycles = static_cast<uint32_t>(first_cycle);',
          '    fsw_gen::ex.cycles_high = static_cast<uint32_t>(first_cycle >> 32);',
          '    if (!simulated) {',
          '        // Paced by the wall clock, timed by the simulated one: cycle k runs at',
          '        // simulated time k periods, so G grows by exactly a period a cycle even',
          '        // when the host is slow (a late cycle runs late, never early or twice).',
          '        fsw::native::console_use_stdin(true);',
          '        timespec t0;',
          '        clock_gettime(CLOCK_MONOTONIC, &t0);',
          '        for (uint64_t k = 1;; ++k) {',
          '            fsw_gen::run_cycle();',
          '            fsw::native::sim_advance_us(fsw_gen::kPeriodUs);',
          '            for (;;) {',
          '                timespec t;',
          '                clock_gettime(CLOCK_MONOTONIC, &t);',
          '                const int64_t ahead = static_cast<int64_t>(k * fsw_gen::kPeriodUs) -',
          '                    ((t.tv_sec - t0.tv_sec) * 1000000LL + (t.tv_nsec - t0.tv_nsec) / 1000);']
    c += ['                ' + x for x in between]
    c += ['                if (ahead <= 0) break;',
          '                usleep(static_cast<useconds_t>(ahead > 1000 ? 1000 : ahead));',
          '            }',
          '        }',
          '    }',
          '    for (unsigned long i = 0; i < cycles; ++i) {',
         '        fsw_gen::run_cycle();']
    if between:
        c += ['        for (uint32_t t = 0; t < fsw_gen::kPeriodUs; t += 50) {  // loop() between cycles',
              '            fsw::native::sim_advance_us(fsw_gen::kPeriodUs - t < 50 ? fsw_gen::kPeriodUs - t : 50);']
        c += ['            ' + x for x in between]
        c += ['        }']
    else:
        c += ['        fsw::native::sim_advance_us(fsw_gen::kPeriodUs);']
    c += ['    }',
          '    if (link_out) {']
    if has_link:
        c += ['        fprintf(stderr, "console overruns: %lu\\n", static_cast<unsigned long>(fsw::native::console_overruns()));']
    c += ['        return 0;',
          '    }',
          '    for (uint16_t i = 0; i < fsw_gen::kSvSize; ++i) printf("%02x", fsw_gen::sv[i]);',
          '    printf("\\n");',
          '    return 0;',
          '}']
    return c
