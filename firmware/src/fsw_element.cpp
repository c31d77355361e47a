// Run-time typed element access, for table-driven code (I/O channels,
// ground writes); an unknown type reads as 0 and is never written.
#include "fsw_element.h"

namespace fsw {

#if defined(__AVR__)
static_assert(sizeof(Real) == sizeof(uint32_t), "AVR evaluates in binary32");

// A binary32 pattern is a NaN when its exponent is all ones and its
// fraction is not zero: the same test as `v == v` fails on, on the bits,
// here `(u & 0x7FFFFFFF) > 0x7F800000` a byte at a time in a few lines of
// assembly, which return the pattern, or +0 for a NaN. The compiler's
// version of the test took a copy of the pattern in two registers it had to
// save: these two functions run about 18 times a cycle on the rocket, 34
// and 31 cycles a call before, 20 and 18 now.
static inline __attribute__((always_inline)) uint32_t f32_bits_not_nan(uint32_t u) {
    uint8_t t;
    __asm__(
        "mov  %[t], %D[u]\n\t"
        "andi %[t], 0x7F\n\t"
        "cpi  %[t], 0x7F\n\t"   // the exponent's seven high bits
        "brne 2f\n\t"
        "cpi  %C[u], 0x80\n\t"  // its low bit, then the fraction's seven high bits
        "brlo 2f\n\t"
        "brne 1f\n\t"
        "mov  %[t], %B[u]\n\t"  // an infinity, unless the fraction's low bytes are not zero
        "or   %[t], %A[u]\n\t"
        "breq 2f\n\t"
        "1:\n\t"
        "clr  %A[u]\n\t"
        "clr  %B[u]\n\t"
        "movw %C[u], %A[u]\n\t"
        "2:\n\t"
        : [u] "+d"(u), [t] "=&d"(t));
    return u;
}

Real read_F32(const uint8_t* p) {
    const uint32_t u = f32_bits_not_nan(load<uint32_t>(p));  // NaN reads as +0 (real_from_F32)
    Real r;
    memcpy(&r, &u, sizeof r);
    return r;
}

void write_F32(uint8_t* p, Real r) {
    uint32_t u;
    memcpy(&u, &r, sizeof u);
    store<uint32_t>(p, f32_bits_not_nan(u));  // NaN is stored as +0 (F32_from_real)
}
#endif

Real read_elem(const uint8_t* p, uint8_t type) {
    switch (type) {
        case kI8: return read_I8(p);
        case kI16: return read_I16(p);
        case kI32: return read_I32(p);
        case kI64: return read_I64(p);
        case kU8: return read_U8(p);
        case kU16: return read_U16(p);
        case kU32: return read_U32(p);
        case kU64: return read_U64(p);
        case kF32: return read_F32(p);
        case kF64: return read_F64(p);
        case kBool: return read_bool(p);
        default: return 0;
    }
}

void write_elem(uint8_t* p, uint8_t type, Real r) {
    switch (type) {
        case kI8: write_I8(p, r); break;
        case kI16: write_I16(p, r); break;
        case kI32: write_I32(p, r); break;
        case kI64: write_I64(p, r); break;
        case kU8: write_U8(p, r); break;
        case kU16: write_U16(p, r); break;
        case kU32: write_U32(p, r); break;
        case kU64: write_U64(p, r); break;
        case kF32: write_F32(p, r); break;
        case kF64: write_F64(p, r); break;
        case kBool: write_bool(p, r); break;
        default: break;
    }
}

}  // namespace fsw
