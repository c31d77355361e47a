// COBS framing of the telemetry link (docs/telemetry.md): an in-place
// framer (the body written raw where its encoding goes, then its CRC-16 and
// COBS in one pass: what the link uses), an incremental encoder (the same
// bytes, built a call at a time: the tests' reference) and an in-place
// decoder (the tests' and the ground's reference: the link's uplink decodes
// a frame and checks its CRC in one pass of its own, fsw_link.cpp
// decode_frame).
#ifndef FSW_COBS_H
#define FSW_COBS_H

#include "fsw_types.h"

namespace fsw {

// Encoded size bound of a frame of `n` bytes (body + CRC), delimiter included.
inline uint16_t cobs_max_encoded(uint16_t n) { return static_cast<uint16_t>(n + n / 254u + 2u); }

// Frames a body in place: the body lies raw at buf[1..n] (buf[0] is the
// first code byte's), and `src_n` more bytes from `src`, then `src2_n` from
// `src2`, are copied in after it as they are framed (no second pass over
// them: a sample frame's stored samples and its current region). Appends
// the CRC-16 (high byte first), COBS-encodes body ‖ CRC where it lies (a
// non-zero byte stays where it is: only zeros, and a byte after every full
// block of 254, move) and writes the delimiter. `buf` holds
// cobs_max_encoded(n + src_n + src2_n + 2) bytes. Returns the encoded
// length, delimiter included: the same bytes as cobs_begin,
// cobs_put_bytes(body ‖ src ‖ src2), cobs_end. On AVR (with `mul`) a
// routine in assembly (fsw_cobs.cpp).
uint16_t cobs_frame(uint8_t* buf, uint16_t n, const uint8_t* src = 0, uint16_t src_n = 0, const uint8_t* src2 = 0,
                    uint16_t src2_n = 0);

struct CobsEncoder {
    uint8_t* out;      // the encoded frame so far
    uint16_t len;      // bytes of `out` used
    uint16_t code_at;  // where the open block's code byte goes
    uint8_t code;      // the open block's code (1 + its data bytes)
    uint16_t crc;      // CRC of the body so far
};

// Starts a frame in `out` (room for cobs_max_encoded(body + 2) bytes).
void cobs_begin(CobsEncoder& e, uint8_t* out);
// Appends body bytes (encoded, and folded into the CRC).
void cobs_put(CobsEncoder& e, uint8_t b);
void cobs_put_bytes(CobsEncoder& e, const uint8_t* p, uint16_t n);
void cobs_put_u16(CobsEncoder& e, uint16_t v);  // little-endian
void cobs_put_u32(CobsEncoder& e, uint32_t v);  // little-endian
// Appends the CRC (high byte first), closes the last block and writes the
// delimiter; returns the encoded length.
uint16_t cobs_end(CobsEncoder& e);

// Decodes one frame (the bytes between two delimiters, none of them 0x00)
// in place; returns its length, or -1 when the bytes are not a valid COBS
// encoding (a block that runs past the end, or a zero byte).
int16_t cobs_decode(uint8_t* buf, uint16_t n);

}  // namespace fsw

#endif  // FSW_COBS_H
