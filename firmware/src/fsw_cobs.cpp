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

#if defined(__AVR__) && defined(__AVR_HAVE_MUL__)

// On AVR the framer is a few lines of assembly (the avr-gcc calling
// convention: buf r25:24, n r23:22, src r21:20, src_n r19:18, src2
// r17:16, src2_n r15:14, the length back in r25:24). Its registers: the
// frame in Z, the source in Y, X one byte past the open block's code byte
// (a zero's code goes there with a pre-decrement store, and the next
// block's code byte is the zero's place: X takes the frame's pointer as it
// is), the open block's code + 1 in r24 (a full block, code 0xFF, is the
// increment that wraps it to 0: no compare), the CRC in r13:r12 (high,
// low), 16 in r2, the bytes left in r23:22 (its low byte counts the bytes,
// its high byte each 256 more: a low byte of 0 on entry is the high
// byte's 256). It saves 7 registers (the shared routine saved 17 for the
// compiled framer: 8 bytes less stack on the deepest path, the sample
// frame's). Each part is a call of the loop (`2:`): 23 cycles a non-zero
// byte, 27 a zero, the CRC step 12 of them with two multiplications
// (x = hi ^ b; r1 = x >> 4; x ^= r1; r1:r0 = x * 16, that is x >> 4 and
// x << 4; the low byte takes x << 4; one shift of r1:r0 gives x >> 3 and
// x << 5; the new high and low bytes in r1:r0, one movw), where avr-libc's
// step takes 18 and the compiled one 16. A full block (254 data bytes)
// stores its code 0xFF and takes a slot for the next code byte: bytes in
// place move one byte on first (frames of 254 bytes and more only).
__attribute__((naked, noinline, used)) uint16_t cobs_frame(uint8_t*, uint16_t, const uint8_t*, uint16_t,
                                                           const uint8_t*, uint16_t) {
    __asm__ __volatile__(
        "    push r28\n"
        "    push r29\n"
        "    push r12\n"
        "    push r13\n"
        "    push r2\n"
        "    push r24\n"  // buf, for the length
        "    push r25\n"
        "    movw r30, r24\n"
        "    adiw r30, 1\n"   // the body's first byte, after the first code byte
        "    movw r26, r30\n"
        "    movw r28, r30\n"  // the body in place
        "    ldi  r24, 16\n"
        "    mov  r2, r24\n"
        "    ldi  r24, 0xFF\n"  // kCrcInit
        "    mov  r12, r24\n"
        "    mov  r13, r24\n"
        "    ldi  r24, 2\n"  // code 1
        "    rcall 2f\n"  // the body, n bytes in r23:22
        "    movw r28, r20\n"
        "    movw r22, r18\n"
        "    rcall 2f\n"  // src's
        "    movw r28, r16\n"
        "    movw r22, r14\n"
        "    rcall 2f\n"  // src2's
        "    mov  r25, r13\n"  // the CRC, high byte first, as body bytes (not folded in)
        "    rcall 1f\n"
        "    mov  r25, r12\n"
        "    rcall 1f\n"
        "    subi r24, 1\n"  // the last block's code
        "    st   -X, r24\n"
        "    st   Z+, r1\n"  // the delimiter
        "    pop  r25\n"
        "    pop  r24\n"
        "    sub  r30, r24\n"  // the length
        "    sbc  r31, r25\n"
        "    movw r24, r30\n"
        "    pop  r2\n"
        "    pop  r13\n"
        "    pop  r12\n"
        "    pop  r29\n"
        "    pop  r28\n"
        "    ret\n"
        // one byte (r25) into the frame, not into the CRC
        "1:  st   Z+, r25\n"
        "    tst  r25\n"
        "    breq 3f\n"
        "    inc  r24\n"
        "    brne 9f\n"
        "    ldi  r25, 0xFF\n"  // a full block: its code, and a slot for the next
        "    st   -X, r25\n"
        "    adiw r30, 1\n"
        "    rjmp 4f\n"
        "3:  subi r24, 1\n"  // a zero: the open block's code
        "    st   -X, r24\n"
        "4:  movw r26, r30\n"
        "    ldi  r24, 2\n"
        "9:  ret\n"
        // r23:22 bytes from Y into the frame, framed and folded into the CRC
        "2:  cp   r22, r1\n"
        "    cpc  r23, r1\n"
        "    breq 9b\n"
        "    cpse r22, r1\n"
        "    rjmp 5f\n"
        "    subi r23, 1\n"
        "5:  ld   r25, Y+\n"
        "    st   Z+, r25\n"
        "    eor  r13, r25\n"  // x = hi ^ b
        FSW_CRC_STEP_MUL("r13", "r12", "r2")  // (fsw_crc.h: r2 holds 16)
        "    tst  r25\n"
        "    breq 6f\n"  // a zero: out of the non-zero bytes' way
        "    inc  r24\n"
        "    breq 8f\n"  // a full block
        "    subi r22, 1\n"
        "    brne 5b\n"
        "7:  subi r23, 1\n"  // 256 more, or none
        "    brcc 5b\n"
        "    clr  r1\n"
        "    ret\n"
        "6:  subi r24, 1\n"  // a zero: the open block's code
        "    st   -X, r24\n"
        "    movw r26, r30\n"
        "    ldi  r24, 2\n"
        "    subi r22, 1\n"
        "    brne 5b\n"
        "    rjmp 7b\n"
        "8:  clr  r1\n"
        "    subi r22, 1\n"  // the bytes left, whole
        "    ldi  r24, 0xFF\n"  // the full block's code
        "    st   -X, r24\n"
        "    cp   r28, r30\n"
        "    cpc  r29, r31\n"
        "    brne 4f\n"
        "    add  r28, r22\n"  // in place: the rest one byte on, from its end
        "    adc  r29, r23\n"
        "3:  cp   r28, r30\n"
        "    cpc  r29, r31\n"
        "    breq 3f\n"
        "    ld   r25, -Y\n"
        "    std  Y+1, r25\n"
        "    rjmp 3b\n"
        "3:  adiw r28, 1\n"
        "4:  adiw r30, 1\n"  // the next code byte's slot
        "    movw r26, r30\n"
        "    ldi  r24, 2\n"
        "    rjmp 2b\n");
}

#else

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
// one byte further.
void frame_copy(FrameRun& r, const uint8_t* src, uint16_t left) {
    uint8_t* p = r.p;
    uint8_t* code_p = r.code_p;
    uint8_t code = r.code;
    uint8_t hi = r.hi, lo = r.lo;
    for (;;) {
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

uint16_t cobs_frame(uint8_t* buf, uint16_t n, const uint8_t* src, uint16_t src_n, const uint8_t* src2,
                    uint16_t src2_n) {
    FrameRun r = {buf + 1, buf, 1, 0xFFu, 0xFFu};  // the CRC from kCrcInit
    frame_copy(r, buf + 1, n);  // the body in place
    frame_copy(r, src, src_n);
    frame_copy(r, src2, src2_n);
    const uint8_t crc[2] = {r.hi, r.lo};  // high byte first
    for (uint8_t i = 0; i < 2; ++i) {      // frame_copy's steps for two bytes, without the CRC
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

#endif

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
