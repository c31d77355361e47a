// Scenario: element <-> Real conversions (spec 4.5) at their boundaries:
// saturation, truncation toward zero, NaN, +-inf, U64/I64 bounds, rounding.
#include <stdio.h>

#include "test_support.h"

using namespace fsw;

void setUp(void) {}
void tearDown(void) {}

static const Real kInf = static_cast<Real>(__builtin_inf());
static Real nan_real() {
    volatile Real z = 0;
    return z / z;
}

static void test_reads_of_integers_are_exact_where_R_holds_them(void) {
    ASSERT_REAL_SAME(Real(255), real_from_U8(255));
    ASSERT_REAL_SAME(Real(-128), real_from_I8(-128));
    ASSERT_REAL_SAME(Real(65535), real_from_U16(65535));
    ASSERT_REAL_SAME(Real(-32768), real_from_I16(-32768));
    ASSERT_REAL_SAME(Real(16777216), real_from_U32(16777216UL));
    ASSERT_REAL_SAME(Real(-16777216), real_from_I32(-16777216L));
    ASSERT_REAL_SAME(Real(1), real_from_bool(true));
    ASSERT_REAL_SAME(Real(0), real_from_bool(false));
}

static void test_reads_of_64_bit_integers_round_once_to_nearest_even(void) {
    // 2^64 - 1 and 2^63 - 1 round up to powers of two in either R.
    ASSERT_REAL_SAME(Real(18446744073709551616.0), real_from_U64(0xFFFFFFFFFFFFFFFFULL));
    ASSERT_REAL_SAME(Real(9223372036854775808.0), real_from_I64(0x7FFFFFFFFFFFFFFFLL));
    ASSERT_REAL_SAME(Real(-9223372036854775808.0), real_from_I64(-0x7FFFFFFFFFFFFFFFLL - 1));
    ASSERT_REAL_SAME(Real(0), real_from_U64(0));
    ASSERT_REAL_SAME(Real(1000), real_from_U64(1000));
    ASSERT_REAL_SAME(Real(-1000), real_from_I64(-1000));
#if FSW_REAL_IS_FLOAT
    // 2^24 + 1 is a tie: to even. 2^24 + 3: up.
    ASSERT_REAL_SAME(16777216.0f, real_from_U64(16777217ULL));
    ASSERT_REAL_SAME(16777220.0f, real_from_U64(16777219ULL));
    ASSERT_REAL_SAME(16777216.0f, real_from_U32(16777217UL));
    // 2^56 + 2^32 + 1: just above half an ulp (2^33), so up. Rounding
    // through binary64 first would give a tie and round down to 2^56.
    ASSERT_REAL_SAME(72057602627862528.0f, real_from_U64(0x0100000100000001ULL));
    ASSERT_REAL_SAME(-72057602627862528.0f, real_from_I64(-0x0100000100000001LL));
    // 2^56 + 2^32 exactly: a tie, to even (2^56).
    ASSERT_REAL_SAME(72057594037927936.0f, real_from_U64(0x0100000100000000ULL));
    // A value whose rounding carries into the next power of two.
    ASSERT_REAL_SAME(4294967296.0f, real_from_U64(0xFFFFFFFFULL + 0ULL));
    ASSERT_REAL_SAME(1099511627776.0f, real_from_U64(0xFFFFFF8000ULL));
    ASSERT_REAL_SAME(1099511562240.0f, real_from_U64(0xFFFFFF7FFFULL));
#else
    // 2^53 + 1 is a tie: to even. 2^53 + 3: up.
    ASSERT_REAL_SAME(9007199254740992.0, real_from_U64(9007199254740993ULL));
    ASSERT_REAL_SAME(9007199254740996.0, real_from_U64(9007199254740995ULL));
    ASSERT_REAL_SAME(-9007199254740996.0, real_from_I64(-9007199254740995LL));
#endif
}

// Integers of up to 32 bits as floats (fsw_convert.h f32_from_*: on AVR one
// routine in assembly, which the runtime's and the generated code's
// conversions all use) give the cast's bits: every 16-bit value, and 32-bit
// values around each power of two (the rounding's ties, the carries into
// the next power), both signs, and a pseudo-random run across the range.
static void check_u32(uint32_t v) {
    volatile uint32_t cast = v;  // no constant folding: the compiler's conversion, at run time
    volatile int32_t scast = static_cast<int32_t>(v);
    if (bits_of(f32_from_u32(v)) != bits_of(static_cast<float>(cast))) {
        TEST_ASSERT_EQUAL_HEX32_MESSAGE(bits_of(static_cast<float>(cast)), bits_of(f32_from_u32(v)),
                                        "f32_from_u32");
    }
    if (bits_of(f32_from_i32(static_cast<int32_t>(v))) != bits_of(static_cast<float>(scast))) {
        TEST_ASSERT_EQUAL_HEX32_MESSAGE(bits_of(static_cast<float>(scast)),
                                        bits_of(f32_from_i32(static_cast<int32_t>(v))), "f32_from_i32");
    }
}

static void test_integers_convert_to_float_as_the_cast_does(void) {
    for (uint32_t n = 0; n <= 0xFFFFu; ++n) {
        volatile uint16_t cast = static_cast<uint16_t>(n);
        if (bits_of(f32_from_u16(static_cast<uint16_t>(n))) != bits_of(static_cast<float>(cast))) {
            TEST_ASSERT_EQUAL_UINT32(n, 0x10000UL);  // reports the first value that differs
        }
        check_u32(n);
    }
    for (uint8_t k = 16; k < 32; ++k) {
        const uint32_t p = 1UL << k;
        for (uint32_t d = 0; d <= 300; ++d) {
            check_u32(p + d);
            check_u32(p - d);
            check_u32(p | (p >> 1) | d);  // 0b11...: rounds up into the next power
            check_u32(~d);
        }
        for (uint8_t j = 0; j < k; ++j) {  // a half of the last place, with and without bits below it
            check_u32(p | (1UL << j));
            check_u32(p | (3UL << j));
            check_u32(p | (1UL << j) | 1u);
        }
    }
    uint32_t x = 0x12345678UL;
    for (uint16_t i = 0; i < 20000; ++i) {
        x = x * 1664525UL + 1013904223UL;
        check_u32(x);
        check_u32(x >> (x & 31u));
    }
    check_u32(0x80000000UL);  // the most negative int32_t: -2^31 exactly
    check_u32(0xFFFFFFFFUL);
}

// F32 elements by pointer (out of line on AVR, with the NaN test on the
// bits): the same as the value forms for every class of binary32 pattern.
static void test_f32_element_access_matches_the_value_forms(void) {
    static const uint32_t kPatterns[] = {
        0x00000000UL, 0x80000000UL, 0x3FC00000UL, 0xBF800000UL,  // +-0, 1.5, -1
        0x00000001UL, 0x807FFFFFUL, 0x00800000UL,                // subnormals, smallest normal
        0x7F7FFFFFUL, 0xFF7FFFFFUL, 0x7F800000UL, 0xFF800000UL,  // +-max, +-inf
        0x7F800001UL, 0x7FC00000UL, 0x7FFFFFFFUL,                // NaNs: signalling, quiet, all ones
        0xFF800001UL, 0xFFC00000UL, 0xFFFFFFFFUL,                // negative NaNs
    };
    for (size_t i = 0; i < sizeof kPatterns / sizeof kPatterns[0]; ++i) {
        uint8_t elem[4];
        memcpy(elem, &kPatterns[i], 4);
        float v;
        memcpy(&v, &kPatterns[i], 4);
        const bool nan = (kPatterns[i] & 0x7FFFFFFFUL) > 0x7F800000UL;
        ASSERT_REAL_SAME(real_from_F32(v), read_F32(elem));
        ASSERT_REAL_SAME(nan ? Real(0) : static_cast<Real>(v), read_F32(elem));
        uint8_t out[4] = {0xAA, 0xAA, 0xAA, 0xAA};
        write_F32(out, static_cast<Real>(v));
        const uint32_t want = nan ? 0UL : kPatterns[i];
        TEST_ASSERT_EQUAL_HEX32(want, load<uint32_t>(out));
        // write_F32_read: the same store, and what read_F32 then reads there
        uint8_t kept[4] = {0x55, 0x55, 0x55, 0x55};
        const Real got = write_F32_read(kept, static_cast<Real>(v));
        TEST_ASSERT_EQUAL_HEX32(want, load<uint32_t>(kept));
        ASSERT_REAL_SAME(read_F32(kept), got);
    }
}

// The threshold tests of a held value (generated code's f32_key_gt and
// f32_key_ge, autocode/emit/expr.py) give what the key of its bytes gives,
// for every class of value read_F32 returns and thresholds on both sides
// of each one's key and at the key's ends.
static void test_a_held_values_threshold_tests_are_its_keys(void) {
    static const uint32_t kValues[] = {
        0x00000000UL, 0x80000000UL, 0x3FC00000UL, 0xBF800000UL, 0x00000001UL, 0x807FFFFFUL, 0x00800000UL,
        0x7F7FFFFFUL, 0xFF7FFFFFUL, 0x7F800000UL, 0xFF800000UL, 0x47C5E680UL, 0xC3480000UL, 0x3CB80000UL,
    };
    for (size_t i = 0; i < sizeof kValues / sizeof kValues[0]; ++i) {
        uint8_t elem[4];
        memcpy(elem, &kValues[i], 4);
        const float v = static_cast<float>(read_F32(elem));
        const uint32_t key = f32_read_key(elem);
        const uint32_t ks[] = {0UL, 1UL, 0x7FFFFFFFUL, 0x80000000UL, 0x80000001UL, 0xFFFFFFFEUL, 0xFFFFFFFFUL,
                               key - 1u, key, key + 1u, ~key, ~key + 1u};
        for (size_t j = 0; j < sizeof ks / sizeof ks[0]; ++j) {
            TEST_ASSERT_EQUAL(key > ks[j], f32_key_gt(v, ks[j]));
            TEST_ASSERT_EQUAL(key >= ks[j], f32_key_ge(v, ks[j]));
        }
    }
}

static void test_reads_of_floats_turn_nan_into_zero(void) {
    ASSERT_REAL_SAME(Real(0), real_from_F32(static_cast<float>(nan_real())));
    ASSERT_REAL_SAME(Real(1.5), real_from_F32(1.5f));
    ASSERT_REAL_SAME(kInf, real_from_F32(static_cast<float>(kInf)));
    ASSERT_REAL_SAME(-kInf, real_from_F32(static_cast<float>(-kInf)));
    ASSERT_REAL_SAME(Real(0), real_from_F64_bits(0x7FF8000000000000ULL));
    ASSERT_REAL_SAME(Real(0), real_from_F64_bits(0xFFF0000000000001ULL));
    ASSERT_REAL_SAME(Real(-2.5), real_from_F64_bits(0xC004000000000000ULL));
    ASSERT_REAL_SAME(kInf, real_from_F64_bits(0x7FF0000000000000ULL));
#if FSW_REAL_IS_FLOAT
    ASSERT_REAL_SAME(kInf, real_from_F64_bits(0x47F0000000000000ULL));  // 2^128
    ASSERT_REAL_SAME(0.1f, real_from_F64_bits(0x3FB999999999999AULL));
#else
    ASSERT_REAL_SAME(0.1, real_from_F64_bits(0x3FB999999999999AULL));
#endif
}

static void test_assign_u8_saturates_and_truncates(void) {
    TEST_ASSERT_EQUAL_UINT8(255, U8_from_real(300));
    TEST_ASSERT_EQUAL_UINT8(255, U8_from_real(256));
    TEST_ASSERT_EQUAL_UINT8(255, U8_from_real(Real(255.99)));
    TEST_ASSERT_EQUAL_UINT8(255, U8_from_real(255));
    TEST_ASSERT_EQUAL_UINT8(254, U8_from_real(Real(254.7)));
    TEST_ASSERT_EQUAL_UINT8(2, U8_from_real(Real(2.9)));
    TEST_ASSERT_EQUAL_UINT8(0, U8_from_real(Real(-0.5)));
    TEST_ASSERT_EQUAL_UINT8(0, U8_from_real(-1));
    TEST_ASSERT_EQUAL_UINT8(0, U8_from_real(nan_real()));
    TEST_ASSERT_EQUAL_UINT8(255, U8_from_real(kInf));
    TEST_ASSERT_EQUAL_UINT8(0, U8_from_real(-kInf));
}

static void test_assign_signed_small_types(void) {
    TEST_ASSERT_EQUAL_INT8(-2, I8_from_real(Real(-2.9)));
    TEST_ASSERT_EQUAL_INT8(2, I8_from_real(Real(2.9)));
    TEST_ASSERT_EQUAL_INT8(127, I8_from_real(Real(127.5)));
    TEST_ASSERT_EQUAL_INT8(127, I8_from_real(128));
    TEST_ASSERT_EQUAL_INT8(-128, I8_from_real(Real(-128.9)));
    TEST_ASSERT_EQUAL_INT8(-128, I8_from_real(-kInf));
    TEST_ASSERT_EQUAL_INT8(0, I8_from_real(nan_real()));
    TEST_ASSERT_EQUAL_INT16(32767, I16_from_real(40000));
    TEST_ASSERT_EQUAL_INT16(-32768, I16_from_real(-40000));
    TEST_ASSERT_EQUAL_INT16(-32767, I16_from_real(Real(-32767.9)));
    TEST_ASSERT_EQUAL_UINT16(65535, U16_from_real(65536));
    TEST_ASSERT_EQUAL_UINT16(65535, U16_from_real(kInf));
    TEST_ASSERT_EQUAL_UINT16(1, U16_from_real(Real(1.999)));
}

static void test_assign_32_bit_bounds(void) {
    TEST_ASSERT_EQUAL_INT32(2147483647L, I32_from_real(Real(2147483648.0)));
    TEST_ASSERT_EQUAL_INT32(-2147483647L - 1, I32_from_real(Real(-2147483648.0)));
    TEST_ASSERT_EQUAL_INT32(-2147483647L - 1, I32_from_real(-kInf));
    TEST_ASSERT_EQUAL_INT32(0, I32_from_real(nan_real()));
    TEST_ASSERT_EQUAL_UINT32(4294967295UL, U32_from_real(Real(4294967296.0)));
    TEST_ASSERT_EQUAL_UINT32(4294967295UL, U32_from_real(kInf));
    TEST_ASSERT_EQUAL_UINT32(0, U32_from_real(-kInf));
#if FSW_REAL_IS_FLOAT
    // Largest binary32 values below the bounds survive unchanged.
    TEST_ASSERT_EQUAL_UINT32(4294967040UL, U32_from_real(4294967040.0f));
    TEST_ASSERT_EQUAL_INT32(2147483520L, I32_from_real(2147483520.0f));
    TEST_ASSERT_EQUAL_INT32(-2147483520L, I32_from_real(-2147483520.0f));
#else
    TEST_ASSERT_EQUAL_UINT32(4294967295UL, U32_from_real(4294967295.9));
    TEST_ASSERT_EQUAL_INT32(2147483647L, I32_from_real(2147483647.5));
    TEST_ASSERT_EQUAL_INT32(-2147483647L - 1, I32_from_real(-2147483648.9));
#endif
}

static void test_assign_64_bit_bounds(void) {
    const int64_t i64max = 0x7FFFFFFFFFFFFFFFLL;
    const int64_t i64min = -i64max - 1;
    const uint64_t u64max = 0xFFFFFFFFFFFFFFFFULL;
    TEST_ASSERT_EQUAL_INT64(i64max, I64_from_real(Real(9223372036854775808.0)));
    TEST_ASSERT_EQUAL_INT64(i64min, I64_from_real(Real(-9223372036854775808.0)));
    TEST_ASSERT_EQUAL_INT64(i64max, I64_from_real(kInf));
    TEST_ASSERT_EQUAL_INT64(i64min, I64_from_real(-kInf));
    TEST_ASSERT_EQUAL_INT64(0, I64_from_real(nan_real()));
    TEST_ASSERT_EQUAL_INT64(-2, I64_from_real(Real(-2.9)));
    TEST_ASSERT_EQUAL_UINT64(u64max, U64_from_real(Real(18446744073709551616.0)));
    TEST_ASSERT_EQUAL_UINT64(u64max, U64_from_real(kInf));
    TEST_ASSERT_EQUAL_UINT64(0, U64_from_real(-kInf));
    TEST_ASSERT_EQUAL_UINT64(0, U64_from_real(Real(-1)));
    TEST_ASSERT_EQUAL_UINT64(0, U64_from_real(nan_real()));
    TEST_ASSERT_EQUAL_UINT64(1000000ULL, U64_from_real(Real(1000000.75)));
#if FSW_REAL_IS_FLOAT
    // Largest binary32 values below 2^64 and 2^63.
    TEST_ASSERT_EQUAL_UINT64(18446742974197923840ULL, U64_from_real(18446742974197923840.0f));
    TEST_ASSERT_EQUAL_INT64(9223371487098961920LL, I64_from_real(9223371487098961920.0f));
    TEST_ASSERT_EQUAL_INT64(-9223371487098961920LL, I64_from_real(-9223371487098961920.0f));
#else
    TEST_ASSERT_EQUAL_UINT64(18446744073709549568ULL, U64_from_real(18446744073709549568.0));
    TEST_ASSERT_EQUAL_INT64(9223372036854774784LL, I64_from_real(9223372036854774784.0));
    TEST_ASSERT_EQUAL_INT64(-9223372036854774784LL, I64_from_real(-9223372036854774784.0));
#endif
}

static void test_assign_bool_and_truthiness(void) {
    TEST_ASSERT_FALSE(bool_from_real(nan_real()));
    TEST_ASSERT_FALSE(bool_from_real(0));
    TEST_ASSERT_FALSE(bool_from_real(-Real(0)));
    TEST_ASSERT_TRUE(bool_from_real(Real(1e-30)));
    TEST_ASSERT_TRUE(bool_from_real(-kInf));
    TEST_ASSERT_TRUE(bool_from_real(Real(-0.5)));
    TEST_ASSERT_FALSE(truthy(nan_real()));
    TEST_ASSERT_TRUE(truthy(Real(2)));
    ASSERT_REAL_SAME(Real(1), real_from_truth(true));
    ASSERT_REAL_SAME(Real(0), real_from_truth(false));
}

static void test_assign_floats_nan_to_zero_and_ieee_rounding(void) {
    TEST_ASSERT_EQUAL_HEX32(0, bits_of(F32_from_real(nan_real())));
    TEST_ASSERT_EQUAL_HEX32(0x7F800000UL, bits_of(F32_from_real(kInf)));
    TEST_ASSERT_EQUAL_HEX32(0xFF800000UL, bits_of(F32_from_real(-kInf)));
    TEST_ASSERT_EQUAL_HEX32(0x80000000UL, bits_of(F32_from_real(-Real(0))));
    TEST_ASSERT_EQUAL_HEX64(0, F64_bits_from_real(nan_real()));
    TEST_ASSERT_EQUAL_HEX64(0x7FF0000000000000ULL, F64_bits_from_real(kInf));
    TEST_ASSERT_EQUAL_HEX64(0x3FF8000000000000ULL, F64_bits_from_real(Real(1.5)));
#if FSW_REAL_IS_FLOAT
    TEST_ASSERT_EQUAL_HEX64(0x3FB99999A0000000ULL, F64_bits_from_real(0.1f));  // exact widening
#else
    TEST_ASSERT_EQUAL_HEX32(0x7F800000UL, bits_of(F32_from_real(1e39)));   // overflow -> inf
    TEST_ASSERT_EQUAL_HEX32(0xFF800000UL, bits_of(F32_from_real(-1e39)));
    TEST_ASSERT_EQUAL_HEX32(0x7F7FFFFFUL, bits_of(F32_from_real(3.4028235e38)));
    TEST_ASSERT_EQUAL_HEX32(0x3DCCCCCDUL, bits_of(F32_from_real(0.1)));   // round to nearest
    TEST_ASSERT_EQUAL_HEX64(0x3FB999999999999AULL, F64_bits_from_real(0.1));
#endif
}

static void test_division_by_zero_follows_ieee(void) {
    volatile Real zero = 0;
    volatile Real one = 1;
    ASSERT_REAL_SAME(kInf, one / zero);
    ASSERT_REAL_SAME(-kInf, -one / zero);
    TEST_ASSERT_TRUE(zero / zero != zero / zero);
    TEST_ASSERT_EQUAL_UINT8(255, U8_from_real(one / zero));
}

static void test_element_pointer_access_round_trips_every_type(void) {
    uint8_t buf[9 + 8];
    for (uint8_t t = kI8; t <= kBool; ++t) {
        memset(buf, 0xAA, sizeof buf);
        uint8_t* p = buf + 1;  // deliberately unaligned
        write_elem(p, t, Real(300.7));
        const Real back = read_elem(p, t);
        Real expected;
        switch (t) {
            case kI8: expected = 127; break;
            case kU8: expected = 255; break;
            case kBool: expected = 1; break;
            case kF32: expected = static_cast<Real>(300.7f); break;
            case kF64: expected = Real(300.7); break;
            default: expected = 300; break;
        }
        ASSERT_REAL_SAME(expected, back);
        TEST_ASSERT_EQUAL_HEX8(0xAA, buf[0]);                    // no write before
        TEST_ASSERT_EQUAL_HEX8(0xAA, buf[1 + elem_size(t)]);     // nor after
    }
    ASSERT_REAL_SAME(Real(0), read_elem(buf, 99));
}

// The run-time access (read_elem/write_elem: I/O tables, the bytecode VM)
// and the typed one (generated code) give the same bytes and values for
// every integer type: at every power of two around each type's limits, on
// both sides of them, at +-0, +-inf and NaN, and over random patterns
// (fewer on an AVR, where the suite runs simulated).
static void check_write(Real r) {
    for (uint8_t t = kI8; t <= kU64; ++t) {
        uint8_t a[10], b[10];
        memset(a, 0x5A, sizeof a);
        memset(b, 0x5A, sizeof b);
        write_elem(a + 1, t, r);
        write_elem_typed(b + 1, t, r);
        if (memcmp(a, b, sizeof a) != 0) {
            char msg[80];
            snprintf(msg, sizeof msg, "write_elem type %u of %.9g differs from the typed write", static_cast<unsigned>(t),
                     static_cast<double>(r));
            TEST_FAIL_MESSAGE(msg);
        }
    }
}
static void check_read(const uint8_t* bytes) {
    for (uint8_t t = kI8; t <= kU64; ++t) {
        if (!fsw_test_same(read_elem_typed(bytes, t), read_elem(bytes, t))) {
            char msg[80];
            snprintf(msg, sizeof msg, "read_elem type %u of %02x..%02x differs from the typed read", static_cast<unsigned>(t),
                     static_cast<unsigned>(bytes[0]),
                     static_cast<unsigned>(bytes[elem_size(t) - 1u]));
            TEST_FAIL_MESSAGE(msg);
        }
    }
}

static void test_run_time_element_access_matches_the_typed_conversions(void) {
    check_write(0);
    check_write(-static_cast<Real>(0));
    check_write(kInf);
    check_write(-kInf);
    check_write(nan_real());
    Real p = 1;
    for (uint8_t k = 0; k <= 66; ++k, p = p * 2) {  // 2^k, and just above and below it, either sign
        const Real around[] = {p, p * Real(1.5), p * Real(0.75), p * Real(0.99999994), p * Real(1.0000001)};
        for (size_t i = 0; i < sizeof around / sizeof around[0]; ++i) {
            check_write(around[i]);
            check_write(-around[i]);
            check_write(around[i] - 1);
            check_write(1 - around[i]);
        }
    }
    uint8_t edge[8];
    for (uint8_t fill = 0; fill < 2; ++fill)
        for (uint8_t top = 0; top < 8; ++top) {  // 0x00../0xFF.. with one byte 0x7F, 0x80 or 0x81
            for (uint8_t v = 0x7F; v != 0x82; ++v) {
                memset(edge, fill ? 0xFF : 0x00, sizeof edge);
                edge[top] = v;
                check_read(edge);
            }
        }
    uint32_t x = 0x9E3779B9UL;
#if defined(__AVR__)
    const uint16_t n = 300;
#else
    const uint16_t n = 60000;
#endif
    for (uint16_t i = 0; i < n; ++i) {
        uint8_t bytes[8];
        for (uint8_t k = 0; k < 8; ++k) {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            bytes[k] = static_cast<uint8_t>(x >> 11);
        }
        check_read(bytes);
        Real r;
        memcpy(&r, bytes + (sizeof(Real) == 4 ? 4 : 0), sizeof r);  // any pattern: NaNs, subnormals, huge
        check_write(r);
        check_write(static_cast<Real>(static_cast<int32_t>(x)) * Real(1e-3) * static_cast<Real>(1u << (i % 32u)));
    }
}

static void test_typed_writes_saturate_through_pointers(void) {
    uint8_t b[8];
    write_U8(b, 256);
    TEST_ASSERT_EQUAL_HEX8(0xFF, b[0]);
    write_I16(b + 1, -40000);
    TEST_ASSERT_EQUAL_HEX8(0x00, b[1]);
    TEST_ASSERT_EQUAL_HEX8(0x80, b[2]);
    write_bool(b, nan_real());
    TEST_ASSERT_EQUAL_HEX8(0, b[0]);
    b[0] = 7;  // any non-zero byte reads as true
    ASSERT_REAL_SAME(Real(1), read_bool(b));
}

#if !defined(__AVR__)
// Host only: random 64-bit integers against conversion through x87 long
// double, which holds every 64-bit integer exactly (one rounding only).
static void test_64_bit_reads_match_single_rounding_reference(void) {
    uint64_t x = 0x9E3779B97F4A7C15ULL;
    for (int i = 0; i < 200000; ++i) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        const uint64_t u = x >> (i % 60);
        const int64_t s = static_cast<int64_t>(x);
        if (!fsw_test_same(static_cast<Real>(static_cast<long double>(u)), real_from_U64(u)) ||
            !fsw_test_same(static_cast<Real>(static_cast<long double>(s)), real_from_I64(s))) {
            TEST_FAIL_MESSAGE("64-bit integer read rounded differently from the reference");
        }
    }
}
#endif

// Integers rounded to binary32's 24 significant bits without floating point
// (generated code's exact slow path of `a + k`). Expected values computed
// independently, with exact rational arithmetic.
static void test_round_to_f32_precision_matches_binary32(void) {
    struct Case {
        uint64_t in;
        uint64_t out;
        bool over;
    };
    static const Case cases[] = {
        {0ULL, 0ULL, false},
        {1ULL, 1ULL, false},
        {16777215ULL, 16777215ULL, false},
        {16777216ULL, 16777216ULL, false},
        {16777217ULL, 16777216ULL, false},
        {16777218ULL, 16777218ULL, false},
        {16777219ULL, 16777220ULL, false},
        {33554433ULL, 33554432ULL, false},
        {33554434ULL, 33554432ULL, false},
        {33554438ULL, 33554440ULL, false},
        {4294967295ULL, 4294967296ULL, false},
        {1099511693312ULL, 1099511627776ULL, false},
        {1099511693313ULL, 1099511758848ULL, false},
        {1099511824384ULL, 1099511889920ULL, false},
        {9223372036854775808ULL, 9223372036854775808ULL, false},
        {9223372586610589696ULL, 9223372036854775808ULL, false},
        {9223372586610589697ULL, 9223373136366403584ULL, false},
        {18446742974197923840ULL, 18446742974197923840ULL, false},
        {18446743523953737727ULL, 18446742974197923840ULL, false},
        {18446743523953737728ULL, 0ULL, true},
        {18446744073709551615ULL, 0ULL, true},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        bool over = false;
        const uint64_t r = round_to_f32_precision(cases[i].in, over);
        TEST_ASSERT_TRUE(over == cases[i].over);
        if (!over) TEST_ASSERT_TRUE(r == cases[i].out);
    }
}

#if !defined(__AVR__)
static void test_round_to_f32_precision_matches_the_host_conversion(void) {
    uint64_t x = 0x9E3779B97F4A7C15ULL;
    for (int i = 0; i < 20000; ++i) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        const uint64_t u = x >> (i % 64);
        const float f = static_cast<float>(u);  // correctly rounded on the host
        bool over = false;
        const uint64_t r = round_to_f32_precision(u, over);
        if (f >= 18446744073709551616.0f) {
            TEST_ASSERT_TRUE(over);
        } else {
            TEST_ASSERT_FALSE(over);
            TEST_ASSERT_TRUE(r == static_cast<uint64_t>(f));
        }
    }
}
#endif

// A full window of a power-of-two N multiplies its sum by 1/N (fsw_window.h);
// on binary32 R that is done on the exponent's bits where the product is
// normal (scale_pow2): the same bits as the float routine's multiplication
// for every exponent of x, both signs, zeros, subnormals, infinities, and
// every 1/N up to 1/65536 (products below the normal range are multiplied);
// NaN gives NaN (whose bits nothing reads: an element stores it as +0).
// Here, not in test_window.cpp, whose AVR build has no RAM left for it.
static void test_window_scale_by_a_power_of_two_is_the_product(void) {
    for (uint16_t e = 0; e < 256u; ++e) {
        for (uint8_t sign = 0; sign < 2u; ++sign) {
            for (uint8_t f = 0; f < 5u; ++f) {  // fractions: 0, the lowest bit, the highest, all, some
                const uint32_t fraction = f == 0 ? 0 : f == 1 ? 1 : f == 2 ? 0x400000UL : f == 3 ? 0x7FFFFFUL : 0x2A5F31UL;
                const uint32_t xb = (static_cast<uint32_t>(sign) << 31) | (static_cast<uint32_t>(e) << 23) | fraction;
                float xf;
                memcpy(&xf, &xb, sizeof xf);
                const Real x = static_cast<Real>(xf);  // binary64 R: the same values, one way to write the test
                for (uint8_t k = 0; k <= 16u; ++k) {
                    volatile Real inv = Real(1) / static_cast<Real>(1UL << k);  // volatile: the routine's product
                    const Real want = x * inv;
                    const Real got = scale_pow2(x, inv);
                    if (want != want && got != got) continue;  // NaN: avr-libc's pattern depends on the operands' order
                    if (bits_of(want) != bits_of(got)) {
                        char msg[48];
                        snprintf(msg, sizeof msg, "x %08lx times 2^-%u", static_cast<unsigned long>(xb), k);
                        TEST_ASSERT_EQUAL_HEX64_MESSAGE(bits_of(want), bits_of(got), msg);
                    }
                }
            }
        }
    }
}

static void run(void) {
    UNITY_BEGIN();
    RUN_TEST(test_reads_of_integers_are_exact_where_R_holds_them);
    RUN_TEST(test_integers_convert_to_float_as_the_cast_does);
    RUN_TEST(test_reads_of_64_bit_integers_round_once_to_nearest_even);
    RUN_TEST(test_reads_of_floats_turn_nan_into_zero);
    RUN_TEST(test_f32_element_access_matches_the_value_forms);
    RUN_TEST(test_a_held_values_threshold_tests_are_its_keys);
    RUN_TEST(test_assign_u8_saturates_and_truncates);
    RUN_TEST(test_assign_signed_small_types);
    RUN_TEST(test_assign_32_bit_bounds);
    RUN_TEST(test_assign_64_bit_bounds);
    RUN_TEST(test_assign_bool_and_truthiness);
    RUN_TEST(test_assign_floats_nan_to_zero_and_ieee_rounding);
    RUN_TEST(test_division_by_zero_follows_ieee);
    RUN_TEST(test_element_pointer_access_round_trips_every_type);
    RUN_TEST(test_typed_writes_saturate_through_pointers);
    RUN_TEST(test_run_time_element_access_matches_the_typed_conversions);
    RUN_TEST(test_round_to_f32_precision_matches_binary32);
    RUN_TEST(test_window_scale_by_a_power_of_two_is_the_product);
#if !defined(__AVR__)
    RUN_TEST(test_64_bit_reads_match_single_rounding_reference);
    RUN_TEST(test_round_to_f32_precision_matches_the_host_conversion);
#endif
    (void)UNITY_END();
}

FSW_TEST_MAIN(run)
