// The state-machine bookkeeping generated code calls out of line (spec 4.6):
// the 64-bit time arithmetic once in flash, whatever the number of machines.
#include "fsw_machine.h"

#include "fsw_element.h"

namespace fsw {

#if defined(__AVR__)
// machine_begin_step in a few lines of assembly, G held in eight registers
// the call may change (r18, r19, r22..r25, r0 and r1, cleared again before
// the return): no register to save, where the compiler's version (on
// 32-bit halves) saved twelve through the call-prologue routine; 137
// cycles a step on the demo flight instead of about 220, and less flash.
// The offsets are the Machine's (the static_assert below).
static_assert(offsetof(Machine, last_g) == 0 && offsetof(Machine, entry_g) == 8 && offsetof(Machine, state) == 16 &&
                  offsetof(Machine, pending) == 20 && offsetof(Machine, entering) == 21 &&
                  offsetof(Machine, started) == 22,
              "machine_begin's assembly reads the Machine at these offsets");
#define FSW_G_BYTES(op) op(0, r18) op(1, r19) op(2, r22) op(3, r23) op(4, r24) op(5, r25) op(6, r0) op(7, r1)
#define FSW_CMP_LAST(i, g) "ldd r26, Z+" #i "\n\t" FSW_CMP_OP_##i " r26, " #g "\n\t"
#define FSW_CMP_OP_0 "cp"
#define FSW_CMP_OP_1 "cpc"
#define FSW_CMP_OP_2 "cpc"
#define FSW_CMP_OP_3 "cpc"
#define FSW_CMP_OP_4 "cpc"
#define FSW_CMP_OP_5 "cpc"
#define FSW_CMP_OP_6 "cpc"
#define FSW_CMP_OP_7 "cpc"
#define FSW_SET_ENTRY(i, g) "std Z+8+" #i ", " #g "\n\t"
#define FSW_SET_LAST(i, g) "std Z+" #i ", " #g "\n\t"
static_assert(kOk == 0 && kErrTime == 1, "machine_begin's assembly returns kOk as 0, kErrTime as 1");
Result machine_begin(Machine& m, const uint8_t* g, uint8_t* s) {
    // the arguments where the call brings them (r24, r22, r20)
    register Machine* mp __asm__("r24") = &m;
    register const uint8_t* gp __asm__("r22") = g;
    register uint8_t* sp __asm__("r20") = s;
    uint8_t r;
    __asm__ __volatile__(
        "movw r30, %[m]\n\t"  // Z: the machine
        "movw r26, %[g]\n\t"  // X: G, read into the registers
        "ld   r18, X+\n\t"
        "ld   r19, X+\n\t"
        "ld   r22, X+\n\t"
        "ld   r23, X+\n\t"
        "ld   r24, X+\n\t"
        "ld   r25, X+\n\t"
        "ld   r0, X+\n\t"
        "ld   r1, X\n\t"
        "ldd  r26, Z+22\n\t"  // started: G must be above the last G
        "tst  r26\n\t"
        "breq 1f\n\t"
        FSW_G_BYTES(FSW_CMP_LAST)  // last G - G borrows only when G is greater
        "brcs 2f\n\t"
        "clr  r1\n\t"  // refused: nothing changed
        "clr  %[r]\n\t"
        "inc  %[r]\n\t"  // kErrTime
        "rjmp 9f\n\t"
        "1:\n\t"  // the first step (only then: a started machine skips these 16 cycles)
        "ldi  r26, 1\n\t"
        "std  Z+22, r26\n\t"
        "ldd  r26, Z+16\n\t"  // a zero Machine (not started, state 0): state 1, its first step
        "ldd  r27, Z+17\n\t"
        "or   r26, r27\n\t"
        "ldd  r27, Z+18\n\t"
        "or   r26, r27\n\t"
        "ldd  r27, Z+19\n\t"
        "or   r26, r27\n\t"
        "brne 2f\n\t"
        "ldi  r26, 1\n\t"
        "std  Z+16, r26\n\t"
        "std  Z+20, r26\n\t"
        "2:\n\t"
        "ldd  r27, Z+20\n\t"  // entering = pending
        "std  Z+21, r27\n\t"
        "tst  r27\n\t"
        "breq 3f\n\t"
        FSW_G_BYTES(FSW_SET_ENTRY)  // the state's first step: entered at G
        "clr  r26\n\t"
        "std  Z+20, r26\n\t"
        "3:\n\t"
        FSW_G_BYTES(FSW_SET_LAST)
        "clr  r1\n\t"
        "tst  r27\n\t"
        "breq 4f\n\t"
        "ldd  r18, Z+16\n\t"  // and S = the state
        "ldd  r19, Z+17\n\t"
        "ldd  r22, Z+18\n\t"
        "ldd  r23, Z+19\n\t"
        "movw r30, %[s]\n\t"
        "st   Z, r18\n\t"
        "std  Z+1, r19\n\t"
        "std  Z+2, r22\n\t"
        "std  Z+3, r23\n\t"
        "4:\n\t"
        "clr  %[r]\n\t"  // kOk
        "9:\n\t"
        : [r] "=r"(r), [m] "+r"(mp), [g] "+r"(gp)
        : [s] "r"(sp)
        : "r0", "r18", "r19", "r26", "r27", "r30", "r31", "memory");
    return static_cast<Result>(r);
}
#undef FSW_G_BYTES
#undef FSW_CMP_LAST
#undef FSW_SET_ENTRY
#undef FSW_SET_LAST
#endif

#if defined(__AVR__)
// T = last_g - entry_g, a byte at a time with the borrow carried up (ldd
// leaves the flags alone): no 64-bit routine on an 8-bit MCU. One copy for
// machine_T32 and machine_T_real, called from their assembly with the
// Machine in Z: the low half in r22..r25, the high half in r18..r21, r0
// changed, Z kept. The offsets are the Machine's (static_assert above).
#define FSW_T_BYTE(op, r, i) "ldd " r ", Z+" #i "\n\t" "ldd __tmp_reg__, Z+8+" #i "\n\t" op " " r ", __tmp_reg__\n\t"
extern "C" __attribute__((naked, noinline, used, externally_visible)) void fsw_machine_T_halves() {
    __asm__ __volatile__(FSW_T_BYTE("sub", "r22", 0) FSW_T_BYTE("sbc", "r23", 1) FSW_T_BYTE("sbc", "r24", 2)
                         FSW_T_BYTE("sbc", "r25", 3) FSW_T_BYTE("sbc", "r18", 4) FSW_T_BYTE("sbc", "r19", 5)
                         FSW_T_BYTE("sbc", "r20", 6) FSW_T_BYTE("sbc", "r21", 7) "ret\n\t");
}
#undef FSW_T_BYTE

namespace {
inline __attribute__((always_inline)) void T_halves(const Machine& m, uint32_t& lo, uint32_t& hi) {
    register uint32_t l __asm__("r22");
    register uint32_t h __asm__("r18");
    __asm__("%~call fsw_machine_T_halves" : "=r"(l), "=r"(h) : "z"(&m), "m"(m) : "r0");
    lo = l;
    hi = h;
}
}  // namespace

uint32_t machine_T32(const Machine& m) {
    uint32_t lo, hi;
    T_halves(m, lo, hi);
    return hi != 0 ? 0xFFFFFFFFUL : lo;
}

Real machine_T_real(const Machine& m) {
    uint32_t lo, hi;
    T_halves(m, lo, hi);
    if (hi == 0) return f32_from_u32(lo);  // correctly rounded (fsw_convert.h)
    // Shift right until the value fits 32 bits, OR-ing what falls off into
    // bit 0 (below the guard bit: the rounding is unchanged), convert, and
    // scale by 2^k exactly. (The loop in assembly: the compiler's copied
    // the 64-bit value between register sets at each turn.)
    uint8_t k = 0, sticky = 0;
    __asm__("1:\n\t"
            "sbrc %A[lo], 0\n\t"
            "ori  %[st], 1\n\t"
            "lsr  %D[hi]\n\tror  %C[hi]\n\tror  %B[hi]\n\tror  %A[hi]\n\t"
            "ror  %D[lo]\n\tror  %C[lo]\n\tror  %B[lo]\n\tror  %A[lo]\n\t"
            "inc  %[k]\n\t"
            "mov  __tmp_reg__, %A[hi]\n\tor   __tmp_reg__, %B[hi]\n\t"
            "or   __tmp_reg__, %C[hi]\n\tor   __tmp_reg__, %D[hi]\n\t"
            "brne 1b"
            : [hi] "+r"(hi), [lo] "+r"(lo), [k] "+r"(k), [st] "+d"(sticky));
    // Times 2^k: k added to the exponent field (bits 23..30; the value is a
    // normal number from 2^31 to 2^64, so the field neither wraps nor spills).
    Real r = f32_from_u32(lo | sticky);
    uint32_t bits;
    memcpy(&bits, &r, sizeof bits);
    const uint16_t e = static_cast<uint16_t>(static_cast<uint16_t>(k) << 7);  // k << 23: the upper half's k << 7
    __asm__("add %C[b], %A[e]\n\tadc %D[b], %B[e]" : [b] "+r"(bits) : [e] "r"(e));
    memcpy(&r, &bits, sizeof r);
    return r;
}
#endif

uint32_t round_f32_saturated(uint32_t v, uint32_t hi) {
#if defined(__AVR__)
    if (v >= 0x1000000UL) {
        // v as a float (f32_from_u32: rounded to 24 significant bits, ties
        // to even, the conversion every integer takes on AVR, linked
        // already) and back: its significand shifted up by its exponent less
        // 23's, 1 to 8, or 9 for 2^32 (rounded up from above 2^32 - 2^7),
        // above any hi. (The rounding written out here was 142 B.)
        const float f = f32_from_u32(v);
        uint8_t b[4];  // little-endian: byte 3 the sign and the exponent's high seven bits, byte 2's top bit its low one
        memcpy(b, &f, sizeof b);
        uint8_t e = static_cast<uint8_t>(static_cast<uint8_t>((b[3] << 1) | (b[2] >> 7)) - 150u);
        if (e > 8) return hi;
        b[2] = static_cast<uint8_t>(b[2] | 0x80u);  // the leading one, over the exponent's low bit
        b[3] = 0;
        memcpy(&v, b, sizeof v);
        do {
            v <<= 1;
        } while (--e != 0);
    }
#else
    if (v >= 0x1000000UL) {
        // 24 significant bits: down to 25, what falls off OR-ed into
        // `sticky`; the lowest of the 25 is the round bit. Round to
        // nearest, ties to even, drop it, and shift back. (Few enough
        // values for the call-clobbered registers: no saves.)
        uint8_t s = 1, sticky = 0;
        while (v >= 0x2000000UL) {
            sticky = static_cast<uint8_t>(sticky | (static_cast<uint8_t>(v) & 1u));
            v >>= 1;
            ++s;
        }
        const bool up = (v & 1u) != 0 && (sticky != 0 || (v & 2u) != 0);
        v = (v >> 1) + up;
        do {
            if ((v & 0x80000000UL) != 0) return hi;  // rounded up to 2^32, above any hi
            v <<= 1;
        } while (--s != 0);
    }
#endif
    return v > hi ? hi : v;
}

}  // namespace fsw
