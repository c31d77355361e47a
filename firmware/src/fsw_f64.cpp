// Software binary64 <-> binary32 conversion on bit patterns. Works on two
// 32-bit halves so that an 8-bit MCU needs no 64-bit shifts.
#include "fsw_f64.h"

namespace fsw {

// Works on the pattern's little-endian bytes: avr-gcc turns 64-bit shifts
// into loops of single-bit shifts, while byte picks are register moves.
// b[7] holds the sign and the exponent's top 7 bits, b[6] its low 4 bits and
// the fraction's top 4; the 52-bit fraction runs down to b[0].
uint32_t f32_bits_from_f64_bytes(const uint8_t* b) {
    const uint32_t sign = static_cast<uint32_t>(b[7] & 0x80u) << 24;
    const uint16_t exp64 = static_cast<uint16_t>((static_cast<uint16_t>(b[7] & 0x7Fu) << 4) | (b[6] >> 4));
    // Top 23 fraction bits: 4 of b[6], b[5], b[4] and the top 3 of b[3].
    uint32_t sig = static_cast<uint32_t>(b[6] & 0x0Fu) << 16 | static_cast<uint32_t>(b[5]) << 8 | b[4];
    sig = (sig << 3) | static_cast<uint8_t>(b[3] >> 5);
    const uint8_t low_bits = static_cast<uint8_t>((b[3] & 0x1Fu) | b[2] | b[1] | b[0]);  // 0 iff the 29 dropped bits are
    if (exp64 == 0x7FFu) {  // infinity or NaN
        if (sig != 0 || low_bits != 0) return sign | 0x7FC00000u | sig;
        return sign | 0x7F800000u;
    }
    if (exp64 == 0) return sign;  // zero or binary64 subnormal: below 2^-1022
    const int16_t e = static_cast<int16_t>(static_cast<int16_t>(exp64) - 1023);
    if (e > 127) return sign | 0x7F800000u;
    sig |= 0x800000u;  // implicit leading one, at bit 23
    uint32_t base;      // exponent field minus one; the leading one adds it back
    uint8_t guard;      // first dropped bit
    bool sticky;        // any of the remaining dropped bits
    if (e >= -126) {    // binary32 normal
        base = static_cast<uint32_t>(e + 126);
        guard = static_cast<uint8_t>((b[3] >> 4) & 1u);
        sticky = ((b[3] & 0x0Fu) | b[2] | b[1] | b[0]) != 0;
    } else {            // binary32 subnormal: shift right by t more bits
        const uint16_t t = static_cast<uint16_t>(-126 - e);
        if (t > 24) return sign;  // below half the smallest subnormal
        base = 0;
        guard = static_cast<uint8_t>((sig >> (t - 1)) & 1u);
        sticky = (sig & ((1u << (t - 1)) - 1u)) != 0 || low_bits != 0;
        sig >>= t;
    }
    if (guard != 0 && (sticky || (sig & 1u) != 0)) ++sig;
    // A carry out of the significand bumps the exponent (up to infinity).
    return sign | ((base << 23) + sig);
}

uint32_t f32_bits_from_f64_bits(uint64_t bits) {
    uint8_t b[8];
    memcpy(b, &bits, sizeof b);
    return f32_bits_from_f64_bytes(b);
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
