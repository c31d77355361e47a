// The state-machine bookkeeping generated code calls out of line (spec 4.6):
// the 64-bit time arithmetic once in flash, whatever the number of machines.
#include "fsw_machine.h"

#include "fsw_element.h"

namespace fsw {

Result machine_begin(Machine& m, const uint8_t* g, uint8_t* s) {
    if (machine_begin_step(m, load<uint64_t>(g)) != kOk) return kErrTime;
    if (m.entering != 0) store<uint32_t>(s, m.state);
    return kOk;
}

#if defined(__AVR__)
uint32_t machine_T32(const Machine& m) {
    // The halves as bytes (little-endian): no 64-bit shift on an 8-bit MCU.
    const uint8_t* t = reinterpret_cast<const uint8_t*>(&m.t);
    return load<uint32_t>(t + 4) != 0 ? 0xFFFFFFFFUL : load<uint32_t>(t);
}
#endif

}  // namespace fsw
