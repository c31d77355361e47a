// CRC-16/CCITT-FALSE of the telemetry link (fsw_crc.h).
#include "fsw_crc.h"

#if defined(__AVR__)
#include <util/crc16.h>
#endif

namespace fsw {

uint16_t crc16_update(uint16_t crc, uint8_t byte) {
#if defined(__AVR__) && defined(__AVR_HAVE_MUL__)
    // The framer's step (fsw_cobs.cpp): 12 cycles with two multiplications,
    // 13 instructions where avr-libc's _crc_xmodem_update takes 25.
    uint8_t k;
    __asm__(
        "eor  %B[crc], %[b]\n\t"  // x = hi ^ b, in the high byte
        "ldi  %[k], 16\n\t"
        FSW_CRC_STEP_MUL("%B[crc]", "%A[crc]", "%[k]")
        "clr  __zero_reg__"
        : [crc] "+r"(crc), [k] "=&d"(k)
        : [b] "r"(byte)
        : "r0");
    return crc;
#elif defined(__AVR__)
    return _crc_xmodem_update(crc, byte);
#else
    crc = static_cast<uint16_t>(crc ^ (static_cast<uint16_t>(byte) << 8));
    for (uint8_t i = 0; i < 8; ++i) {
        crc = static_cast<uint16_t>((crc & 0x8000u) ? (crc << 1) ^ 0x1021u : crc << 1);
    }
    return crc;
#endif
}

uint16_t crc16(const uint8_t* data, uint16_t len, uint16_t crc) {
    for (uint16_t i = 0; i < len; ++i) crc = crc16_update(crc, data[i]);
    return crc;
}

}  // namespace fsw
