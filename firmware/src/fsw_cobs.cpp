// COBS encoder (incremental, with the link's CRC-16) and in-place decoder.
#include "fsw_cobs.h"

#include "fsw_crc.h"

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

void cobs_put(CobsEncoder& e, uint8_t b) {
    e.crc = crc16_update(e.crc, b);
    put_raw(e, b);
}

void cobs_put_bytes(CobsEncoder& e, const uint8_t* p, uint16_t n) {
    for (uint16_t i = 0; i < n; ++i) cobs_put(e, p[i]);
}

void cobs_put_u16(CobsEncoder& e, uint16_t v) {
    cobs_put(e, static_cast<uint8_t>(v));
    cobs_put(e, static_cast<uint8_t>(v >> 8));
}

void cobs_put_u32(CobsEncoder& e, uint32_t v) {
    cobs_put_u16(e, static_cast<uint16_t>(v));
    cobs_put_u16(e, static_cast<uint16_t>(v >> 16));
}

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
