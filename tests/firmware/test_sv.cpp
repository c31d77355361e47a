// Scenario: the packed state vector: unaligned little-endian element access,
// F64 stored as 8 bytes everywhere, region copy-in/out with bounds, and the
// lock (threads on the host, interrupts off on AVR).
#include "test_support.h"

#if FSW_PLATFORM_NATIVE
#include <pthread.h>
#else
#include <avr/interrupt.h>
#endif

using namespace fsw;

void setUp(void) {}
void tearDown(void) {}

// Layout: U8 @0, F64 @1, U16 @9, I32 @11, U64 @15, F32 @23, bool @27.
static uint8_t bytes[28];

static void test_elements_are_packed_little_endian_at_any_alignment(void) {
    memset(bytes, 0, sizeof bytes);
    write_U8(bytes + 0, 200);
    write_F64(bytes + 1, Real(1.5));
    write_U16(bytes + 9, 0x1234);
    write_I32(bytes + 11, -2);
    store<uint64_t>(bytes + 15, 0x0102030405060708ULL);
    write_F32(bytes + 23, Real(-2));
    write_bool(bytes + 27, 1);
    const uint8_t expected[28] = {200,
                                  0, 0, 0, 0, 0, 0, 0xF8, 0x3F,   // 1.5 as binary64
                                  0x34, 0x12,
                                  0xFE, 0xFF, 0xFF, 0xFF,
                                  8, 7, 6, 5, 4, 3, 2, 1,
                                  0, 0, 0, 0xC0,                  // -2 as binary32
                                  1};
    TEST_ASSERT_EQUAL_HEX8_ARRAY(expected, bytes, 28);
    ASSERT_REAL_SAME(Real(200), read_U8(bytes));
    ASSERT_REAL_SAME(Real(1.5), read_F64(bytes + 1));
    ASSERT_REAL_SAME(Real(0x1234), read_U16(bytes + 9));
    ASSERT_REAL_SAME(Real(-2), read_I32(bytes + 11));
    TEST_ASSERT_EQUAL_HEX64(0x0102030405060708ULL, load<uint64_t>(bytes + 15));
    ASSERT_REAL_SAME(Real(-2), read_F32(bytes + 23));
    ASSERT_REAL_SAME(Real(1), read_bool(bytes + 27));
}

static void test_region_copy_in_and_out(void) {
    StateVector sv = {bytes, sizeof bytes, false};
    const Region r = {9, 6};
    uint8_t out[6];
    memset(bytes, 0, sizeof bytes);
    write_U16(bytes + 9, 0xBEEF);
    TEST_ASSERT_EQUAL(kOk, region_copy_out(sv, r, out));
    TEST_ASSERT_EQUAL_HEX8(0xEF, out[0]);
    TEST_ASSERT_EQUAL_HEX8(0xBE, out[1]);
    const uint8_t in[6] = {1, 2, 3, 4, 5, 6};
    sv.lock = true;
    TEST_ASSERT_EQUAL(kOk, region_copy_in(sv, r, in));
    TEST_ASSERT_EQUAL_HEX8_ARRAY(in, bytes + 9, 6);
    TEST_ASSERT_EQUAL_HEX8(0, bytes[8]);
    TEST_ASSERT_EQUAL_HEX8(0, bytes[15]);
    const Region past = {23, 6};
    TEST_ASSERT_EQUAL(kErrRange, region_copy_out(sv, past, out));
    TEST_ASSERT_EQUAL(kErrRange, sv_copy_in(sv, 0xFFFF, 2, in));
    TEST_ASSERT_EQUAL(kOk, sv_copy_out(sv, 22, 6, out));  // ends exactly at the end
}

static void test_guard_without_lock_costs_nothing(void) {
    TEST_ASSERT_EQUAL(1, sizeof(SvGuard<false>));  // empty class
    SvGuard<false> g;
    (void)g;
}

#if FSW_PLATFORM_NATIVE
static uint64_t shared_counter_bytes[2];  // an 8-byte element, 8-byte aligned storage

static void* hammer(void*) {
    uint8_t* p = reinterpret_cast<uint8_t*>(shared_counter_bytes) + 3;  // unaligned on purpose
    for (int i = 0; i < 200000; ++i) {
        SvGuard<true> g;
        SvGuard<true> nested;  // re-entrant: must not deadlock
        store<uint64_t>(p, load<uint64_t>(p) + 1);
    }
    return 0;
}

static void test_lock_makes_read_modify_write_atomic_across_threads(void) {
    memset(shared_counter_bytes, 0, sizeof shared_counter_bytes);
    pthread_t a, b;
    TEST_ASSERT_EQUAL(0, pthread_create(&a, 0, hammer, 0));
    TEST_ASSERT_EQUAL(0, pthread_create(&b, 0, hammer, 0));
    pthread_join(a, 0);
    pthread_join(b, 0);
    TEST_ASSERT_EQUAL_UINT64(400000, load<uint64_t>(reinterpret_cast<uint8_t*>(shared_counter_bytes) + 3));
}
#else
static void test_lock_disables_interrupts_and_restores_them(void) {
    sei();
    {
        SvGuard<true> outer;
        TEST_ASSERT_EQUAL(0, SREG & _BV(SREG_I));
        {
            SvGuard<true> inner;
            TEST_ASSERT_EQUAL(0, SREG & _BV(SREG_I));
        }
        TEST_ASSERT_EQUAL(0, SREG & _BV(SREG_I));  // inner restored "off"
    }
    TEST_ASSERT_TRUE((SREG & _BV(SREG_I)) != 0);
    cli();
    { SvGuard<true> g; }
    TEST_ASSERT_EQUAL(0, SREG & _BV(SREG_I));  // stays off when it was off
    sei();
}
#endif

static void run(void) {
    UNITY_BEGIN();
    RUN_TEST(test_elements_are_packed_little_endian_at_any_alignment);
    RUN_TEST(test_region_copy_in_and_out);
    RUN_TEST(test_guard_without_lock_costs_nothing);
#if FSW_PLATFORM_NATIVE
    RUN_TEST(test_lock_makes_read_modify_write_atomic_across_threads);
#else
    RUN_TEST(test_lock_disables_interrupts_and_restores_them);
#endif
    (void)UNITY_END();
}

FSW_TEST_MAIN(run)
