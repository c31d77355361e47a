// CRC-16/CCITT-FALSE (polynomial 0x1021, init 0xFFFF, MSB first, no final
// xor) of the telemetry link: avr-libc's _crc_xmodem_update on AVR, the same
// bitwise algorithm elsewhere; Python's binascii.crc_hqx(data, 0xFFFF).
#ifndef FSW_CRC_H
#define FSW_CRC_H

#include "fsw_types.h"

#if defined(__AVR__)
#include <util/crc16.h>
#endif

namespace fsw {

static const uint16_t kCrcInit = 0xFFFFu;

inline uint16_t crc16_update(uint16_t crc, uint8_t byte) {
#if defined(__AVR__)
    return _crc_xmodem_update(crc, byte);
#else
    crc = static_cast<uint16_t>(crc ^ (static_cast<uint16_t>(byte) << 8));
    for (uint8_t i = 0; i < 8; ++i) {
        crc = static_cast<uint16_t>((crc & 0x8000u) ? (crc << 1) ^ 0x1021u : crc << 1);
    }
    return crc;
#endif
}

// CRC of `len` bytes. Over a frame followed by its CRC (high byte first)
// the result is 0.
inline uint16_t crc16(const uint8_t* data, uint16_t len, uint16_t crc = kCrcInit) {
    for (uint16_t i = 0; i < len; ++i) crc = crc16_update(crc, data[i]);
    return crc;
}

}  // namespace fsw

#endif  // FSW_CRC_H
