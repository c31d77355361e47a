// CRC-16/CCITT-FALSE (polynomial 0x1021, init 0xFFFF, MSB first, no final
// xor) of the telemetry link: avr-libc's _crc_xmodem_update on AVR, the same
// bitwise algorithm elsewhere; Python's binascii.crc_hqx(data, 0xFFFF).
#ifndef FSW_CRC_H
#define FSW_CRC_H

#include "fsw_types.h"

namespace fsw {

static const uint16_t kCrcInit = 0xFFFFu;

// One byte into the CRC. Out of line (fsw_crc.cpp): the encoder and the
// uplink parser share one copy.
uint16_t crc16_update(uint16_t crc, uint8_t byte);

// CRC of `len` bytes. Over a frame followed by its CRC (high byte first)
// the result is 0.
uint16_t crc16(const uint8_t* data, uint16_t len, uint16_t crc = kCrcInit);

}  // namespace fsw

#endif  // FSW_CRC_H
