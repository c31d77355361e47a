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

// The 4 bytes at p, loaded where a result goes (r22..r25: the compiler's
// choice was r24..r27, and two moves after, 4 B of flash and 2 cycles a
// call, of read_F32's 18 a cycle on the rocket).
static inline __attribute__((always_inline)) uint32_t f32_bits_at(const uint8_t* p) {
    register uint32_t b __asm__("r22");
    __asm__("ld   %A[b], Z\n\t"
            "ldd  %B[b], Z+1\n\t"
            "ldd  %C[b], Z+2\n\t"
            "ldd  %D[b], Z+3"
            : [b] "=r"(b)
            : "z"(p), "m"(*reinterpret_cast<const uint8_t(*)[4]>(p)));
    return b;
}

// fsw_f64.h: the key of the value read_F32(p) returns, from its bits (the
// byte-wise NaN test of f32_is_nan, then the loads of f32_key, were 70 B).
uint32_t f32_read_key(const uint8_t* p) {
    register uint32_t u __asm__("r22") = f32_bits_not_nan(f32_bits_at(p));  // NaN reads as +0: the key of +0
    __asm__("sbrc %D[u], 7\n\t"  // (u & 0x80000000) != 0 ? ~u : u | 0x80000000, in place
            "rjmp 1f\n\t"
            "ori  %D[u], 0x80\n\t"
            "rjmp 2f\n\t"
            "1:\n\t"
            "com  %A[u]\n\t"
            "com  %B[u]\n\t"
            "com  %C[u]\n\t"
            "com  %D[u]\n\t"
            "2:"
            : [u] "+d"(u));
    return u;
}

Real read_F32(const uint8_t* p) {
    const uint32_t u = f32_bits_not_nan(f32_bits_at(p));  // NaN reads as +0 (real_from_F32)
    Real r;
    memcpy(&r, &u, sizeof r);
    return r;
}

Real f32_write_back(Real r, uint8_t* p) {
    uint32_t u;
    memcpy(&u, &r, sizeof u);
    u = f32_bits_not_nan(u);  // NaN is stored as +0 (F32_from_real)
    store<uint32_t>(p, u);
    memcpy(&r, &u, sizeof r);
    return r;
}
#endif

#if defined(__AVR__)
// fsw_convert.h: integers as floats. The value is shifted until its leading
// one is bit 23 (a value of up to 24 bits: exact) or down to it (above:
// the bits shifted out rounded to nearest, ties to even), the exponent
// counted from bit 23's (127 + 23), and the float put together: the
// exponent over the leading one's place, the 23 bits after it. None of the
// three changes T (the signed one keeps the sign there across its call)
// and each changes r20 and r21 at most of the registers a call may change.
#if defined(__AVR_HAVE_JMP_CALL__)
#define FSW_FAR_JMP "jmp "
#define FSW_FAR_CALL "call "
#else
#define FSW_FAR_JMP "rjmp "
#define FSW_FAR_CALL "rcall "
#endif

// 16 bits, v in r25:r24 (a byte, a nibble, then at most three bits: the
// analog counts' conversion, 4 a cycle on the rocket).
extern "C" __attribute__((naked, noinline, used, externally_visible)) float fsw_f32_from_u16(uint16_t) {
    __asm__ __volatile__(
        "movw r22, r24\n\t"
        "ldi  r25, 142\n\t"  // bit 15's exponent
        "tst  r23\n\t"
        "brne 1f\n\t"
        "mov  r23, r22\n\t"  // a byte
        "clr  r22\n\t"
        "ldi  r25, 134\n\t"
        "tst  r23\n\t"
        "breq 9f\n\t"  // 0: +0
        "1:\n\t"
        "cpi  r23, 0x10\n\t"
        "brsh 2f\n\t"
        "swap r23\n\t"  // a nibble (the high byte's high one is 0)
        "swap r22\n\t"
        "mov  r21, r22\n\t"
        "andi r21, 0x0F\n\t"
        "or   r23, r21\n\t"
        "eor  r22, r21\n\t"
        "subi r25, 4\n\t"
        "2:\n\t"
        "sbrc r23, 7\n\t"
        "rjmp 3f\n\t"
        "lsl  r22\n\t"  // a bit
        "rol  r23\n\t"
        "dec  r25\n\t"
        "rjmp 2b\n\t"
        "3:\n\t"
        "mov  r24, r23\n\t"  // the leading one to bit 23
        "mov  r23, r22\n\t"
        "clr  r22\n\t"
        "lsl  r24\n\t"  // out, and the exponent's low bit in its place
        "lsr  r25\n\t"
        "ror  r24\n\t"
        "ret\n\t"
        "9:\n\t"
        "clr  r24\n\t"
        "clr  r25\n\t"
        "ret\n\t");
}

// 32 bits, v in r25..r22: below 2^16 the 16-bit conversion's.
extern "C" __attribute__((naked, noinline, used, externally_visible)) float fsw_f32_from_u32(uint32_t) {
    __asm__ __volatile__(
        "tst  r25\n\t"
        "brne 3f\n\t"
        "tst  r24\n\t"
        "brne 1f\n\t"
        "movw r24, r22\n\t"
        FSW_FAR_JMP "fsw_f32_from_u16\n\t"
        "1:\n\t"  // 17 to 24 bits: up, a bit at a time
        "ldi  r25, 150\n\t"
        "2:\n\t"
        "sbrc r24, 7\n\t"
        "rjmp 6f\n\t"
        "lsl  r22\n\t"
        "rol  r23\n\t"
        "rol  r24\n\t"
        "dec  r25\n\t"
        "rjmp 2b\n\t"
        "3:\n\t"  // 25 to 32 bits: down, the bits shifted out (8 at most) in r20
        "mov  r21, r25\n\t"
        "ldi  r25, 150\n\t"
        "clr  r20\n\t"
        "4:\n\t"
        "inc  r25\n\t"
        "lsr  r21\n\t"
        "ror  r24\n\t"
        "ror  r23\n\t"
        "ror  r22\n\t"
        "ror  r20\n\t"
        "tst  r21\n\t"
        "brne 4b\n\t"
        "sbrs r20, 7\n\t"  // below half of the last place: down
        "rjmp 6f\n\t"
        "lsl  r20\n\t"  // above it: up; half: to the even one
        "brne 5f\n\t"
        "sbrs r22, 0\n\t"
        "rjmp 6f\n\t"
        "5:\n\t"
        "subi r22, 0xFF\n\t"  // + 1: a carry out of the fraction goes on into the exponent
        "sbci r23, 0xFF\n\t"
        "sbci r24, 0xFF\n\t"
        "sbci r25, 0xFF\n\t"
        "6:\n\t"
        "lsl  r24\n\t"
        "lsr  r25\n\t"
        "ror  r24\n\t"
        "ret\n\t");
}

// Signed: the magnitude's, with the sign (kept in T) on it; 0 is +0.
extern "C" __attribute__((naked, noinline, used, externally_visible)) float fsw_f32_from_i32(int32_t) {
    __asm__ __volatile__(
        "bst  r25, 7\n\t"
        "brtc 1f\n\t"
        "com  r25\n\t"
        "com  r24\n\t"
        "com  r23\n\t"
        "neg  r22\n\t"
        "sbci r23, 0xFF\n\t"
        "sbci r24, 0xFF\n\t"
        "sbci r25, 0xFF\n\t"
        "1:\n\t"
        FSW_FAR_CALL "fsw_f32_from_u32\n\t"
        "bld  r25, 7\n\t"
        "ret\n\t");
}

// Binary32 addition and subtraction, the compiler's __addsf3 and __subsf3
// ahead of avr-libc's (weak: where a program links avr-libc's file of the
// two anyway, its pair is taken, and nothing else changes). One case is
// worked out here: the operands' signs differ (after the subtraction's
// flip) and their exponents are the same, 24 or above and not all ones.
// The difference is then exact (Sterbenz's lemma: it has no bits below
// the operands' last place, and fewer above it) and normal: the
// significands' difference, signed, shifted up until its leading one is
// bit 23 (a byte, then a bit at a time, the exponent counted down with
// it), or +0 where they are equal, what IEEE 754 rounding to nearest gives
// too. Every other case is avr-libc's __addsf3: its __addsf3x, rounded by
// its __fp_round (tests/firmware/test_float.cpp: the same bits). On the
// rocket nav's two subtractions of pressures near each other (a reading
// less the last one taken, the pad's pressure less the average) and the
// accelerometer's offset (a count's volts less 20 g near 1 g) take this
// path, about 3 a cycle: avr-libc unpacked both operands, shifted their
// cancelled bits out one at a time (8 cycles each) and rounded, where
// nothing is left to round.
extern "C" __attribute__((naked, noinline, used, externally_visible)) void __subsf3() {
    __asm__ __volatile__(
        ".weak __subsf3\n\t"
        ".weak __addsf3\n\t"
        "subi r21, 0x80\n\t"  // a - b = a + (-b)
        ".global __addsf3\n"
        "__addsf3:\n\t"
        "mov  r26, r25\n\t"  // the signs differ, the exponents' high seven bits are the same ...
        "eor  r26, r21\n\t"
        "cpi  r26, 0x80\n\t"
        "brne 8f\n\t"
        "mov  r26, r24\n\t"  // ... and their low bits
        "eor  r26, r20\n\t"
        "brmi 8f\n\t"
        "mov  r26, r24\n\t"  // E, the exponent: 24 or above (a normal difference: 2^-126 at least) ...
        "lsl  r26\n\t"
        "mov  r26, r25\n\t"
        "rol  r26\n\t"
        "cpi  r26, 24\n\t"
        "brlo 8f\n\t"
        "cpi  r26, 0xFF\n\t"  // ... and not all ones (an infinity or a NaN)
        "breq 8f\n\t"
        "sub  r22, r18\n\t"  // the significands' difference (the leading ones cancel), 24-bit two's complement
        "sbc  r23, r19\n\t"
        "sbc  r24, r20\n\t"
        "breq 7f\n\t"  // (sbc keeps Z only while every byte was 0) equal: +0
        "brpl 1f\n\t"
        "com  r24\n\t"  // b's magnitude the larger: the magnitude, and b's sign
        "com  r23\n\t"
        "neg  r22\n\t"
        "sbci r23, 0xFF\n\t"
        "sbci r24, 0xFF\n\t"
        "subi r25, 0x80\n\t"
        "1:\n\t"  // up a byte while the top one is 0
        "tst  r24\n\t"
        "brne 3f\n\t"
        "mov  r24, r23\n\t"
        "mov  r23, r22\n\t"
        "clr  r22\n\t"
        "subi r26, 8\n\t"
        "rjmp 1b\n\t"
        "3:\n\t"  // then a bit at a time until the leading one is bit 23
        "brmi 5f\n\t"
        "4:\n\t"
        "dec  r26\n\t"
        "lsl  r22\n\t"
        "rol  r23\n\t"
        "rol  r24\n\t"
        "brpl 4b\n\t"
        "5:\n\t"  // the leading one out, E in its place, the sign
        "lsl  r24\n\t"
        "lsr  r26\n\t"
        "ror  r24\n\t"
        "andi r25, 0x80\n\t"
        "or   r25, r26\n\t"
        "ret\n\t"
        "7:\n\t"  // +0 (r22..r24 are 0)
        "clr  r25\n\t"
        "ret\n\t"
        "8:\n\t"  // avr-libc's __addsf3
        "clr  r27\n\t"
        "clr  r26\n\t"
        FSW_FAR_CALL "__addsf3x\n\t"
        FSW_FAR_JMP "__fp_round\n\t");
}

#undef FSW_FAR_JMP
#undef FSW_FAR_CALL
#endif

Real read_elem_typed(const uint8_t* p, uint8_t type) {
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

void write_elem_typed(uint8_t* p, uint8_t type, Real r) {
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

void elem_widen(const uint8_t* p, uint8_t type, uint8_t* b) {
    const uint8_t n = elem_size(type);
    const uint8_t fill = type < kU8 && (p[n - 1u] & 0x80u) != 0 ? 0xFF : 0x00;
    for (uint8_t i = 0; i < 8; ++i) b[i] = i < n ? p[i] : fill;
}

#if FSW_REAL_IS_FLOAT
// Where R is binary32, every integer type goes through one path on the
// bits (the typed conversions of fsw_convert.h, exactly): a read widens the
// value to 64 bits and rounds its magnitude once, a write builds the
// truncated magnitude from the float's fields and clamps by its exponent.
// Less than half the code the eleven typed cases inlined (the bytecode VM's
// flash, tools/bench_vm.py), and no float arithmetic routine.

namespace {

// Two's complement negation of the 8 bytes at b, a byte at a time (no
// 64-bit arithmetic inlined on an 8-bit MCU).
FSW_NOINLINE void negate8(uint8_t* b) {
    uint8_t carry = 1;
    for (uint8_t i = 0; i < 8; ++i) {
        const uint8_t x = static_cast<uint8_t>(static_cast<uint8_t>(~b[i]) + carry);
        if (x != 0) carry = 0;
        b[i] = x;
    }
}

}  // namespace

Real read_int_elem(const uint8_t* p, uint8_t type) {
    uint8_t b[8];
    elem_widen(p, type, b);
    const bool neg = type < kU8 && (b[7] & 0x80u) != 0;
    if (neg) negate8(b);
    uint64_t v;
    memcpy(&v, b, sizeof v);
    const Real r = real_from_U64(v);
    return neg ? -r : r;
}

Real read_elem(const uint8_t* p, uint8_t type) {
    if (type <= kU64) return read_int_elem(p, type);
    switch (type) {
        case kF32: return read_F32(p);
        case kF64: return read_F64(p);
        case kBool: return read_bool(p);
        default: return 0;
    }
}

void write_elem(uint8_t* p, uint8_t type, Real r) {
    switch (type) {
        case kF32: write_F32(p, r); break;
        case kF64: write_F64(p, r); break;
        case kBool: write_bool(p, r); break;
        default:
            if (type <= kU64) write_int_elem(p, type, r);
            break;
    }
}

void write_int_elem(uint8_t* p, uint8_t type, Real r) {
    uint32_t u;
    memcpy(&u, &r, sizeof u);
    const uint8_t n = elem_size(type);
    const bool sign = type < kU8;
    const bool neg = (u >> 31) != 0;
    const uint8_t e = static_cast<uint8_t>(u >> 23);
    uint8_t b[12] = {0};  // (4 spare: the shifted copy below) NaN, below 1 in magnitude, a negative into an unsigned type: 0
    if ((u & 0x7FFFFFFFUL) <= 0x7F800000UL && e >= 127 && (sign || !neg)) {
        // |r| = 1.f x 2^s: saturated at 2^bits (2^(bits-1) signed), which a
        // saturating assignment clamps to, else truncated toward zero.
        const uint8_t bits = static_cast<uint8_t>(8u * n - (sign ? 1u : 0u));
        const uint8_t s = static_cast<uint8_t>(e - 127u);
        if (s >= bits) {  // the type's max (min when negative), which needs no negation
            memset(b, neg ? 0x00 : 0xFF, n);
            if (sign) b[n - 1u] = neg ? 0x80 : 0x7F;
        } else {
            uint32_t m = (u & 0x7FFFFFUL) | 0x800000UL;  // 24 bits
            uint8_t at = 0;
            if (s <= 23) {
                m >>= 23u - s;
            } else {  // shifted left by s - 23 (1..40): by bytes, then bits
                at = static_cast<uint8_t>((s - 23u) / 8u);
                m <<= (s - 23u) % 8u;
            }
            memcpy(b + at, &m, 4);
            if (neg) negate8(b);
        }
    }
    memcpy(p, b, n);  // the low bytes (little-endian)
}
#else
Real read_elem(const uint8_t* p, uint8_t type) { return read_elem_typed(p, type); }
void write_elem(uint8_t* p, uint8_t type, Real r) { write_elem_typed(p, type, r); }
#endif

}  // namespace fsw
