// Tasks and the fixed-rate cooperative executor: tasks run in table order,
// each every `divider` base cycles, in its mode (disabled / safed / enabled);
// per-task overruns and worst step time; watchdog kick; reset cause.
#ifndef FSW_EXECUTOR_H
#define FSW_EXECUTOR_H

#include "fsw_types.h"

namespace fsw {

// A task's step: kOk, or a fault code (the task is then safed).
typedef Result (*TaskStepFn)(void* ctx);
// What a safed task runs instead of its step.
typedef void (*TaskSafeFn)(void* ctx);

// Task modes, as stored in a task's U8 mode element. Any other value is
// treated as safed (the conservative reading of a corrupted byte).
enum TaskMode : uint8_t { kModeDisabled = 0, kModeSafed = 1, kModeEnabled = 2 };

// One row of the task table: constant data (FSW_FLASH on AVR).
struct Task {
    TaskStepFn step;
    TaskSafeFn safe;         // may be null: a safed task then does nothing
    void* ctx;               // passed to step/safe
    uint16_t divider;        // runs every `divider` base cycles, >= 1
    uint16_t phase;          // first runs at cycle `phase`, < divider
    ElemOff mode_off;        // U8 mode element, or kNoElement (mode kept in TaskStats)
    ElemOff overruns_off;    // U16 element mirroring TaskStats::overruns, or kNoElement
    ElemOff worst_us_off;    // U32 element mirroring TaskStats::worst_us, or kNoElement
    uint8_t init_mode;       // mode set by executor_begin
};

static_assert(offsetof(Task, overruns_off) == offsetof(Task, mode_off) + sizeof(ElemOff) &&
                  offsetof(Task, worst_us_off) == offsetof(Task, overruns_off) + sizeof(ElemOff),
              "a task's element offsets are adjacent (the link reads them as one)");

// Per-task run-time record (RAM, zero-initialised): 8 bytes. (A task that
// runs less often than every cycle counts down to its next run in the
// configuration's `countdowns`, RAM only an application with one has.)
struct TaskStats {
    uint32_t worst_us;       // longest step (or safe) call, microseconds
    uint16_t overruns;       // calls longer than the task's period (saturates)
    uint8_t faults;          // steps that returned a fault (saturates at 255)
    uint8_t mode;            // the mode, for a task without a mode element
};

// Executor configuration: constant data (FSW_FLASH on AVR), like the task
// table it points at; the Executor keeps a pointer to it.
struct ExecConfig {
    const Task* tasks;       // FSW_FLASH table of n_tasks rows
    TaskStats* stats;        // n_tasks records
    uint8_t* sv;             // state vector bytes (mode and stat elements)
    uint32_t period_us;      // base period: the fastest rate
    ElemOff reset_cause_off; // U8 element receiving the reset cause, or kNoElement
    uint8_t n_tasks;
    bool sv_lock;            // state vector `lock` option
    uint16_t* countdowns;    // n_tasks records, base cycles until each task's next run: required
                             // when a task's divider is above 1 (executor_begin refuses such a
                             // table without them), else null (every task runs every cycle)
};

struct Executor {
    const ExecConfig* cfg;   // FSW_FLASH
#if !FSW_SLEEP
    uint32_t next_due_us;    // start of the next cycle: micros32(), which wraps (the sleeping
                             // executor's schedule is its timer's: pal::cycle_wait)
#endif
    uint32_t cycles;         // cycles run, low 32 bits (health frames carry these)
    uint16_t late;           // cycles that started a full period or more late
    uint8_t reset_cause;     // captured at executor_begin
    uint32_t cycles_high;    // cycles run, high 32 bits: wraps of `cycles`
    // Cycle starts that passed unserved: skipped and counted (saturates).
    // (Why a cycle started late -- the previous cycle's tasks ran past its
    // start, or something else held the CPU then -- is counted nowhere:
    // nothing sent or read those two counters, 4 bytes of RAM.)
    uint16_t skipped;
    // 1: some task mirrors its overruns or worst time into elements (set by
    // executor_begin from the table: a cycle then looks at no row's offsets
    // when none does).
    uint8_t mirrors;
    // (The base period of each task run's overrun test is the application's
    // constant, app_period_us, or read out of the configuration: no copy in
    // RAM, 4 bytes a generated application never read.)
};

// Cycles run, all 64 bits: `[time] source cycle` keeps counting past the
// 2^32nd cycle (49.7 days at 1 kHz) instead of starting again from 0.
inline uint64_t executor_cycles(const Executor& ex) {
    // (high << 32) | low, read without the 64-bit shift an 8-bit MCU calls a
    // library routine for (little-endian targets, fsw_config.h)
    const uint32_t words[2] = {ex.cycles, ex.cycles_high};
    uint64_t n;
    memcpy(&n, words, sizeof n);
    return n;
}

// What executor_begin checks of a table, for one checked when compiled
// (generated code's static_assert; fsw_app.h kAppTableChecks): a base
// period, and each row's divider and phase. (Its step, the task table and
// the stats records are there by construction.)
constexpr bool exec_config_ok(uint32_t period_us) { return period_us != 0; }
constexpr bool exec_task_ok(uint16_t divider, uint16_t phase) { return divider != 0 && phase < divider; }

// Validates the table (dividers, phases), sets every task's initial mode,
// starts the platform, arms the watchdog, captures the reset cause. The
// first cycle is due at once. `cfg` points at an FSW_FLASH object that
// outlives the executor.
// Out of line: its copies of the configuration and of a task's row are on
// the stack only at boot, not in main()'s frame, which every path pays.
FSW_MUST_CHECK FSW_NOINLINE Result executor_begin(Executor& ex, const ExecConfig* cfg);
// Runs one cycle now: kicks the watchdog, then each due task in order.
void executor_run_cycle(Executor& ex);
// Runs a cycle if one is due (call from loop()); true when one ran.
// With FSW_SLEEP (AVR) it first sleeps until the cycle is due or another
// interrupt wakes the CPU (false then: loop() serves the link and calls
// again); cycles start on a hardware timer's count, a late one (started
// after its time) counts in `late` and in why, and a start that passed
// unserved is skipped. Otherwise it polls micros32(): a cycle that starts
// a full period late counts in `late`, and the schedule restarts from now
// (missed cycles are skipped, not run in a burst); compared wrap-safe, the
// due time never more than a period ahead, so a poll may come up to 2^31 us
// (35.8 minutes) late.
// `background`: whether the main loop has work between cycles (the
// sleeping executor then returns after any interrupt; pal::cycle_wait).
bool executor_poll(Executor& ex, bool background = true);

// The configuration the executor runs (a copy of its FSW_FLASH object).
ExecConfig executor_config(const Executor& ex);
// A task's current mode (from its element or its TaskStats).
uint8_t executor_task_mode(const Executor& ex, uint8_t i);
// Sets a task's mode (ground command, tests). Out of line: its copies of
// the configuration and the task's row are on the stack only while it runs,
// not in the frame of the uplink's command handler.
FSW_NOINLINE void executor_set_task_mode(Executor& ex, uint8_t i, uint8_t mode);

}  // namespace fsw

#endif  // FSW_EXECUTOR_H
