// COBS framing with the link's CRC-16: the in-place framer the link uses, the
// incremental encoder (the tests' reference), and the in-place decoder.
#include "fsw_cobs.h"

#include "fsw_crc.h"

#if defined(__AVR__)
#include <util/crc16.h>
#endif

namespace fsw {

void cobs_begin(CobsEncoder& e, uint8_t* out) {
    e.out = out;
    e.len = 1;
    e.code_at = 0;
    e.code = 1;
    e.crc = kCrcInit;
}

FSW_NOINLINE FSW_NOCLONE static void put_raw(CobsEncoder& e, uint8_t b) {
    if (b == 0) {
        e.out[e.code_at] = e.code;
        e.code_at = e.len++;
        e.code = 1;
        return;
    }
    e.out[e.len++] = b;
    if (++e.code == 0xFFu) {  // a full block: 254 data bytes, no zero implied
        e.out[e.code_at] = 0xFFu;
        e.code_at = e.len++;
        e.code = 1;
    }
}

// The incremental encoder's loop (the link frames with cobs_frame; this is
// the tests' reference): its state in registers, the output through pointers.
void cobs_put_bytes(CobsEncoder& e, const uint8_t* p, uint16_t n) {
    uint8_t* w = e.out + e.len;
    uint8_t* code_p = e.out + e.code_at;
    uint8_t code = e.code;
    uint16_t crc = e.crc;
    for (; n != 0; --n) {
        const uint8_t b = *p++;
#if defined(__AVR__)
        crc = _crc_xmodem_update(crc, b);
#else
        crc = crc16_update(crc, b);
#endif
        if (b == 0) {
            *code_p = code;
            code_p = w++;
            code = 1;
        } else {
            *w++ = b;
            if (++code == 0xFFu) {  // a full block: 254 data bytes, no zero implied
                *code_p = 0xFFu;
                code_p = w++;
                code = 1;
            }
        }
    }
    e.len = static_cast<uint16_t>(w - e.out);
    e.code_at = static_cast<uint16_t>(code_p - e.out);
    e.code = code;
    e.crc = crc;
}

void cobs_put(CobsEncoder& e, uint8_t b) { cobs_put_bytes(e, &b, 1); }

// Little-endian targets (fsw_config.h): a value's bytes are its wire order.
void cobs_put_u16(CobsEncoder& e, uint16_t v) { cobs_put_bytes(e, reinterpret_cast<const uint8_t*>(&v), 2); }

void cobs_put_u32(CobsEncoder& e, uint32_t v) { cobs_put_bytes(e, reinterpret_cast<const uint8_t*>(&v), 4); }

uint16_t cobs_end(CobsEncoder& e) {
    const uint16_t crc = e.crc;
    put_raw(e, static_cast<uint8_t>(crc >> 8));
    put_raw(e, static_cast<uint8_t>(crc));
    e.out[e.code_at] = e.code;
    e.out[e.len++] = 0;
    return e.len;
}

namespace {

// The framer's state between its runs.
struct FrameRun {
    uint8_t* p;       // the next byte's place
    uint8_t* code_p;  // the open block's code byte
    uint8_t code;     // the open block's code (1 + its data bytes)
    uint8_t hi, lo;   // the CRC so far
};

// The framer's loop: `left` bytes from `src` copied to r.p and framed on
// the way, the CRC folded in. `src` is r.p itself for bytes already in
// place (the body composed raw), or another buffer (the state vector's
// region). A zero closes the open block: its code goes to the block's code
// byte and the zero's place is the next block's. A full block (254 data
// bytes) takes a slot for the next code byte after it: bytes in place move
// one byte on (frames of 254 bytes and more only); bytes copied in just go
// one byte further. On AVR a few lines of assembly (the source in Y, the
// frame in Z, the open block's code byte behind X): 23 cycles a non-zero
// byte, 27 a zero (the CRC 12 of them, with two multiplications, where
// avr-libc's step takes 18: 27 and 35 before; 29 before an 8-bit count
// and a zero's steps out of line, 32 and 18 before that; MCUs without
// `mul` keep the 16-cycle step); it leaves the loop for a full block with
// the bytes left in `left`, whole.
#if defined(__AVR__)
// crc16_step on the CRC pair (%A low byte, %B high byte) and the byte %[b],
// in frame_copy's assembly. With `mul` 12 cycles: x = hi ^ b; r1 = x >> 4;
// x ^= r1; r1:r0 = x * 16 (x >> 4, x << 4); the low byte takes x << 4;
// one shift of r1:r0 gives x >> 3 and x << 5; the new bytes in r1:r0, one
// movw. Without, 16 cycles through %[k].
#if defined(__AVR_HAVE_MUL__)
#define FSW_FRAME_CRC_STEP                                                    \
    "    eor  %B[crc], %[b]\n\t"  /* x = hi ^ b, in the high byte */          \
    "    mul  %B[crc], %[k]\n\t"  /* r1 = x >> 4 */                           \
    "    eor  %B[crc], r1\n\t"    /* x ^= x >> 4 */                           \
    "    mul  %B[crc], %[k]\n\t"  /* r0 = x << 4, r1 = x >> 4 */              \
    "    eor  %A[crc], r0\n\t"    /* lo ^ x << 4 */                           \
    "    lsl  r0\n\t"             /* x << 5, and x's bit 3 in the carry */    \
    "    rol  r1\n\t"             /* x >> 3 */                                \
    "    eor  r1, %A[crc]\n\t"    /* the new high byte: lo ^ x << 4 ^ x >> 3 */ \
    "    eor  r0, %B[crc]\n\t"    /* the new low byte: x ^ x << 5 */          \
    "    movw %A[crc], r0\n\t"
#else
#define FSW_FRAME_CRC_STEP                                                    \
    "    eor  %B[crc], %[b]\n\t" /* x = hi ^ b, in the high byte */           \
    "    mov  %[k], %B[crc]\n\t"                                             \
    "    swap %[k]\n\t"                                                      \
    "    andi %[k], 0x0F\n\t"                                                \
    "    eor  %B[crc], %[k]\n\t" /* x ^= x >> 4 */                            \
    "    mov  %[k], %B[crc]\n\t"                                             \
    "    swap %[k]\n\t"                                                      \
    "    andi %[k], 0xF0\n\t"    /* x << 4 */                                 \
    "    eor  %A[crc], %[k]\n\t" /* lo ^ x << 4 */                            \
    "    lsl  %[k]\n\t"                                                      \
    "    eor  %[k], %B[crc]\n\t" /* x ^ x << 5: the new low byte */           \
    "    lsr  %B[crc]\n\t"                                                   \
    "    lsr  %B[crc]\n\t"                                                   \
    "    lsr  %B[crc]\n\t"                                                   \
    "    eor  %B[crc], %A[crc]\n\t" /* the new high byte */                   \
    "    mov  %A[crc], %[k]\n\t"
#endif
#endif

inline __attribute__((always_inline)) void frame_copy(FrameRun& r, const uint8_t* src, uint16_t left) {
    uint8_t* p = r.p;
    uint8_t* code_p = r.code_p;
    uint8_t code = r.code;
    uint8_t hi = r.hi, lo = r.lo;
    for (;;) {
#if defined(__AVR__)
        if (left != 0) {
            // c is the open block's code + 1, so that a full block (code
            // 0xFF) is the increment that wraps it to 0: no compare. X is
            // one byte past the open block's code byte (a zero's code goes
            // there with a pre-decrement store, and the next block's code
            // byte is the zero's place: X takes the frame's pointer as it
            // is). The CRC is a register pair (its low byte first): the
            // step's two products end in r1:r0, new high byte and new low
            // byte, and one movw puts them back.
            uint8_t b, k, c = static_cast<uint8_t>(code + 1u);
            uint8_t* cx = code_p + 1;
            uint16_t crc = static_cast<uint16_t>(lo | hi << 8);
            __asm__ __volatile__(
                "    ldi  %[k], 16\n\t"
                // the count's low byte counts the bytes, its high byte each
                // 256 more: a low byte of 0 on entry is the high byte's 256
                "    cpse %A[left], __zero_reg__\n\t"
                "    rjmp 1f\n\t"
                "    subi %B[left], 1\n\t"
                "1:  ld   %[b], Y+\n\t"
                "    st   Z+, %[b]\n\t"
                FSW_FRAME_CRC_STEP
                "    tst  %[b]\n\t"
                "    breq 6f\n\t"  // a zero: out of the non-zero bytes' way
                "    inc  %[c]\n\t"
                "    breq 4f\n\t"  // a full block
                "    subi %A[left], 1\n\t"
                "    brne 1b\n\t"
                "7:  subi %B[left], 1\n\t"  // 256 more, or none
                "    brcc 1b\n\t"
                "    rjmp 5f\n\t"
                "6:  subi %[c], 1\n\t"  // a zero: the open block's code
                "    st   -X, %[c]\n\t"
                "    movw %A[cx], %A[p]\n\t"
                "    ldi  %[c], 2\n\t"
                "    subi %A[left], 1\n\t"
                "    brne 1b\n\t"
                "    rjmp 7b\n\t"
                "4:  subi %A[left], 1\n\t"  // (the high byte as it is: the bytes left, whole)
                "5:  clr  __zero_reg__\n\t"  // (the products' r1)
                : [p] "+z"(p), [cx] "+x"(cx), [src] "+y"(src), [left] "+d"(left), [c] "+d"(c),
                  [crc] "+r"(crc), [b] "=&r"(b), [k] "=&d"(k)
                :
                : "r0", "memory");
            code = static_cast<uint8_t>(c - 1u);
            code_p = cx - 1;
            hi = static_cast<uint8_t>(crc >> 8);
            lo = static_cast<uint8_t>(crc);
        }
#else
        while (left != 0) {
            const uint8_t b = *src++;
            *p++ = b;
            --left;
            crc16_step(hi, lo, b);
            if (b == 0) {
                *code_p = code;
                code_p = p - 1;
                code = 1;
            } else if (++code == 0xFFu) {
                break;  // a full block
            }
        }
#endif
        if (code != 0xFFu) break;
        *code_p = 0xFFu;
        if (src == p) {  // in place: the rest one byte on
            memmove(p + 1, p, left);
            ++src;
        }
        code_p = p++;  // the next code byte's slot
        code = 1;
    }
    r.p = p;  // after the bytes framed, and the slots taken
    r.code_p = code_p;
    r.code = code;
    r.hi = hi;
    r.lo = lo;
}

}  // namespace

FSW_NOINLINE uint16_t cobs_frame(uint8_t* buf, uint16_t n, const uint8_t* src, uint16_t src_n) {
    FrameRun r = {buf + 1, buf, 1, 0xFFu, 0xFFu};  // the CRC from kCrcInit
    // the body in place, then src's bytes: one loop (one copy of the
    // framer's code) over the two parts
    const uint8_t* part = buf + 1;
    uint16_t part_n = n;
    for (uint8_t k = 0; k < 2; ++k) {
        frame_copy(r, part, part_n);
        part = src;
        part_n = src_n;
    }
    const uint8_t crc[2] = {r.hi, r.lo};  // high byte first
    for (uint8_t i = 0; i < 2; ++i) {      // frame_copy's steps for two bytes, without its call
        const uint8_t b = crc[i];
        *r.p++ = b;
        if (b == 0) {
            *r.code_p = r.code;
            r.code_p = r.p - 1;
            r.code = 1;
        } else if (++r.code == 0xFFu) {
            *r.code_p = 0xFFu;
            r.code_p = r.p++;
            r.code = 1;
        }
    }
    *r.code_p = r.code;
    *r.p++ = 0;
    return static_cast<uint16_t>(r.p - buf);
}

int16_t cobs_decode(uint8_t* buf, uint16_t n) {
    uint16_t in = 0, out = 0;
    while (in < n) {
        const uint8_t code = buf[in++];
        if (code == 0 || static_cast<uint16_t>(in + code - 1u) > n) return -1;
        const uint16_t end = static_cast<uint16_t>(in + code - 1u);
        while (in < end) {
            const uint8_t b = buf[in++];
            if (b == 0) return -1;
            buf[out++] = b;
        }
        if (code != 0xFFu && in < n) buf[out++] = 0;
    }
    return static_cast<int16_t>(out);
}

}  // namespace fsw
