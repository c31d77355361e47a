// The 64-bit integer conversions (out of line: on AVR they pull in large
// library routines, which one shared copy keeps small).
#include "fsw_convert.h"

namespace fsw {

static const int64_t kI64Max = 0x7FFFFFFFFFFFFFFFLL;
static const int64_t kI64Min = -kI64Max - 1;
static const uint64_t kU64Max = 0xFFFFFFFFFFFFFFFFULL;

// Magnitude -> Real, correctly rounded (to nearest, ties to even).
FSW_NOINLINE static Real real_from_magnitude(uint64_t m) {
#if FSW_REAL_IS_FLOAT
    // Done in 32-bit halves: no 64-bit shifts on 8-bit MCUs, and no reliance
    // on a 64-bit conversion routine that might round twice. Shift the value
    // right until it fits 32 bits, folding every dropped bit into bit 0
    // (sticky): binary32 keeps 24 bits, so rounding that 32-bit value rounds
    // the original exactly; then scale back by 2^s, which is exact (the
    // result is at most 2^64: always finite). Values under 2^32 (T for 49
    // days in ms) are one conversion; the shift is a bit at a time, a short
    // loop rather than fast code for a path that is rarely taken.
    uint32_t hi = static_cast<uint32_t>(m >> 32);
    uint32_t lo = static_cast<uint32_t>(m);
    if (hi == 0) return f32_from_u32(lo);
    uint8_t s = 0;
    uint8_t sticky = 0;
    do {
        sticky = static_cast<uint8_t>(sticky | (lo & 1u));
        lo = (lo >> 1) | (hi << 31);
        hi >>= 1;
        ++s;
    } while (hi != 0);
    lo |= sticky;
    // lo >= 2^31, so its binary32 value is normal: scaling by 2^s is
    // adding s to the exponent field (no multiply routine pulled in).
    const float f = f32_from_u32(lo);
    uint32_t bits;
    memcpy(&bits, &f, sizeof bits);
    bits += static_cast<uint32_t>(s) << 23;
    Real r;
    memcpy(&r, &bits, sizeof r);
    return r;
#else
    return static_cast<Real>(m);  // hardware conversion rounds once, correctly
#endif
}

Real real_from_U64(uint64_t v) { return real_from_magnitude(v); }

Real real_from_I64(int64_t v) {
    if (v >= 0) return real_from_magnitude(static_cast<uint64_t>(v));
    // Negate in unsigned arithmetic: well defined for the most negative value.
    return -real_from_magnitude(static_cast<uint64_t>(0) - static_cast<uint64_t>(v));
}

int64_t I64_from_real(Real r) {
    if (r != r) return 0;
    if (r >= Real(9223372036854775808.0)) return kI64Max;   // 2^63
    if (r <= Real(-9223372036854775808.0)) return kI64Min;  // -2^63
    return static_cast<int64_t>(r);
}

uint64_t U64_from_real(Real r) {
    if (!(r > 0)) return 0;  // NaN, zero, negatives
    if (r >= Real(18446744073709551616.0)) return kU64Max;  // 2^64
    return static_cast<uint64_t>(r);
}

uint64_t round_to_f32_precision(uint64_t m, bool& over) {
    if (m < (static_cast<uint64_t>(1) << 24)) return m;
    uint8_t drop = 0;  // low bits that do not fit in 24 significant bits
    for (uint64_t t = m >> 24; t != 0; t >>= 1) ++drop;
    const uint64_t unit = static_cast<uint64_t>(1) << drop;
    const uint64_t low = m & (unit - 1u);
    const uint64_t half = unit >> 1;
    m -= low;
    if (low > half || (low == half && (m & unit) != 0)) {
        m += unit;
        if (m == 0) over = true;  // rounded up to 2^64
    }
    return m;
}

}  // namespace fsw
