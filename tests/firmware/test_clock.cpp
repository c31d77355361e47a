// Scenario: the 64-bit monotonic clock extended from 32-bit micros()/millis():
// wraps (every 71.6 minutes for micros) are invisible.
#include "test_support.h"

#if FSW_PLATFORM_NATIVE
#include "psl_native.h"
#else
#include <Arduino.h>
#endif

using namespace fsw;

void setUp(void) {
#if FSW_PLATFORM_NATIVE
    native::sim_reset();
#endif
}
void tearDown(void) {}

static void test_extend_counts_wraps(void) {
    Clock64 c = {0, 0};
    TEST_ASSERT_EQUAL_UINT64(0, clock64_extend(c, 0));
    TEST_ASSERT_EQUAL_UINT64(100, clock64_extend(c, 100));
    TEST_ASSERT_EQUAL_UINT64(0xFFFFFFF0ULL, clock64_extend(c, 0xFFFFFFF0UL));
    TEST_ASSERT_EQUAL_UINT64(0x100000005ULL, clock64_extend(c, 5));
    TEST_ASSERT_EQUAL_UINT64(0x100000005ULL, clock64_extend(c, 5));  // same reading
    TEST_ASSERT_EQUAL_UINT64(0x1FFFFFFFFULL, clock64_extend(c, 0xFFFFFFFFUL));
    TEST_ASSERT_EQUAL_UINT64(0x200000000ULL, clock64_extend(c, 0));
}

static void test_extend_is_monotonic_over_many_wraps(void) {
    Clock64 c = {0, 0};
    uint64_t t = 0, prev = 0;
    const uint32_t step = 0x3FFFFFFBUL;  // under a quarter of the wrap period
    for (int i = 0; i < 40; ++i) {
        t += step;
        const uint64_t got = clock64_extend(c, static_cast<uint32_t>(t));
        TEST_ASSERT_EQUAL_UINT64(t, got);
        TEST_ASSERT_TRUE(got > prev);
        prev = got;
    }
    TEST_ASSERT_EQUAL_UINT32(9, c.high);
}

#if FSW_PLATFORM_NATIVE
// The simulated board's micros() wraps like a real one's.
static void test_micros64_across_the_71_minute_wrap(void) {
    native::sim_set_time_us(0xFFFFFFFFULL - 10);
    TEST_ASSERT_EQUAL_UINT64(0xFFFFFFFFULL - 10, pal::micros64());
    native::sim_advance_us(20);
    TEST_ASSERT_EQUAL_UINT32(9, pal::micros32());  // the 32-bit clock wrapped
    TEST_ASSERT_EQUAL_UINT64(0xFFFFFFFFULL + 10, pal::micros64());
    // Three more hours in one-second reads: always equal to true time.
    for (int i = 0; i < 3 * 3600; ++i) {
        native::sim_advance_us(1000000);
        if (pal::micros64() != native::sim_time_us()) TEST_FAIL_MESSAGE("micros64 lost a wrap");
    }
}

static void test_millis64_across_the_49_day_wrap(void) {
    native::sim_set_time_us((0xFFFFFFFFULL - 5) * 1000);
    TEST_ASSERT_EQUAL_UINT64(0xFFFFFFFFULL - 5, pal::millis64());
    native::sim_advance_us(10 * 1000);
    TEST_ASSERT_EQUAL_UINT64(0xFFFFFFFFULL + 5, pal::millis64());
}
#else
static void test_micros64_follows_micros(void) {
#if FSW_SLEEP
    pal::cycle_timer_begin(10000);  // the clock runs on the executor's timer
#endif
    const uint64_t a = pal::micros64();
    delayMicroseconds(2000);
    const uint64_t b = pal::micros64();
    TEST_ASSERT_TRUE(b - a >= 2000 && b - a < 2200);
}
#endif

static void run(void) {
    UNITY_BEGIN();
    RUN_TEST(test_extend_counts_wraps);
    RUN_TEST(test_extend_is_monotonic_over_many_wraps);
#if FSW_PLATFORM_NATIVE
    RUN_TEST(test_micros64_across_the_71_minute_wrap);
    RUN_TEST(test_millis64_across_the_49_day_wrap);
#else
    RUN_TEST(test_micros64_follows_micros);
#endif
    (void)UNITY_END();
}

FSW_TEST_MAIN(run)
