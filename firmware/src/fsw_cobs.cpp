// COBS encoder (incremental, with the link's CRC-16) and in-place decoder.
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

// The encoder's loop: its state in registers, the CRC inline, the output
// through pointers; about 35 AVR cycles a byte (make bench measures it).
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
