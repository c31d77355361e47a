// Scenario: the cooperative executor: declared order, rate dividers and
// phases, modes (disabled / safed / enabled), fault -> safed, overrun count
// and worst step time (host: simulated clock; AVR: real time in simavr),
// late cycles, watchdog kicks, reset cause, table validation.
#include "test_support.h"

#if FSW_PLATFORM_NATIVE
#include "psl_native.h"
#else
#include <Arduino.h>
#include <avr/wdt.h>
#endif

using namespace fsw;

static char trace[64];
static uint8_t trace_len;
static uint8_t fail_on_call[4];   // step of task i faults on its n-th call (0: never)
static uint8_t calls[4];
static uint16_t busy_us[4];       // how long step i takes

static void note(char c) {
    if (trace_len + 1u < sizeof trace) trace[trace_len++] = c;
    trace[trace_len] = 0;
}

static void spend(uint16_t us) {
    if (us == 0) return;
#if FSW_PLATFORM_NATIVE
    native::sim_advance_us(us);
#else
    delayMicroseconds(us);
#endif
}

static uint32_t task0_at_us;  // when task 0 (first in every cycle) last started

static Result step_fn(void* ctx) {
    const uint8_t i = static_cast<uint8_t>(reinterpret_cast<uintptr_t>(ctx));
    if (i == 0) task0_at_us = pal::micros32();
    note(static_cast<char>('A' + i));
    ++calls[i];
    spend(busy_us[i]);
    return fail_on_call[i] != 0 && calls[i] == fail_on_call[i] ? kErrFault : kOk;
}

static void safe_fn(void* ctx) {
    const uint8_t i = static_cast<uint8_t>(reinterpret_cast<uintptr_t>(ctx));
    note(static_cast<char>('a' + i));
}

#define CTX(i) reinterpret_cast<void*>(static_cast<uintptr_t>(i))

// sv layout: modes @0..2 (U8), overruns of task 0 @3 (U16), worst of task 0
// @5 (U32), reset cause @9.
static uint8_t sv[10];
static TaskStats stats[3];
static uint16_t countdowns[3];  // B and C run less often than every cycle
static Executor ex;

static const Task kTasks[3] FSW_FLASH = {
    {step_fn, safe_fn, CTX(0), 1, 0, 0, 3, 5, kModeEnabled},
    {step_fn, safe_fn, CTX(1), 2, 0, 1, kNoElement, kNoElement, kModeEnabled},
    {step_fn, 0, CTX(2), 3, 1, 2, kNoElement, kNoElement, kModeEnabled},
};

// The executor keeps a pointer to its configuration: constant data, in
// flash on AVR.
static const ExecConfig kConfig FSW_FLASH = {kTasks, stats, sv, 1000, 9, 3, false, countdowns};

void setUp(void) {
    trace_len = 0;
    trace[0] = 0;
    memset(fail_on_call, 0, sizeof fail_on_call);
    memset(calls, 0, sizeof calls);
    memset(busy_us, 0, sizeof busy_us);
    memset(sv, 0, sizeof sv);
#if FSW_PLATFORM_NATIVE
    native::sim_reset();
    native::sim_set_reset_cause(0x08);
#endif
}

void tearDown(void) {
#if !FSW_PLATFORM_NATIVE
    wdt_disable();  // output after the test must not be cut by a reset
#endif
}

static void test_tasks_run_in_order_at_their_dividers_and_phases(void) {
    TEST_ASSERT_EQUAL(kOk, executor_begin(ex, &kConfig));
    for (int c = 0; c < 6; ++c) {
        executor_run_cycle(ex);
        note('|');
    }
    // A every cycle; B every 2nd from 0; C every 3rd from cycle 1.
    TEST_ASSERT_EQUAL_STRING("AB|AC|AB|A|ABC|A|", trace);
    TEST_ASSERT_EQUAL_UINT32(6, ex.cycles);
    TEST_ASSERT_EQUAL_UINT8(6, calls[0]);
    TEST_ASSERT_EQUAL_UINT8(3, calls[1]);
    TEST_ASSERT_EQUAL_UINT8(2, calls[2]);
}

static void test_begin_writes_initial_modes_into_mode_elements(void) {
    sv[0] = sv[1] = sv[2] = 77;
    TEST_ASSERT_EQUAL(kOk, executor_begin(ex, &kConfig));
    TEST_ASSERT_EQUAL_UINT8(kModeEnabled, sv[0]);
    TEST_ASSERT_EQUAL_UINT8(kModeEnabled, sv[1]);
    TEST_ASSERT_EQUAL_UINT8(kModeEnabled, sv[2]);
    TEST_ASSERT_EQUAL_UINT8(kModeEnabled, executor_task_mode(ex, 1));
}

static void test_modes_disabled_safed_enabled(void) {
    TEST_ASSERT_EQUAL(kOk, executor_begin(ex, &kConfig));
    sv[0] = kModeDisabled;
    sv[1] = kModeSafed;
    executor_run_cycle(ex);  // cycle 0: A disabled, B safed -> b
    TEST_ASSERT_EQUAL_STRING("b", trace);
    sv[0] = 200;             // not a mode: treated as safed
    executor_run_cycle(ex);  // cycle 1: A -> a, C enabled
    TEST_ASSERT_EQUAL_STRING("baC", trace);
    executor_set_task_mode(ex, 2, kModeSafed);  // C has no safe function
    sv[0] = kModeEnabled;
    executor_run_cycle(ex);
    executor_run_cycle(ex);  // cycle 3: A only
    executor_run_cycle(ex);  // cycle 4: A, B safed, C safed (nothing)
    TEST_ASSERT_EQUAL_STRING("baCAbAAb", trace);
    TEST_ASSERT_EQUAL_UINT8(kModeSafed, sv[2]);
}

static void test_a_faulting_step_safes_its_task(void) {
    fail_on_call[0] = 2;
    TEST_ASSERT_EQUAL(kOk, executor_begin(ex, &kConfig));
    executor_run_cycle(ex);
    executor_run_cycle(ex);  // A faults here
    TEST_ASSERT_EQUAL_UINT8(kModeSafed, sv[0]);
    TEST_ASSERT_EQUAL_UINT8(1, stats[0].faults);
    trace_len = 0;
    executor_run_cycle(ex);  // cycle 2: A safed -> a, B
    TEST_ASSERT_EQUAL_STRING("aB", trace);
    TEST_ASSERT_EQUAL_UINT8(2, calls[0]);
}

static void test_overrun_and_worst_step_time(void) {
    busy_us[0] = 1500;  // longer than its 1000 us period
    busy_us[1] = 1500;  // shorter than its 2000 us period
    TEST_ASSERT_EQUAL(kOk, executor_begin(ex, &kConfig));
    executor_run_cycle(ex);
    executor_run_cycle(ex);
    TEST_ASSERT_EQUAL_UINT16(2, stats[0].overruns);
    TEST_ASSERT_EQUAL_UINT16(0, stats[1].overruns);
    TEST_ASSERT_TRUE(stats[0].worst_us >= 1500);
    TEST_ASSERT_TRUE(stats[0].worst_us < 1700);
    TEST_ASSERT_TRUE(stats[1].worst_us >= 1500);
    // Mirrored into the state vector for telemetry.
    TEST_ASSERT_EQUAL_UINT16(2, load<uint16_t>(sv + 3));
    TEST_ASSERT_EQUAL_UINT32(stats[0].worst_us, load<uint32_t>(sv + 5));
}

static void test_poll_keeps_the_rate_and_counts_late_cycles(void) {
#if FSW_PLATFORM_NATIVE
    native::sim_set_time_us(5000);
    TEST_ASSERT_EQUAL(kOk, executor_begin(ex, &kConfig));
    TEST_ASSERT_TRUE(executor_poll(ex));     // due at once (t=5000)
    TEST_ASSERT_FALSE(executor_poll(ex));
    native::sim_advance_us(999);
    TEST_ASSERT_FALSE(executor_poll(ex));
    native::sim_advance_us(1);
    TEST_ASSERT_TRUE(executor_poll(ex));     // t=6000
    native::sim_advance_us(1200);
    TEST_ASSERT_TRUE(executor_poll(ex));     // t=7200, due 7000: late but < 1 period
    TEST_ASSERT_EQUAL_UINT16(0, ex.late);
    native::sim_advance_us(800);
    TEST_ASSERT_TRUE(executor_poll(ex));     // t=8000: schedule kept, no drift
    native::sim_advance_us(3500);
    TEST_ASSERT_TRUE(executor_poll(ex));     // t=11500: a full period late
    TEST_ASSERT_EQUAL_UINT16(1, ex.late);
    TEST_ASSERT_FALSE(executor_poll(ex));    // missed cycles are not run in a burst
    native::sim_advance_us(1000);
    TEST_ASSERT_TRUE(executor_poll(ex));
    TEST_ASSERT_EQUAL_UINT32(6, ex.cycles);
    TEST_ASSERT_EQUAL_UINT32(6, native::watchdog_kicks());
    TEST_ASSERT_TRUE(native::watchdog_armed());
#else
    TEST_ASSERT_EQUAL(kOk, executor_begin(ex, &kConfig));
    TEST_ASSERT_TRUE((WDTCSR & _BV(WDE)) != 0);  // watchdog armed
    const uint32_t start = pal::micros32();
    uint16_t ran = 0;
    while (pal::micros32() - start < 10500UL) {
        if (executor_poll(ex)) ++ran;
    }
    TEST_ASSERT_TRUE(ran >= 10 && ran <= 12);
    TEST_ASSERT_EQUAL_UINT16(0, ex.late);
#if FSW_SLEEP
    // Cycles start on the timer's count: one period apart to within a spin.
    uint32_t starts[4];
    for (uint8_t i = 0; i < 4;) {
        if (executor_poll(ex)) starts[i++] = task0_at_us;
    }
    for (uint8_t i = 1; i < 4; ++i) {
        const uint32_t d = starts[i] - starts[i - 1];
        TEST_ASSERT_TRUE(d >= 999 && d <= 1001);
    }
    // A step that runs past the next start: that cycle is late, because of
    // an overrun; a start that passed unserved is skipped, not run in a burst.
    busy_us[0] = 2300;
    while (!executor_poll(ex)) {
    }
    busy_us[0] = 0;
    while (!executor_poll(ex)) {
    }
    TEST_ASSERT_EQUAL_UINT16(1, ex.late);
    TEST_ASSERT_EQUAL_UINT16(1, ex.skipped);
    // Held between cycles (interrupts off past a start): late for another reason.
    while (!executor_poll(ex)) {
    }
    noInterrupts();
    delayMicroseconds(1100);
    interrupts();
    while (!executor_poll(ex)) {
    }
    TEST_ASSERT_EQUAL_UINT16(2, ex.late);
    // Reached later and later in the last stretch (as when handlers held
    // the CPU from the wake-up towards the start): a cycle not counted late
    // starts on time, as an undisturbed one does (its first task at the
    // same microsecond past the period's start, to within one); one the executor reached
    // too late to count the sub-period's end before the wrap (it does so
    // in the spin's time) is counted late. Both happen in the sweep.
    while (!executor_poll(ex)) {
    }
    const uint16_t on_time = static_cast<uint16_t>(task0_at_us % 1000u);
    uint16_t late = ex.late, on_time_seen = 0, late_seen = 0;
    for (uint16_t at = 1940; at < 1999u; at = static_cast<uint16_t>(at + 3u)) {
        noInterrupts();
        while (TCNT1 >= 1900u) {  // (past this cycle's start: the count is small)
        }
        while (TCNT1 < at) {  // (top 1999: 1 ms at 0.5 us a tick)
        }
        while (!executor_poll(ex)) {  // (it turns interrupts on)
        }
        if (ex.late != late) {
            ++late_seen;
        } else {
            ++on_time_seen;  // (within a spin: the clock's microsecond may differ by one)
            TEST_ASSERT_UINT16_WITHIN(1, on_time, task0_at_us % 1000u);
        }
        late = ex.late;
    }
    TEST_ASSERT_TRUE(on_time_seen > 0 && late_seen > 0);
    TEST_ASSERT_EQUAL_UINT16(1, ex.skipped);
    // A run's time: from the timer's count within the cycle while no
    // sub-period ended (task 0, then task 1 from 300 us on), from the
    // whole clock once one did (task 1 from 300 us to past the count's
    // wrap): each its step's time, as two reads of the whole clock gave.
    busy_us[0] = 300;
    busy_us[1] = 600;
    stats[0].worst_us = stats[1].worst_us = 0;
    for (uint8_t i = 0; i < 2;) {  // (task 1 runs every other cycle)
        if (executor_poll(ex)) ++i;
    }
    TEST_ASSERT_TRUE(stats[0].worst_us >= 300 && stats[0].worst_us < 400);
    TEST_ASSERT_TRUE(stats[1].worst_us >= 600 && stats[1].worst_us < 700);
    busy_us[1] = 900;
    stats[1].worst_us = 0;
    const uint16_t overruns = stats[1].overruns;
    for (uint8_t i = 0; i < 2;) {
        if (executor_poll(ex)) ++i;
    }
    busy_us[0] = busy_us[1] = 0;
    TEST_ASSERT_TRUE(stats[1].worst_us >= 900 && stats[1].worst_us < 1000);
    TEST_ASSERT_EQUAL_UINT16(overruns, stats[1].overruns);  // (within its 2,000 us)
#endif
#endif
}

static void test_reset_cause_is_captured(void) {
    TEST_ASSERT_EQUAL(kOk, executor_begin(ex, &kConfig));
    TEST_ASSERT_EQUAL_UINT8(pal::reset_cause(), ex.reset_cause);
    TEST_ASSERT_EQUAL_UINT8(ex.reset_cause, sv[9]);
#if FSW_PLATFORM_NATIVE
    TEST_ASSERT_EQUAL_UINT8(0x08, sv[9]);
#endif
}

// The cycle count is 64 bits: it keeps counting past the 2^32nd cycle
// (`[time] source cycle` derives G from it), and health frames still carry
// its low 32 bits where they always lay.
static void test_cycle_count_across_the_32_bit_wrap(void) {
    TEST_ASSERT_EQUAL(kOk, executor_begin(ex, &kConfig));
    TEST_ASSERT_EQUAL_UINT32(0, static_cast<uint32_t>(executor_cycles(ex) >> 32));
    ex.cycles = 0xFFFFFFFEUL;
    uint64_t last = executor_cycles(ex);
    for (uint8_t k = 0; k < 4; ++k) {
        executor_run_cycle(ex);
        TEST_ASSERT_TRUE(executor_cycles(ex) == last + 1);
        last = executor_cycles(ex);
    }
    TEST_ASSERT_TRUE(executor_cycles(ex) == 0x100000002ULL);
    TEST_ASSERT_EQUAL_UINT32(2, ex.cycles);
    TEST_ASSERT_EQUAL_UINT32(1, ex.cycles_high);
}

static const Task kBadDivider[1] FSW_FLASH = {{step_fn, 0, CTX(0), 0, 0, kNoElement, kNoElement, kNoElement, 2}};
static const Task kBadPhase[1] FSW_FLASH = {{step_fn, 0, CTX(0), 2, 2, kNoElement, kNoElement, kNoElement, 2}};
static const Task kNoStep[1] FSW_FLASH = {{0, 0, CTX(0), 1, 0, kNoElement, kNoElement, kNoElement, 2}};

static const ExecConfig kBadDividerConfig FSW_FLASH = {kBadDivider, stats, sv, 1000, 9, 1, false, countdowns};
static const ExecConfig kBadPhaseConfig FSW_FLASH = {kBadPhase, stats, sv, 1000, 9, 1, false, countdowns};
static const ExecConfig kNoStepConfig FSW_FLASH = {kNoStep, stats, sv, 1000, 9, 1, false, countdowns};
static const ExecConfig kNoPeriodConfig FSW_FLASH = {kTasks, stats, sv, 0, 9, 3, false, countdowns};
// slow tasks (B, C) and nowhere to count down to their runs
static const ExecConfig kNoCountdownsConfig FSW_FLASH = {kTasks, stats, sv, 1000, 9, 3, false, 0};
// every task every cycle: no countdowns needed
static const Task kEveryCycle[2] FSW_FLASH = {{step_fn, 0, CTX(0), 1, 0, kNoElement, kNoElement, kNoElement, 2},
                                              {step_fn, 0, CTX(1), 1, 0, kNoElement, kNoElement, kNoElement, 2}};
static const ExecConfig kEveryCycleConfig FSW_FLASH = {kEveryCycle, stats, sv, 1000, 9, 2, false, 0};

static void test_begin_refuses_bad_tables(void) {
    TEST_ASSERT_EQUAL(kErrConfig, executor_begin(ex, &kBadDividerConfig));
    TEST_ASSERT_EQUAL(kErrConfig, executor_begin(ex, &kBadPhaseConfig));
    TEST_ASSERT_EQUAL(kErrConfig, executor_begin(ex, &kNoStepConfig));
    TEST_ASSERT_EQUAL(kErrConfig, executor_begin(ex, &kNoPeriodConfig));
    TEST_ASSERT_EQUAL(kErrConfig, executor_begin(ex, &kNoCountdownsConfig));
}

static void test_tasks_of_every_cycle_need_no_countdowns(void) {
    TEST_ASSERT_EQUAL(kOk, executor_begin(ex, &kEveryCycleConfig));
    for (int c = 0; c < 3; ++c) {
        executor_run_cycle(ex);
        note('|');
    }
    TEST_ASSERT_EQUAL_STRING("AB|AB|AB|", trace);
}

#if FSW_PLATFORM_NATIVE
// The schedule runs on micros32(), which wraps every 71.6 minutes: across
// the wrap the rate holds, and a poll that comes half an hour late (under
// 2^31 us) counts as late, once.
static void test_poll_across_the_32_bit_wrap(void) {
    native::sim_set_time_us(0xFFFFFFFFull - 1500);  // 1.5 ms before the wrap
    TEST_ASSERT_EQUAL(kOk, executor_begin(ex, &kConfig));
    TEST_ASSERT_TRUE(executor_poll(ex));
    uint16_t ran = 1;
    for (uint16_t k = 0; k < 5000; ++k) {  // 5 ms in 1 us steps
        native::sim_advance_us(1);
        if (executor_poll(ex)) ++ran;
    }
    TEST_ASSERT_EQUAL_UINT16(6, ran);  // due at -1.5, -0.5, +0.5, ... +3.5 ms
    TEST_ASSERT_EQUAL_UINT16(0, ex.late);
    TEST_ASSERT_FALSE(executor_poll(ex));
    native::sim_advance_us(2000000000UL);  // 33 minutes without a poll
    TEST_ASSERT_TRUE(executor_poll(ex));
    TEST_ASSERT_EQUAL_UINT16(1, ex.late);
    TEST_ASSERT_FALSE(executor_poll(ex));
    native::sim_advance_us(1000);
    TEST_ASSERT_TRUE(executor_poll(ex));
}
#endif

static void run(void) {
    UNITY_BEGIN();
    RUN_TEST(test_tasks_run_in_order_at_their_dividers_and_phases);
    RUN_TEST(test_begin_writes_initial_modes_into_mode_elements);
    RUN_TEST(test_modes_disabled_safed_enabled);
    RUN_TEST(test_a_faulting_step_safes_its_task);
    RUN_TEST(test_overrun_and_worst_step_time);
    RUN_TEST(test_poll_keeps_the_rate_and_counts_late_cycles);
    RUN_TEST(test_reset_cause_is_captured);
    RUN_TEST(test_cycle_count_across_the_32_bit_wrap);
    RUN_TEST(test_begin_refuses_bad_tables);
    RUN_TEST(test_tasks_of_every_cycle_need_no_countdowns);
#if FSW_PLATFORM_NATIVE
    RUN_TEST(test_poll_across_the_32_bit_wrap);
#endif
    (void)UNITY_END();
}

FSW_TEST_MAIN(run)
