// Scenario: software binary64 <-> binary32 conversion on bit patterns (the
// F64 path of AVR builds): fixed vectors at every rounding boundary, round
// trips, and on the host a differential run against the FPU.
#include "test_support.h"

using namespace fsw;

void setUp(void) {}
void tearDown(void) {}

struct Vec { uint64_t f64; uint32_t f32; };

// binary64 pattern -> expected binary32 pattern (round to nearest even).
static const Vec kNarrow[] = {
    {0x3FF0000000000000ULL, 0x3F800000UL},  // 1
    {0xC004000000000000ULL, 0xC0200000UL},  // -2.5
    {0x3FB999999999999AULL, 0x3DCCCCCDUL},  // 0.1
    {0x0000000000000000ULL, 0x00000000UL},  // +0
    {0x8000000000000000ULL, 0x80000000UL},  // -0
    {0x7FF0000000000000ULL, 0x7F800000UL},  // +inf
    {0xFFF0000000000000ULL, 0xFF800000UL},  // -inf
    {0x7FEFFFFFFFFFFFFFULL, 0x7F800000UL},  // DBL_MAX -> inf
    {0x47EFFFFFE0000000ULL, 0x7F7FFFFFUL},  // FLT_MAX, exact
    {0x47EFFFFFEFFFFFFFULL, 0x7F7FFFFFUL},  // just below the overflow tie
    {0x47EFFFFFF0000000ULL, 0x7F800000UL},  // FLT_MAX + half ulp: tie -> even = inf
    {0xC7EFFFFFF0000000ULL, 0xFF800000UL},  // same, negative
    {0x47F0000000000000ULL, 0x7F800000UL},  // 2^128
    {0x3FF0000010000000ULL, 0x3F800000UL},  // 1 + 2^-24: tie -> even (down)
    {0x3FF0000030000000ULL, 0x3F800002UL},  // 1 + 3*2^-24: tie -> even (up)
    {0x3FF0000010000001ULL, 0x3F800001UL},  // just above the tie
    {0x3FF000000FFFFFFFULL, 0x3F800000UL},  // just below the tie
    {0x3FFFFFFFF0000000ULL, 0x40000000UL},  // carry into the exponent
    {0x3810000000000000ULL, 0x00800000UL},  // 2^-126, smallest normal
    {0x380FFFFFE0000000ULL, 0x00800000UL},  // 2^-126 - 2^-150: tie -> even = normal
    {0x380FFFFFC0000000ULL, 0x007FFFFFUL},  // largest subnormal, exact
    {0x36A0000000000000ULL, 0x00000001UL},  // 2^-149, smallest subnormal
    {0x3690000000000000ULL, 0x00000000UL},  // 2^-150: tie -> even = 0
    {0x3690000000000001ULL, 0x00000001UL},  // just above 2^-150
    {0xB690000000000001ULL, 0x80000001UL},  // negative
    {0x36A8000000000000ULL, 0x00000002UL},  // 1.5 * 2^-149: tie -> even = 2
    {0x36A4000000000000ULL, 0x00000001UL},  // 1.25 * 2^-149
    {0x3680000000000000ULL, 0x00000000UL},  // 2^-151
    {0x358DEE7A4AD4B81FULL, 0x00000000UL},  // 1e-50
    {0x0000000000000001ULL, 0x00000000UL},  // binary64 subnormal
    {0x800FFFFFFFFFFFFFULL, 0x80000000UL},  // negative binary64 subnormal
    {0x4197D78400000000ULL, 0x4CBEBC20UL},  // 1e8
};

static void test_narrowing_fixed_vectors(void) {
    for (size_t i = 0; i < sizeof kNarrow / sizeof kNarrow[0]; ++i) {
        TEST_ASSERT_EQUAL_HEX32(kNarrow[i].f32, f32_bits_from_f64_bits(kNarrow[i].f64));
    }
}

static void test_narrowing_nan_stays_nan_with_its_sign(void) {
    const uint64_t nans[] = {0x7FF8000000000000ULL, 0x7FF0000000000001ULL, 0xFFF8000000000000ULL,
                             0x7FF0000020000000ULL, 0x7FFFFFFFFFFFFFFFULL};
    for (size_t i = 0; i < sizeof nans / sizeof nans[0]; ++i) {
        const uint32_t r = f32_bits_from_f64_bits(nans[i]);
        TEST_ASSERT_EQUAL_HEX32(0x7F800000UL, r & 0x7F800000UL);
        TEST_ASSERT_NOT_EQUAL(0, r & 0x007FFFFFUL);
        TEST_ASSERT_EQUAL(nans[i] >> 63, r >> 31);
    }
}

static void test_widening_fixed_vectors(void) {
    TEST_ASSERT_EQUAL_HEX64(0x3FF0000000000000ULL, f64_bits_from_f32_bits(0x3F800000UL));
    TEST_ASSERT_EQUAL_HEX64(0x3FB99999A0000000ULL, f64_bits_from_f32_bits(0x3DCCCCCDUL));
    TEST_ASSERT_EQUAL_HEX64(0x36A0000000000000ULL, f64_bits_from_f32_bits(0x00000001UL));
    TEST_ASSERT_EQUAL_HEX64(0x380FFFFFC0000000ULL, f64_bits_from_f32_bits(0x007FFFFFUL));
    TEST_ASSERT_EQUAL_HEX64(0x3800000000000000ULL, f64_bits_from_f32_bits(0x00400000UL));
    TEST_ASSERT_EQUAL_HEX64(0x47EFFFFFE0000000ULL, f64_bits_from_f32_bits(0x7F7FFFFFUL));
    TEST_ASSERT_EQUAL_HEX64(0x8000000000000000ULL, f64_bits_from_f32_bits(0x80000000UL));
    TEST_ASSERT_EQUAL_HEX64(0xFFF0000000000000ULL, f64_bits_from_f32_bits(0xFF800000UL));
    TEST_ASSERT_EQUAL_HEX64(0x7FF8000000000000ULL, f64_bits_from_f32_bits(0x7FC00000UL));
    TEST_ASSERT_EQUAL_HEX64(0xC004000000000000ULL, f64_bits_from_f32(-2.5f));
    TEST_ASSERT_EQUAL_HEX32(0xC0200000UL, bits_of(f32_from_f64_bits(0xC004000000000000ULL)));
}

// Widening then narrowing gives back every binary32 value (sampled).
static void test_round_trip_through_binary64_is_identity(void) {
#if defined(__AVR__)
    const uint32_t stride = 0x00FFFFF1UL;
#else
    const uint32_t stride = 0x0000FFF1UL;
#endif
    uint32_t u = 0;
    for (;;) {
        const uint32_t back = f32_bits_from_f64_bits(f64_bits_from_f32_bits(u));
        const bool nan = (u & 0x7F800000UL) == 0x7F800000UL && (u & 0x7FFFFFUL) != 0;
        if (nan ? (back & 0x7FC00000UL) != 0x7FC00000UL : back != u) {
            TEST_FAIL_MESSAGE("binary32 -> binary64 -> binary32 changed a value");
        }
        if (u > 0xFFFFFFFFUL - stride) break;
        u += stride;
    }
    // Every subnormal neighbourhood edge too.
    for (uint32_t v = 0; v < 64; ++v) {
        TEST_ASSERT_EQUAL_HEX32(v, f32_bits_from_f64_bits(f64_bits_from_f32_bits(v)));
        TEST_ASSERT_EQUAL_HEX32(0x00800000UL - v, f32_bits_from_f64_bits(f64_bits_from_f32_bits(0x00800000UL - v)));
    }
}

#if !defined(__AVR__)
static uint64_t rng_state = 0x0123456789ABCDEFULL;
static uint64_t rng() {
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}

// The host FPU narrows binary64 to binary32 with the same rounding rule.
static void test_narrowing_matches_the_fpu_on_random_patterns(void) {
    for (long i = 0; i < 2000000L; ++i) {
        uint64_t b = rng();
        if (i & 1) {
            // Concentrate on binary32's exponent range and its edges.
            const uint64_t e = 1023 - 160 + (rng() % 300);
            b = (b & 0x800FFFFFFFFFFFFFULL) | (e << 52);
            if (i & 2) b &= ~0x0FFFFFFFULL;       // many ties and near-ties
            if (i & 4) b |= 0x0FFFFFFFULL;
        }
        const double d = double_of(b);
        const uint32_t expect = bits_of(static_cast<float>(d));
        const uint32_t got = f32_bits_from_f64_bits(b);
        if (d != d) {
            if ((got & 0x7F800000UL) != 0x7F800000UL || (got & 0x7FFFFFUL) == 0) TEST_FAIL_MESSAGE("NaN lost");
        } else if (got != expect) {
            char msg[96];
            snprintf(msg, sizeof msg, "narrowing 0x%016llx: got 0x%08x, FPU 0x%08x",
                     static_cast<unsigned long long>(b), got, expect);
            TEST_FAIL_MESSAGE(msg);
        }
    }
}

static void test_widening_matches_the_fpu_on_random_patterns(void) {
    for (long i = 0; i < 1000000L; ++i) {
        const uint32_t u = static_cast<uint32_t>(rng());
        const float f = float_of(u);
        if (f != f) continue;
        TEST_ASSERT_EQUAL_HEX64(bits_of(static_cast<double>(f)), f64_bits_from_f32_bits(u));
    }
}
#endif

static void run(void) {
    UNITY_BEGIN();
    RUN_TEST(test_narrowing_fixed_vectors);
    RUN_TEST(test_narrowing_nan_stays_nan_with_its_sign);
    RUN_TEST(test_widening_fixed_vectors);
    RUN_TEST(test_round_trip_through_binary64_is_identity);
#if !defined(__AVR__)
    RUN_TEST(test_narrowing_matches_the_fpu_on_random_patterns);
    RUN_TEST(test_widening_matches_the_fpu_on_random_patterns);
#endif
    (void)UNITY_END();
}

FSW_TEST_MAIN(run)
