// Typed access to packed, little-endian element bytes (state vector or
// locals) by pointer: raw load/store, and read_X/write_X through Real.
#ifndef FSW_ELEMENT_H
#define FSW_ELEMENT_H

#include "fsw_convert.h"

namespace fsw {

// Raw access, safe at any alignment: memcpy into a local compiles to plain
// loads and stores. T is an integer type, float, or (host) double.
template <typename T>
inline T load(const uint8_t* p) {
    T v;
    memcpy(&v, p, sizeof v);
    return v;
}
template <typename T>
inline void store(uint8_t* p, T v) {
    memcpy(p, &v, sizeof v);
}
// bool elements are one byte; any non-zero byte reads as true.
inline bool load_bool(const uint8_t* p) { return *p != 0; }
inline void store_bool(uint8_t* p, bool v) { *p = v ? 1 : 0; }

// ---- element -> Real (reads, spec 4.5) -------------------------------------
inline Real read_I8(const uint8_t* p) { return real_from_I8(load<int8_t>(p)); }
inline Real read_I16(const uint8_t* p) { return real_from_I16(load<int16_t>(p)); }
inline Real read_I32(const uint8_t* p) { return real_from_I32(load<int32_t>(p)); }
inline Real read_I64(const uint8_t* p) { return real_from_I64(load<int64_t>(p)); }
inline Real read_U8(const uint8_t* p) { return real_from_U8(*p); }
inline Real read_U16(const uint8_t* p) { return real_from_U16(load<uint16_t>(p)); }
inline Real read_U32(const uint8_t* p) { return real_from_U32(load<uint32_t>(p)); }
inline Real read_U64(const uint8_t* p) { return real_from_U64(load<uint64_t>(p)); }
#if defined(__AVR__)
// Out of line on AVR, with the NaN test on the bits: a call is 8 bytes of
// code where the inline read, a float compare routine's call and the select
// are about 30, and the bit test is faster than the compare (with write_F32,
// about 0.9 KB of the rocket's flash).
FSW_NOINLINE FSW_NOCLONE Real read_F32(const uint8_t* p);
#else
inline Real read_F32(const uint8_t* p) { return real_from_F32(load<float>(p)); }
#endif
inline Real read_F64(const uint8_t* p) {
#if FSW_F64_SOFT
    // Straight from the bytes: no 64-bit value on an 8-bit MCU.
    const uint32_t u = f32_bits_from_f64_bytes(p);
    float f;
    memcpy(&f, &u, sizeof f);
    return f == f ? f : 0.0f;
#else
    return real_from_F64_bits(load<uint64_t>(p));
#endif
}
inline Real read_bool(const uint8_t* p) { return real_from_bool(load_bool(p)); }

// ---- Real -> element (assignments, spec 4.5) -------------------------------
inline void write_I8(uint8_t* p, Real r) { store<int8_t>(p, I8_from_real(r)); }
inline void write_I16(uint8_t* p, Real r) { store<int16_t>(p, I16_from_real(r)); }
inline void write_I32(uint8_t* p, Real r) { store<int32_t>(p, I32_from_real(r)); }
inline void write_I64(uint8_t* p, Real r) { store<int64_t>(p, I64_from_real(r)); }
inline void write_U8(uint8_t* p, Real r) { *p = U8_from_real(r); }
inline void write_U16(uint8_t* p, Real r) { store<uint16_t>(p, U16_from_real(r)); }
inline void write_U32(uint8_t* p, Real r) { store<uint32_t>(p, U32_from_real(r)); }
inline void write_U64(uint8_t* p, Real r) { store<uint64_t>(p, U64_from_real(r)); }
// write_F32_read: write_F32, returning what read_F32(p) then reads (a NaN
// stored as +0 reads +0): generated step code keeps it for the statements
// after the assignment that read the variable again, with no read of their
// own (autocode/emit/machine.py).
#if defined(__AVR__)
// Out of line on AVR, as read_F32: one routine for both, which takes the
// value first, where the float routines leave their result (r22..r25), the
// place second, and returns what it stored (in those same registers, so it
// costs write_F32 nothing): a value computed just before the write goes
// in as it is (with the place first, each call moved it down to r20..r23
// first, 4 bytes of flash a call), and write_F32_read is the same code.
FSW_NOINLINE FSW_NOCLONE Real f32_write_back(Real r, uint8_t* p);
inline void write_F32(uint8_t* p, Real r) { (void)f32_write_back(r, p); }
inline Real write_F32_read(uint8_t* p, Real r) { return f32_write_back(r, p); }
#else
inline void write_F32(uint8_t* p, Real r) { store<float>(p, F32_from_real(r)); }
inline Real write_F32_read(uint8_t* p, Real r) {
    write_F32(p, r);
    return read_F32(p);
}
#endif
inline void write_F64(uint8_t* p, Real r) { store<uint64_t>(p, F64_bits_from_real(r)); }
inline void write_bool(uint8_t* p, Real r) { store_bool(p, bool_from_real(r)); }

// Run-time dispatch on an ElemType (for tables: I/O channels, uplink).
// Generated step code calls the typed functions above instead.
// The integer element at p (type <= kU64) widened to 8 little-endian bytes
// at b: sign-extended for a signed type, zero-extended for an unsigned one.
void elem_widen(const uint8_t* p, uint8_t type, uint8_t* b);
// The same by a switch over the typed conversions above: what read_elem
// and write_elem are where R is binary64, and the reference their binary32
// path is held to (tests/firmware/test_convert.cpp).
Real read_elem_typed(const uint8_t* p, uint8_t type);
void write_elem_typed(uint8_t* p, uint8_t type, Real r);
Real read_elem(const uint8_t* p, uint8_t type);
void write_elem(uint8_t* p, uint8_t type, Real r);
#if FSW_REAL_IS_FLOAT
// Their path for the integer types (type <= kU64), for a caller that
// takes the other types itself (the bytecode VM, which leaves out the
// float types its board has no element or local of: fsw_vm.h).
Real read_int_elem(const uint8_t* p, uint8_t type);
void write_int_elem(uint8_t* p, uint8_t type, Real r);
#endif

}  // namespace fsw

#endif  // FSW_ELEMENT_H
