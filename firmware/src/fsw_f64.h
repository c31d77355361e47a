// Software conversion between binary64 bit patterns and binary32, for
// boards whose `double` is 32 bits (F64 elements are still 8 bytes there).
#ifndef FSW_F64_H
#define FSW_F64_H

#include "fsw_types.h"

namespace fsw {

// binary64 bits -> binary32, correctly rounded (round to nearest, ties to
// even): too large -> +-inf, too small -> +-0 or a binary32 subnormal,
// NaN -> a quiet NaN of the same sign.
float f32_from_f64_bits(uint64_t bits);

// binary32 -> binary64 bits, exact (every binary32 value, subnormals
// included, is a binary64 value; NaN keeps its sign and payload).
uint64_t f64_bits_from_f32(float v);

// Same two conversions on raw binary32 bit patterns.
uint32_t f32_bits_from_f64_bits(uint64_t bits);
uint64_t f64_bits_from_f32_bits(uint32_t bits);

}  // namespace fsw

#endif  // FSW_F64_H
