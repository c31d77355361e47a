// Software conversion between binary64 bit patterns and binary32, for
// boards whose `double` is 32 bits (F64 elements are still 8 bytes there).
#ifndef FSW_F64_H
#define FSW_F64_H

#include "fsw_types.h"

namespace fsw {

// binary64 bits -> binary32, correctly rounded (round to nearest, ties to
// even): too large -> +-inf, too small -> +-0 or a binary32 subnormal,
// NaN -> a quiet NaN of the same sign.
float f32_from_f64_bits(uint64_t bits);

// binary32 -> binary64 bits, exact (every binary32 value, subnormals
// included, is a binary64 value; NaN keeps its sign and payload).
uint64_t f64_bits_from_f32(float v);

// Same two conversions on raw binary32 bit patterns.
uint32_t f32_bits_from_f64_bits(uint64_t bits);
// The same from the pattern's 8 little-endian bytes (an element in memory).
uint32_t f32_bits_from_f64_bytes(const uint8_t* bytes);
uint64_t f64_bits_from_f32_bits(uint32_t bits);

// ---- order-preserving keys ---------------------------------------------------
// For float patterns a and b that are not NaN, a < b as values iff key(a) <
// key(b) (-0 sorts just below +0). Generated code compares an element with a
// threshold it computed at build time this way, with no float arithmetic.
inline uint64_t f64_key(const uint8_t* p) {
    uint64_t bits;
    memcpy(&bits, p, sizeof bits);
    return (p[7] & 0x80u) != 0 ? ~bits : bits | 0x8000000000000000ULL;
}
inline uint32_t f32_key(const uint8_t* p) {
    uint32_t bits;
    memcpy(&bits, p, sizeof bits);
    return (p[3] & 0x80u) != 0 ? ~bits : bits | 0x80000000UL;
}
// True when the pattern is a NaN (all-ones exponent, non-zero fraction).
inline bool f64_is_nan(const uint8_t* p) {
    if ((p[7] & 0x7Fu) != 0x7Fu || (p[6] & 0xF0u) != 0xF0u) return false;
    return ((p[6] & 0x0Fu) | p[5] | p[4] | p[3] | p[2] | p[1] | p[0]) != 0;
}
inline bool f32_is_nan(const uint8_t* p) {
    if ((p[3] & 0x7Fu) != 0x7Fu || (p[2] & 0x80u) == 0) return false;
    return ((p[2] & 0x7Fu) | p[1] | p[0]) != 0;
}

// The key of the value an element reads as (a NaN reads as +0: the key of
// +0), for threshold tests in generated code: `R(x) op c` for a literal c is
// a test of this key against constants, NaN included. Out of line (one copy
// however many tests a machine has) on AVR, inline elsewhere. The 64-bit
// one stays inline on AVR too: its result is compared in the caller byte
// by byte, and a call would add as many cycles as a step's tests take.
#if defined(__AVR__)
FSW_NOINLINE uint32_t f32_read_key(const uint8_t* p);
#else
inline uint32_t f32_read_key(const uint8_t* p) { return f32_is_nan(p) ? 0x80000000UL : f32_key(p); }
#endif
// The threshold tests of a binary32 value that is not a NaN (one read_F32
// returned): key > k and key >= k, for the key f32_read_key gives of the
// bytes it was read from, as generated code tests a variable it holds in
// registers (autocode/emit/machine.py). On the value's bits as a signed
// integer: a key at or above 0x80000000 is a sign bit of 0 (the bits
// ordered as the values), one below it a sign bit of 1 (the bits ordered
// backwards); k is a constant, so one 32-bit comparison for a threshold
// of 0 or above, where the key itself took a few more instructions.
inline bool f32_key_gt(float v, uint32_t k) {
    int32_t s;
    memcpy(&s, &v, sizeof s);
    if (k >= 0x80000000UL) return s > static_cast<int32_t>(k - 0x80000000UL);
    return s >= 0 || s < static_cast<int32_t>(~k);
}
inline bool f32_key_ge(float v, uint32_t k) { return k == 0 || f32_key_gt(v, k - 1u); }
inline uint64_t f64_read_key(const uint8_t* p) { return f64_is_nan(p) ? 0x8000000000000000ULL : f64_key(p); }

}  // namespace fsw

#endif  // FSW_F64_H
