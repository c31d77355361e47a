// Region copy-in/copy-out: bounds-checked, atomic when the lock is on.
#include "fsw_sv.h"

namespace fsw {

static bool span_ok(const StateVector& sv, uint16_t off, uint16_t len) {
    return static_cast<uint32_t>(off) + len <= sv.size;
}

Result sv_copy_out(const StateVector& sv, uint16_t off, uint16_t len, uint8_t* dst) {
    if (!span_ok(sv, off, len)) return kErrRange;
    if (sv.lock) {
        SvGuard<true> g;
        memcpy(dst, sv.bytes + off, len);
    } else {
        memcpy(dst, sv.bytes + off, len);
    }
    return kOk;
}

Result sv_copy_in(const StateVector& sv, uint16_t off, uint16_t len, const uint8_t* src) {
    if (!span_ok(sv, off, len)) return kErrRange;
    if (sv.lock) {
        SvGuard<true> g;
        memcpy(sv.bytes + off, src, len);
    } else {
        memcpy(sv.bytes + off, src, len);
    }
    return kOk;
}

Result region_copy_out(const StateVector& sv, const Region& r, uint8_t* dst) {
    return sv_copy_out(sv, r.off, r.size, dst);
}

Result region_copy_in(const StateVector& sv, const Region& r, const uint8_t* src) {
    return sv_copy_in(sv, r.off, r.size, src);
}

}  // namespace fsw
