// Software binary64 <-> binary32 conversion on bit patterns. Works on two
// 32-bit halves so that an 8-bit MCU needs no 64-bit shifts.
#include "fsw_f64.h"

namespace fsw {

uint32_t f32_bits_from_f64_bits(uint64_t bits) {
    const uint32_t hi = static_cast<uint32_t>(bits >> 32);
    const uint32_t lo = static_cast<uint32_t>(bits);
    const uint32_t sign = hi & 0x80000000u;
    const uint32_t exp64 = (hi >> 20) & 0x7FFu;
    // Top 23 bits of the 52-bit fraction, and the 29 bits below them.
    uint32_t sig = ((hi & 0xFFFFFu) << 3) | (lo >> 29);
    const uint32_t rest = lo & 0x1FFFFFFFu;

    if (exp64 == 0x7FFu) {  // infinity or NaN
        if ((hi & 0xFFFFFu) != 0 || lo != 0) return sign | 0x7FC00000u | sig;
        return sign | 0x7F800000u;
    }
    if (exp64 == 0) return sign;  // zero or binary64 subnormal: below 2^-1022
    const int16_t e = static_cast<int16_t>(static_cast<int16_t>(exp64) - 1023);
    if (e > 127) return sign | 0x7F800000u;

    sig |= 0x800000u;  // implicit leading one, at bit 23
    uint32_t base;      // exponent field minus one; the leading one adds it back
    uint32_t guard;     // first dropped bit
    uint32_t sticky;    // OR of the remaining dropped bits
    if (e >= -126) {    // binary32 normal
        base = static_cast<uint32_t>(e + 126);
        guard = rest >> 28;
        sticky = rest & 0x0FFFFFFFu;
    } else {            // binary32 subnormal: shift right by t more bits
        const uint16_t t = static_cast<uint16_t>(-126 - e);
        if (t > 24) return sign;  // below half the smallest subnormal
        base = 0;
        guard = (sig >> (t - 1)) & 1u;
        sticky = (sig & ((1u << (t - 1)) - 1u)) | rest;
        sig >>= t;
    }
    if (guard != 0 && (sticky != 0 || (sig & 1u) != 0)) ++sig;
    // A carry out of the significand bumps the exponent (up to infinity).
    return sign | ((base << 23) + sig);
}

uint64_t f64_bits_from_f32_bits(uint32_t u) {
    const uint32_t sign = u & 0x80000000u;
    const uint32_t exp32 = (u >> 23) & 0xFFu;
    uint32_t frac = u & 0x7FFFFFu;
    uint32_t exp64;
    if (exp32 == 0xFFu) {
        exp64 = 0x7FFu;
    } else if (exp32 == 0) {
        if (frac == 0) return static_cast<uint64_t>(sign) << 32;
        // Subnormal: normalise so the leading one reaches bit 23.
        exp64 = 1023 - 126;
        while ((frac & 0x800000u) == 0) {
            frac <<= 1;
            --exp64;
        }
        frac &= 0x7FFFFFu;
    } else {
        exp64 = exp32 + (1023 - 127);
    }
    const uint32_t hi = sign | (exp64 << 20) | (frac >> 3);
    const uint32_t lo = frac << 29;
    return (static_cast<uint64_t>(hi) << 32) | lo;
}

float f32_from_f64_bits(uint64_t bits) {
    const uint32_t u = f32_bits_from_f64_bits(bits);
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

uint64_t f64_bits_from_f32(float v) {
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    return f64_bits_from_f32_bits(u);
}

}  // namespace fsw
