// The cooperative executor: a fixed-rate loop over a constant task table.
#include "fsw_executor.h"

#include "fsw_app.h"
#include "fsw_element.h"
#include "fsw_pal.h"

namespace fsw {

namespace {

void read_task(const ExecConfig& c, uint8_t i, Task& t) { flash_read(&t, &c.tasks[i], sizeof t); }

// Where a task's mode lives: its U8 element, else its TaskStats.
uint8_t* mode_byte(const ExecConfig& c, const Task& t, uint8_t i) {
    return app_has(kAppModeElems) && t.mode_off != kNoElement ? c.sv + t.mode_off : &c.stats[i].mode;
}

// A field of the configuration: from its copy where executor_begin made
// one, else out of flash (FSW_FLASH), read where used.
template <typename T>
inline __attribute__((always_inline)) T config_field(bool copied, const T& copy, const T& in_flash) {
    return copied ? copy : flash_get(in_flash);
}

}  // namespace

ExecConfig executor_config(const Executor& ex) {
    ExecConfig c;
    flash_read(&c, ex.cfg, sizeof c);
    return c;
}

Result executor_begin(Executor& ex, const ExecConfig* cfg) {
    // Where the application has no check, mirror, mode element nor slow task
    // (fsw_app.h), a row's start mode is all there is to read of it, and the
    // configuration is read a field at a time where used (FSW_FLASH: no copy
    // of it on the stack, nor avr-libc's memcpy_P; 46 B of the core rocket's
    // flash); else it is copied.
    const bool check = app_has(kAppTableChecks);
    const bool whole_rows = check || app_has(kAppMirrors | kAppModeElems | kAppSlowTasks);
    ExecConfig c;
    if (whole_rows) flash_read(&c, cfg, sizeof c);
    const uint8_t n_tasks = config_field(whole_rows, c.n_tasks, cfg->n_tasks);
    TaskStats* const stats = config_field(whole_rows, c.stats, cfg->stats);
    const Task* const tasks = config_field(whole_rows, c.tasks, cfg->tasks);  // (read once: a flash load stays in a loop)
    // (a generated table was checked when compiled: exec_config_ok, exec_task_ok)
    if (check && (c.period_us == 0 || (c.n_tasks != 0 && (c.tasks == 0 || c.stats == 0)))) return kErrConfig;
    uint8_t mirrors = 0;
    for (uint8_t i = 0; i < n_tasks; ++i) {
        if (!whole_rows) {
            TaskStats& s = stats[i];
            memset(&s, 0, sizeof s);
            s.mode = flash_get(tasks[i].init_mode);  // (its record: no mode element)
            continue;
        }
        Task t;
        read_task(c, i, t);
        if (check && (t.step == 0 || t.divider == 0 || t.phase >= t.divider)) return kErrConfig;
        if (check && c.sv == 0 &&
            (t.mode_off != kNoElement || t.overruns_off != kNoElement || t.worst_us_off != kNoElement)) {
            return kErrConfig;
        }
        if (check && t.divider > 1 && c.countdowns == 0) return kErrConfig;  // a slow task: its countdown
        if (app_has(kAppMirrors) && (t.overruns_off != kNoElement || t.worst_us_off != kNoElement)) mirrors = 1;
        TaskStats& s = stats[i];
        memset(&s, 0, sizeof s);
        if (app_has(kAppSlowTasks) && c.countdowns != 0) c.countdowns[i] = t.phase;
        *mode_byte(c, t, i) = t.init_mode;  // one byte: atomic on every target
    }
    pal::begin();
#if FSW_SLEEP
    // the base period: the application's constant where it has one (fsw_app.h; the timer's settings are
    // then worked out when compiling), else the configuration's, read only then (a flash load is never
    // dropped unused)
    pal::cycle_timer_begin(app_period_us != 0 ? app_period_us : config_field(whole_rows, c.period_us, cfg->period_us));
#endif
    memset(&ex, 0, sizeof ex);  // the counters (one clear: a store a field was 4 bytes of flash a byte)
    ex.cfg = cfg;
#if !FSW_SLEEP
    ex.next_due_us = pal::micros32();
#endif
    ex.mirrors = mirrors;
    ex.reset_cause = pal::reset_cause();
    const ElemOff reset_cause_off = config_field(whole_rows, c.reset_cause_off, cfg->reset_cause_off);
    uint8_t* const sv = config_field(whole_rows, c.sv, cfg->sv);
    if (reset_cause_off != kNoElement && sv != 0) sv[reset_cause_off] = ex.reset_cause;
    pal::watchdog_begin();
    return kOk;
}

namespace {

// What a cycle reads of a row before a task's run: its step, context,
// divider and mode offset. On AVR in one run of flash loads through Z: the
// compiler's loads, a field at a time, worked out each field's address
// afresh in registers of their own.
struct RowHead {
    TaskStepFn step;
    void* ctx;
    uint16_t divider;
    ElemOff mode_off;
};
inline __attribute__((always_inline)) RowHead row_head(const Task* row) {
    RowHead h;
#if defined(__AVR__) && FSW_USE_PROGMEM
    static_assert(offsetof(Task, step) == 0 && offsetof(Task, ctx) == 4 && offsetof(Task, divider) == 6 &&
                      offsetof(Task, mode_off) == 10,
                  "row_head's loads follow the row's layout");
    if (!app_has(kAppSlowTasks | kAppModeElems)) {  // (fsw_app.h) neither the divider nor the mode offset used
        __asm__(
            "lpm  %A[step], Z+\n\t"
            "lpm  %B[step], Z+\n\t"
            "adiw r30, 2\n\t"  // the safe function: read only for a safed task
            "lpm  %A[ctx], Z+\n\t"
            "lpm  %B[ctx], Z\n\t"
            : [step] "=&r"(h.step), [ctx] "=&r"(h.ctx), "+z"(row));
        h.divider = 1;
        h.mode_off = kNoElement;
        return h;
    }
    __asm__(
        "lpm  %A[step], Z+\n\t"
        "lpm  %B[step], Z+\n\t"
        "adiw r30, 2\n\t"  // the safe function: read only for a safed task
        "lpm  %A[ctx], Z+\n\t"
        "lpm  %B[ctx], Z+\n\t"
        "lpm  %A[div], Z+\n\t"
        "lpm  %B[div], Z+\n\t"
        "adiw r30, 2\n\t"  // the phase: executor_begin's
        "lpm  %A[mode], Z+\n\t"
        "lpm  %B[mode], Z\n\t"
        : [step] "=&r"(h.step), [ctx] "=&r"(h.ctx), [div] "=&r"(h.divider), [mode] "=&r"(h.mode_off), "+z"(row));
#else
    h.step = flash_get(row->step);
    h.ctx = flash_get(row->ctx);
    h.divider = flash_get(row->divider);
    h.mode_off = flash_get(row->mode_off);
#endif
    return h;
}

// The clock, for a task run's time: on the sleeping executor micros32()'s
// code inline (fsw_pal.h).
inline __attribute__((always_inline)) uint32_t now_us() {
#if FSW_SLEEP
    return pal::micros32_inline();
#else
    return pal::micros32();
#endif
}

// Where a task's mode lives, for a running cycle: its U8 element, else its
// TaskStats (mode_byte without the copies of the configuration and the row).
inline uint8_t* mode_at(const ExecConfig& f, ElemOff off, TaskStats& s) {
    return app_has(kAppModeElems) && off != kNoElement ? flash_get(f.sv) + off : &s.mode;
}

}  // namespace

// A cycle keeps across a task's step only what the next turn needs: the
// row, its record, the table's end, the clock's mark and where the mode
// lives. The state vector's address is read out of flash when a run needs
// it (a mode element, a mirror), the base period out of the Executor for
// the overrun test: kept in registers for the whole cycle as well, they
// pushed the others onto the stack in loop(), where the cycle is inlined
// (on the rocket's seven tasks, 1,221 AVR cycles a cycle between and
// around the task steps before, about 1,030 since; a per-instruction
// profile of the demo flight). The period from RAM and the clock read
// inline (now_us) took the time between the rocket's task steps from 70
// to 58 us a cycle (tools/bench_busy.py, 2026-12-07). A turn a task: the
// run's time, its record and its mirrors right after it (no turn past the
// last run, no test of whether the turn before ran one), for a second copy
// of the clock's inline read before the first: 2.5 us a cycle on the
// rocket for 52 B of flash (2026-12-07, night; an outer turn a run with
// the clock read at one place, the next task found by an inner loop, took
// the same time as before). The kit's main(), where the cycle is inlined,
// saves no register for its caller (OS_main): the registers this loop
// keeps cost no stack.
#if FSW_TASK_TIMING
// A run timed by two whole clock reads: its worst, and an overrun when it
// took longer than its period. A run within the base period is within the
// task's (divider >= 1): the product, a 32-bit multiplication, only for the
// longer ones.
static inline __attribute__((always_inline)) void note_whole_run(TaskStats& s, uint32_t took, const ExecConfig& f,
                                                                 const Task* row) {
    if (took > s.worst_us) s.worst_us = took;
    const uint32_t period_us = app_period_us != 0 ? app_period_us : flash_get(f.period_us);  // the base period
    if (took > period_us && (!app_has(kAppSlowTasks) || took > period_us * flash_get(row->divider)) &&
        s.overruns != 0xFFFFu) {
        ++s.overruns;
    }
}
#endif

void executor_run_cycle(Executor& ex_) {
    Executor& ex = *by_pointer(&ex_);
    pal::watchdog_kick();
    // The configuration's fields read out of flash one at a time, only those
    // a cycle uses (no copy routine for the whole of it: a cycle's 10 us).
    const ExecConfig& f = *ex.cfg;
    TaskStats* sp = flash_get(f.stats);
    const Task* row = flash_get(f.tasks);
    const Task* const end = row + flash_get(f.n_tasks);
    // a slow task's countdown (fsw_app.h: none where every task runs every cycle)
    uint16_t* cp = app_has(kAppSlowTasks) ? flash_get(f.countdowns) : 0;
    // One clock read per task run, and one at the cycle's start: a run is
    // timed from the previous run's end (the cycle's start for the first)
    // to its own end, so it counts the executor's few instructions that
    // find and start it too.
#if FSW_TASK_TIMING
#if FSW_SLEEP
    // The marks are microseconds past the clock's base at the cycle's start
    // (`base`): a run while no sub-period ended takes the difference of two
    // counts within it (pal::cycle_clock), 16 bits, and is within the base
    // period (a sub-period is no longer); a run past an end reads the whole
    // clock. Either takes what two whole reads would (tested:
    // tests/firmware/test_executor.cpp).
    uint16_t at;
    const uint32_t base = pal::cycle_base(at);
    uint32_t mark = at;
#else
    uint32_t mark = now_us();
#endif
#endif
    for (; row != end; ++row, ++sp) {
        TaskStats& s = *sp;
        uint16_t* const countdown = cp;  // (null: every task runs every cycle)
        if (countdown != 0) {
            ++cp;
            if (*countdown != 0) {
                --*countdown;
                continue;
            }
        }
        const RowHead h = row_head(row);
        if (countdown != 0) *countdown = static_cast<uint16_t>(h.divider - 1u);
        uint8_t* const mode_p = mode_at(f, h.mode_off, s);
        const uint8_t mode = *mode_p;
        if (mode == kModeDisabled) continue;
        if (mode == kModeEnabled) {
            const Result r = h.step(h.ctx);
            if (r != kOk) {
                *mode_p = kModeSafed;
                if (s.faults != 0xFFu) ++s.faults;
            }
        } else if (app_has(kAppSafeFns)) {
            const TaskSafeFn safe = flash_get(row->safe);
            if (safe != 0) safe(h.ctx);
        }
#if FSW_TASK_TIMING
#if FSW_SLEEP
        uint16_t us;
        if (pal::cycle_clock(us)) {  // (the mark too was a count within the cycle's first sub-period)
            const uint16_t took = static_cast<uint16_t>(us - static_cast<uint16_t>(mark));
            mark = us;
            if (took > s.worst_us) s.worst_us = took;
        } else {
            const uint32_t now = now_us() - base;
            note_whole_run(s, now - mark, f, row);
            mark = now;
        }
#else
        const uint32_t now = now_us();
        note_whole_run(s, now - mark, f, row);
        mark = now;
#endif
#endif
        if (app_has(kAppMirrors) && ex.mirrors != 0) {  // (ex.mirrors: some row has an element to mirror into)
            const ElemOff overruns_off = flash_get(row->overruns_off), worst_us_off = flash_get(row->worst_us_off);
            if (overruns_off != kNoElement || worst_us_off != kNoElement) {
                uint8_t* const sv = flash_get(f.sv);
                const bool lock = app_has(kAppSvLock) && flash_get(f.sv_lock);
                const pal::IrqState saved = lock ? pal::critical_enter() : 0;
                if (overruns_off != kNoElement) store<uint16_t>(sv + overruns_off, s.overruns);
                if (worst_us_off != kNoElement) store<uint32_t>(sv + worst_us_off, s.worst_us);
                if (lock) pal::critical_exit(saved);
            }
        }
    }
    if (++ex.cycles == 0) ++ex.cycles_high;
}

#if FSW_SLEEP
namespace {
inline void count(uint16_t& n, uint8_t by) {
    n = static_cast<uint16_t>(n > 0xFFFFu - by ? 0xFFFFu : n + by);
}
}  // namespace

bool executor_poll(Executor& ex_, bool background) {
    Executor& ex = *by_pointer(&ex_);
    uint8_t skipped;
    const uint8_t why = pal::cycle_wait(skipped, background);
    if (why == pal::kCycleNotDue) return false;
    if (why != pal::kCycleOnTime) count(ex.late, 1);
    count(ex.skipped, skipped);
    executor_run_cycle(ex);
    pal::cycle_end();
    return true;
}
#else
bool executor_poll(Executor& ex, bool) {
    // On 32 bits, wrap-safe: the due time is never more than a period ahead,
    // so the signed difference tells "not yet" from "late by so much" for
    // any lateness under 2^31 us (35.8 minutes; the watchdog resets an AVR
    // long before). A short idle pass keeps cycle starts close to their due
    // time: it reads nothing else.
    const uint32_t late_by = pal::micros32() - ex.next_due_us;
    if (static_cast<int32_t>(late_by) < 0) return false;
    uint32_t period = app_period_us;
    if (period == 0) flash_read(&period, &ex.cfg->period_us, sizeof period);
    if (late_by >= period) {
        if (ex.late != 0xFFFFu) ++ex.late;
        const uint32_t missed = late_by / period;  // cycle starts that passed unserved
        ex.skipped = static_cast<uint16_t>(ex.skipped > 0xFFFFu - missed ? 0xFFFFu : ex.skipped + missed);
        ex.next_due_us += late_by;  // restart the schedule from now
    }
    ex.next_due_us += period;
    executor_run_cycle(ex);
    return true;
}
#endif

uint8_t executor_task_mode(const Executor& ex, uint8_t i) {
    if (!app_has(kAppModeElems)) return flash_get(ex.cfg->stats)[i].mode;  // no task has a mode element
    const ExecConfig c = executor_config(ex);
    Task t;
    read_task(c, i, t);
    return *mode_byte(c, t, i);
}

void executor_set_task_mode(Executor& ex, uint8_t i, uint8_t mode) {
    if (!app_has(kAppModeElems)) {  // no task has a mode element (fsw_app.h)
        flash_get(ex.cfg->stats)[i].mode = mode;
        return;
    }
    const ExecConfig c = executor_config(ex);
    Task t;
    read_task(c, i, t);
    *mode_byte(c, t, i) = mode;
}

}  // namespace fsw
