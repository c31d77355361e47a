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

// CRC of `len` bytes. Over a frame followed by its CRC (high byte first)
// the result is 0.
uint16_t crc16(const uint8_t* data, uint16_t len, uint16_t crc = kCrcInit);

}  // namespace fsw

#endif  // FSW_CRC_H
