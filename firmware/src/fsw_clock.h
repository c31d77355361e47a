// 64-bit monotonic time from a wrapping 32-bit counter (micros() wraps every
// 71.6 minutes): correct as long as it is read at least once per wrap.
#ifndef FSW_CLOCK_H
#define FSW_CLOCK_H

#include "fsw_types.h"

namespace fsw {

struct Clock64 {
    uint32_t last;  // previous 32-bit reading
    uint32_t high;  // wraps seen so far
};

static_assert(sizeof(Clock64) == 8, "Clock64: two packed words");

// Extends a new 32-bit reading; a reading below the previous one is a wrap.
// Not re-entrant: call from one context (the executor's loop).
inline uint64_t clock64_extend(Clock64& record, uint32_t now32) {
    Clock64* p = &record;
#if defined(__AVR__)
    // The record through a pointer register, not at its constant address:
    // its bytes read and written with displacements (2 bytes of flash an
    // access) instead of absolute ones (4), about 60 of millis64()'s 194 B.
    __asm__("" : "+e"(p));
#endif
    Clock64& c = *p;
    if (now32 < c.last) ++c.high;
    c.last = now32;
    // (high << 32) | now32 is the record itself on a little-endian target
    // (fsw_config.h), read without the 64-bit shift an 8-bit MCU calls a
    // library routine for.
    uint64_t t;
    memcpy(&t, &c, sizeof t);
    return t;
}

}  // namespace fsw

#endif  // FSW_CLOCK_H
