// State vector support: the lock (spec 3 `lock` option) as a compile-time
// guard, region descriptors, and region copy-in/copy-out for telemetry.
#ifndef FSW_SV_H
#define FSW_SV_H

#include "fsw_element.h"
#include "fsw_pal.h"

namespace fsw {

// Scoped lock for element and region access. SvGuard<false> is empty and
// costs nothing; SvGuard<true> is a critical section (interrupts off on an
// MCU, a re-entrant lock on the host). Generated code declares
// `static const bool kSvLock = <lock option>;` and wraps each access:
//     { fsw::SvGuard<kSvLock> g; v = fsw::read_F64(sv + 8); }
template <bool kLock>
class SvGuard;

template <>
class SvGuard<false> {
public:
    SvGuard() {}
};

template <>
class SvGuard<true> {
public:
    SvGuard() : saved_(pal::critical_enter()) {}
    ~SvGuard() { pal::critical_exit(saved_); }

private:
    SvGuard(const SvGuard&);
    SvGuard& operator=(const SvGuard&);
    pal::IrqState saved_;
};

// A region: a contiguous run of elements, offset and size in bytes.
struct Region {
    ElemOff off;
    uint16_t size;
};

// A state vector: its bytes, its size, and whether the lock option is on.
// Generated code defines one as constant data.
struct StateVector {
    uint8_t* bytes;
    uint16_t size;
    bool lock;
};

// Copies `len` bytes at `off` out of (into) the state vector, atomically
// when the lock option is on. kErrRange when the span leaves the vector.
FSW_MUST_CHECK Result sv_copy_out(const StateVector& sv, uint16_t off, uint16_t len, uint8_t* dst);
FSW_MUST_CHECK Result sv_copy_in(const StateVector& sv, uint16_t off, uint16_t len, const uint8_t* src);
// Whole-region forms (regions are constant tables: pass a RAM copy).
FSW_MUST_CHECK Result region_copy_out(const StateVector& sv, const Region& r, uint8_t* dst);
FSW_MUST_CHECK Result region_copy_in(const StateVector& sv, const Region& r, const uint8_t* src);

}  // namespace fsw

#endif  // FSW_SV_H
