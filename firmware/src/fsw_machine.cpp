// The state-machine bookkeeping generated code calls out of line (spec 4.6):
// the 64-bit time arithmetic once in flash, whatever the number of machines.
#include "fsw_machine.h"

#include "fsw_element.h"

namespace fsw {

#if defined(__AVR__)
// machine_begin_step on 32-bit halves: avr-gcc calls a library routine for
// each 64-bit compare and subtraction and moves every operand through
// registers; halves are less code and as fast.
Result machine_begin(Machine& m, const uint8_t* g, uint8_t* s) {
    const uint32_t glo = load<uint32_t>(g), ghi = load<uint32_t>(g + 4);
    uint8_t* last = reinterpret_cast<uint8_t*>(&m.last_g);
    if (m.started != 0) {  // G <= last G: refused
        const uint32_t lhi = load<uint32_t>(last + 4);
        if (ghi < lhi || (ghi == lhi && glo <= load<uint32_t>(last))) return kErrTime;
    }
    m.started = 1;
    store<uint32_t>(last, glo);
    store<uint32_t>(last + 4, ghi);
    if (m.state == 0) {  // a zero Machine: before the first step in state 1
        m.state = 1;
        m.pending = 1;
    }
    m.entering = m.pending;
    uint8_t* entry = reinterpret_cast<uint8_t*>(&m.entry_g);
    if (m.pending != 0) {
        store<uint32_t>(entry, glo);
        store<uint32_t>(entry + 4, ghi);
        m.pending = 0;
    }
    const uint32_t elo = load<uint32_t>(entry);  // T = G - entry, the borrow between the halves
    uint8_t* t = reinterpret_cast<uint8_t*>(&m.t);
    store<uint32_t>(t, glo - elo);
    store<uint32_t>(t + 4, ghi - load<uint32_t>(entry + 4) - (glo < elo ? 1u : 0u));
    if (m.entering != 0) store<uint32_t>(s, m.state);
    return kOk;
}
#endif

#if defined(__AVR__)
uint32_t machine_T32(const Machine& m) {
    // The halves as bytes (little-endian): no 64-bit shift on an 8-bit MCU.
    const uint8_t* t = reinterpret_cast<const uint8_t*>(&m.t);
    return load<uint32_t>(t + 4) != 0 ? 0xFFFFFFFFUL : load<uint32_t>(t);
}

Real machine_T_real(const Machine& m) {
    const uint8_t* t = reinterpret_cast<const uint8_t*>(&m.t);
    uint32_t lo = load<uint32_t>(t), hi = load<uint32_t>(t + 4);
    if (hi == 0) return static_cast<Real>(lo);  // correctly rounded by the float library
    // Shift right until the value fits 32 bits, OR-ing what falls off into
    // bit 0 (below the guard bit: the rounding is unchanged), convert, and
    // scale by 2^k exactly.
    uint8_t k = 0, sticky = 0;
    do {
        sticky = static_cast<uint8_t>(sticky | (lo & 1u));
        lo = (lo >> 1) | (hi << 31);
        hi >>= 1;
        ++k;
    } while (hi != 0);
    // Times 2^k: k added to the exponent field (bits 23..30; the value is a
    // normal number from 2^31 to 2^64, so the field neither wraps nor spills).
    Real r = static_cast<Real>(lo | sticky);
    uint32_t bits;
    memcpy(&bits, &r, sizeof bits);
    bits += static_cast<uint32_t>(static_cast<uint16_t>(k << 7)) << 16;  // k << 23, as byte moves
    memcpy(&r, &bits, sizeof r);
    return r;
}
#endif

uint32_t round_f32_saturated(uint32_t v, uint32_t hi) {
    if (v >= 0x1000000UL) {
        // 24 significant bits: drop s low bits, round to nearest, ties to even.
        uint8_t s = 1;
        while ((v >> s) >= 0x1000000UL) ++s;
        const uint32_t unit = 1UL << s, rem = v & (unit - 1u), half = unit >> 1;
        v -= rem;
        if (rem > half || (rem == half && (v & unit) != 0)) {
            v += unit;
            if (v == 0) return hi;  // rounded up to 2^32, above any hi
        }
    }
    return v > hi ? hi : v;
}

}  // namespace fsw
