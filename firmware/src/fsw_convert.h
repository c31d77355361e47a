// Conversions between element values and the evaluation type Real (spec
// 4.5): reads (NaN -> 0), saturating assignments, truthiness.
#ifndef FSW_CONVERT_H
#define FSW_CONVERT_H

#include "fsw_f64.h"
#include "fsw_types.h"

namespace fsw {

// ---- truthiness -------------------------------------------------------------

// True when non-zero and not NaN (conditions, and/or/not).
inline bool truthy(Real r) { return r == r && r != 0; }
// Comparisons and logical operators yield 1 or 0.
inline Real real_from_truth(bool b) { return b ? Real(1) : Real(0); }

// ---- integer -> binary32 -------------------------------------------------------
// An integer of up to 32 bits as a float, rounded to nearest (ties to even)
// as the cast does. On AVR one routine in assembly for all of them
// (fsw_element.cpp), which takes a count of 16 bits in about 30 cycles,
// where the float library's conversion (122 B, pulled in by the first
// cast of an integer) works through 32 bits in 50; the runtime's and the
// generated code's conversions all go through these, so the library's is
// never linked. Tested against the cast (tests/firmware/test_convert.cpp).
#if defined(__AVR__)
extern "C" float fsw_f32_from_u16(uint16_t v);
extern "C" float fsw_f32_from_u32(uint32_t v);
extern "C" float fsw_f32_from_i32(int32_t v);
inline float f32_from_u16(uint16_t v) { return fsw_f32_from_u16(v); }
inline float f32_from_u32(uint32_t v) { return fsw_f32_from_u32(v); }
inline float f32_from_i32(int32_t v) { return fsw_f32_from_i32(v); }
#else
inline float f32_from_u16(uint16_t v) { return static_cast<float>(v); }
inline float f32_from_u32(uint32_t v) { return static_cast<float>(v); }
inline float f32_from_i32(int32_t v) { return static_cast<float>(v); }
#endif

// ---- element value -> Real --------------------------------------------------
// Integers round to nearest (ties to even) when R cannot hold them exactly.

#if FSW_REAL_IS_FLOAT
inline Real real_from_I8(int8_t v) { return f32_from_i32(v); }
inline Real real_from_I16(int16_t v) { return f32_from_i32(v); }
inline Real real_from_I32(int32_t v) { return f32_from_i32(v); }
inline Real real_from_U8(uint8_t v) { return f32_from_u16(v); }
inline Real real_from_U16(uint16_t v) { return f32_from_u16(v); }
inline Real real_from_U32(uint32_t v) { return f32_from_u32(v); }
#else
inline Real real_from_I8(int8_t v) { return static_cast<Real>(v); }
inline Real real_from_I16(int16_t v) { return static_cast<Real>(v); }
inline Real real_from_I32(int32_t v) { return static_cast<Real>(v); }
inline Real real_from_U8(uint8_t v) { return static_cast<Real>(v); }
inline Real real_from_U16(uint16_t v) { return static_cast<Real>(v); }
inline Real real_from_U32(uint32_t v) { return static_cast<Real>(v); }
#endif
Real real_from_I64(int64_t v);
Real real_from_U64(uint64_t v);
inline Real real_from_bool(bool v) { return v ? Real(1) : Real(0); }
inline Real real_from_F32(float v) { return v == v ? static_cast<Real>(v) : Real(0); }
// F64 element given as its binary64 bit pattern (every build).
inline Real real_from_F64_bits(uint64_t bits) {
#if FSW_F64_SOFT
    const float f = f32_from_f64_bits(bits);
    return f == f ? f : 0.0f;
#else
    double d;
    memcpy(&d, &bits, sizeof d);
    return d == d ? static_cast<Real>(d) : Real(0);
#endif
}
#if !FSW_F64_SOFT
inline Real real_from_F64(double v) { return v == v ? static_cast<Real>(v) : Real(0); }
#endif

// ---- Real -> element value --------------------------------------------------
// Integers: NaN -> 0, clamp to the type's range (infinities too), truncate
// toward zero. Bounds are compared as powers of two, which R holds exactly.

inline int8_t I8_from_real(Real r) {
    if (r != r) return 0;
    if (r >= Real(128)) return 127;
    if (r <= Real(-128)) return -128;
    return static_cast<int8_t>(r);
}
inline int16_t I16_from_real(Real r) {
    if (r != r) return 0;
    if (r >= Real(32768)) return 32767;
    if (r <= Real(-32768)) return -32767 - 1;
    return static_cast<int16_t>(r);
}
inline int32_t I32_from_real(Real r) {
    if (r != r) return 0;
    if (r >= Real(2147483648.0)) return 2147483647L;
    if (r <= Real(-2147483648.0)) return -2147483647L - 1;
    return static_cast<int32_t>(r);
}
inline uint8_t U8_from_real(Real r) {
    if (!(r > 0)) return 0;  // NaN, zero, negatives
    if (r >= Real(256)) return 255;
    return static_cast<uint8_t>(r);
}
inline uint16_t U16_from_real(Real r) {
    if (!(r > 0)) return 0;
    if (r >= Real(65536)) return 65535u;
    return static_cast<uint16_t>(r);
}
inline uint32_t U32_from_real(Real r) {
    if (!(r > 0)) return 0;
    if (r >= Real(4294967296.0)) return 4294967295UL;
    return static_cast<uint32_t>(r);
}
int64_t I64_from_real(Real r);
uint64_t U64_from_real(Real r);
// bool: NaN or 0 -> false, anything else -> true.
inline bool bool_from_real(Real r) { return truthy(r); }
// F32/F64: NaN -> 0, otherwise IEEE round to nearest (overflow -> +-inf).
inline float F32_from_real(Real r) { return r == r ? static_cast<float>(r) : 0.0f; }
inline uint64_t F64_bits_from_real(Real r) {
#if FSW_F64_SOFT
    return f64_bits_from_f32(r == r ? r : 0.0f);
#else
    const double d = r == r ? static_cast<double>(r) : 0.0;
    uint64_t bits;
    memcpy(&bits, &d, sizeof bits);
    return bits;
#endif
}
#if !FSW_F64_SOFT
inline double F64_from_real(Real r) { return r == r ? static_cast<double>(r) : 0.0; }
#endif

// ---- integers through binary32 without floating point -------------------------
// `m` rounded to 24 significant bits (ties to even): the value a binary32 R
// holds for the integer m. Sets `over` when the result is 2^64, which a
// uint64_t cannot hold. Generated code uses it to evaluate `a + k` on
// unsigned integers exactly as binary32 arithmetic does, with no float code.
FSW_NOINLINE uint64_t round_to_f32_precision(uint64_t m, bool& over);

}  // namespace fsw

#endif  // FSW_CONVERT_H
