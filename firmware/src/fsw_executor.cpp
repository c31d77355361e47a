// The cooperative executor: a fixed-rate loop over a constant task table.
#include "fsw_executor.h"

#include "fsw_element.h"
#include "fsw_pal.h"

namespace fsw {

static void read_task(const Executor& ex, uint8_t i, Task& t) {
    flash_read(&t, &ex.cfg.tasks[i], sizeof t);
}

static uint8_t mode_of(const Executor& ex, const Task& t, uint8_t i) {
    return t.mode_off != kNoElement ? ex.cfg.sv[t.mode_off] : ex.cfg.stats[i].mode;
}

static void set_mode(Executor& ex, const Task& t, uint8_t i, uint8_t mode) {
    if (t.mode_off != kNoElement) {
        ex.cfg.sv[t.mode_off] = mode;  // one byte: atomic on every target
    } else {
        ex.cfg.stats[i].mode = mode;
    }
}

Result executor_begin(Executor& ex, const ExecConfig& cfg) {
    if (cfg.period_us == 0 || (cfg.n_tasks != 0 && (cfg.tasks == 0 || cfg.stats == 0))) {
        return kErrConfig;
    }
    ex.cfg = cfg;
    for (uint8_t i = 0; i < cfg.n_tasks; ++i) {
        Task t;
        read_task(ex, i, t);
        if (t.step == 0 || t.divider == 0 || t.phase >= t.divider) return kErrConfig;
        if (t.mode_off == kNoElement && t.overruns_off == kNoElement &&
            t.worst_us_off == kNoElement) {
            // nothing in the state vector: fine
        } else if (cfg.sv == 0) {
            return kErrConfig;
        }
        TaskStats& s = cfg.stats[i];
        memset(&s, 0, sizeof s);
        s.countdown = t.phase;
        set_mode(ex, t, i, t.init_mode);
    }
    pal::begin();
    ex.next_due_us = pal::micros64();
    ex.cycles = 0;
    ex.late = 0;
    ex.reset_cause = pal::reset_cause();
    if (cfg.reset_cause_off != kNoElement && cfg.sv != 0) cfg.sv[cfg.reset_cause_off] = ex.reset_cause;
    pal::watchdog_begin();
    return kOk;
}

static void mirror_stats(Executor& ex, const Task& t, const TaskStats& s) {
    if (t.overruns_off == kNoElement && t.worst_us_off == kNoElement) return;
    const pal::IrqState saved = ex.cfg.sv_lock ? pal::critical_enter() : 0;
    if (t.overruns_off != kNoElement) store<uint16_t>(ex.cfg.sv + t.overruns_off, s.overruns);
    if (t.worst_us_off != kNoElement) store<uint32_t>(ex.cfg.sv + t.worst_us_off, s.worst_us);
    if (ex.cfg.sv_lock) pal::critical_exit(saved);
}

void executor_run_cycle(Executor& ex) {
    pal::watchdog_kick();
    for (uint8_t i = 0; i < ex.cfg.n_tasks; ++i) {
        TaskStats& s = ex.cfg.stats[i];
        if (s.countdown != 0) {
            --s.countdown;
            continue;
        }
        Task t;
        read_task(ex, i, t);
        s.countdown = static_cast<uint16_t>(t.divider - 1u);
        const uint8_t mode = mode_of(ex, t, i);
        if (mode == kModeDisabled) continue;
#if FSW_TASK_TIMING
        const uint32_t start = pal::micros32();
#endif
        if (mode == kModeEnabled) {
            const Result r = t.step(t.ctx);
            if (r != kOk) {
                set_mode(ex, t, i, kModeSafed);
                s.last_fault = r;
                if (s.faults != 0xFFFFu) ++s.faults;
            }
        } else if (t.safe != 0) {
            t.safe(t.ctx);
        }
        ++s.runs;
#if FSW_TASK_TIMING
        const uint32_t took = pal::micros32() - start;
        if (took > s.worst_us) s.worst_us = took;
        if (took > ex.cfg.period_us * t.divider && s.overruns != 0xFFFFu) ++s.overruns;
#endif
        mirror_stats(ex, t, s);
    }
    ++ex.cycles;
}

bool executor_poll(Executor& ex) {
    // The idle path decides on 32 bits: the due time is never more than a
    // period ahead, so the wrap-safe difference of the low words tells. A
    // short idle pass is what keeps cycle starts close to their due time.
    const uint32_t due32 = static_cast<uint32_t>(ex.next_due_us & 0xFFFFFFFFu);
    if (static_cast<int32_t>(pal::micros32() - due32) < 0) return false;
    const uint64_t now = pal::micros64();
    if (now < ex.next_due_us) return false;
    if (now - ex.next_due_us >= ex.cfg.period_us) {
        if (ex.late != 0xFFFFu) ++ex.late;
        ex.next_due_us = now;
    }
    ex.next_due_us += ex.cfg.period_us;
    executor_run_cycle(ex);
    return true;
}

uint8_t executor_task_mode(const Executor& ex, uint8_t i) {
    Task t;
    read_task(ex, i, t);
    return mode_of(ex, t, i);
}

void executor_set_task_mode(Executor& ex, uint8_t i, uint8_t mode) {
    Task t;
    read_task(ex, i, t);
    set_mode(ex, t, i, mode);
}

}  // namespace fsw
