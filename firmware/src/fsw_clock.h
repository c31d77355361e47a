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

// Extends a new 32-bit reading; a reading below the previous one is a wrap.
// Not re-entrant: call from one context (the executor's loop).
inline uint64_t clock64_extend(Clock64& c, uint32_t now32) {
    if (now32 < c.last) ++c.high;
    c.last = now32;
    return (static_cast<uint64_t>(c.high) << 32) | now32;
}

}  // namespace fsw

#endif  // FSW_CLOCK_H
