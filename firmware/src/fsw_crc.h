// CRC-16/CCITT-FALSE (polynomial 0x1021, init 0xFFFF, MSB first, no final
// xor) of the telemetry link: on AVR a step with two multiplications
// (fsw_crc.cpp; avr-libc's _crc_xmodem_update, the same CRC, on an AVR
// without `mul`), the same bitwise algorithm elsewhere; Python's
// binascii.crc_hqx(data, 0xFFFF).
#ifndef FSW_CRC_H
#define FSW_CRC_H

#include "fsw_types.h"

namespace fsw {

static const uint16_t kCrcInit = 0xFFFFu;

// One byte into the CRC. Out of line (fsw_crc.cpp): the encoder and the
// uplink parser share one copy.
uint16_t crc16_update(uint16_t crc, uint8_t byte);

// One byte into the CRC held as its two bytes, inline, without a table
// (x = high ^ byte; x ^= x >> 4; crc = crc << 8 ^ x << 12 ^ x << 5 ^ x, a
// byte at a time): about 16 AVR cycles; the framer's loop where it is
// compiled (the AVR framer has its own 12-cycle step, fsw_cobs.cpp), the
// recorder's block check.
inline void crc16_step(uint8_t& hi, uint8_t& lo, uint8_t byte) {
    uint8_t x = static_cast<uint8_t>(hi ^ byte);
    x = static_cast<uint8_t>(x ^ (x >> 4));
    const uint8_t t = static_cast<uint8_t>(x << 4);
    hi = static_cast<uint8_t>(lo ^ t ^ (x >> 3));
    lo = static_cast<uint8_t>(x ^ static_cast<uint8_t>(t << 1));
}

// The AVR step with two multiplications (`mul`), as assembly text for a
// routine's own registers: the byte already folded in, x = high ^ byte, in
// HI; LO the low byte (HI the register after it, a pair for `movw`); K a
// register holding 16. 12 cycles: x * 16 gives x >> 4 and x << 4 in r1:r0,
// one shift of them x >> 3 and x << 5, and the new CRC goes back into LO:HI.
// Clobbers r0 and r1 (the caller clears __zero_reg__ after). The framer's
// loop (fsw_cobs.cpp) and crc16_update (fsw_crc.cpp) take it.
#define FSW_CRC_STEP_MUL(HI, LO, K)                    \
    "mul  " HI ", " K "\n\t"  /* r1 = x >> 4 */       \
    "eor  " HI ", r1\n\t"     /* x ^= x >> 4 */       \
    "mul  " HI ", " K "\n\t"  /* r0 = x << 4, r1 = x >> 4 */ \
    "eor  " LO ", r0\n\t"     /* lo ^ x << 4 */       \
    "lsl  r0\n\t"             /* x << 5, and x's bit 3 in the carry */ \
    "rol  r1\n\t"             /* x >> 3 */            \
    "eor  r1, " LO "\n\t"     /* the new high byte: lo ^ x << 4 ^ x >> 3 */ \
    "eor  r0, " HI "\n\t"     /* the new low byte: x ^ x << 5 */ \
    "movw " LO ", r0\n\t"

// CRC of `len` bytes. Over a frame followed by its CRC (high byte first)
// the result is 0.
uint16_t crc16(const uint8_t* data, uint16_t len, uint16_t crc = kCrcInit);

}  // namespace fsw

#endif  // FSW_CRC_H
