// Basic vocabulary of the runtime: the evaluation type Real, result codes,
// element types, and flash-table helpers shared by every other file.
#ifndef FSW_TYPES_H
#define FSW_TYPES_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "fsw_config.h"

#if FSW_USE_PROGMEM
#include <avr/pgmspace.h>
#endif

// A function whose result code must not be dropped by its caller.
#define FSW_MUST_CHECK __attribute__((warn_unused_result))

// Keeps a rarely taken, sizeable routine out of line (LTO would copy it into
// each caller: flash matters more than a call on the slow path).
#define FSW_NOINLINE __attribute__((noinline))

// Keeps the compiler from specialising a function for a constant argument
// (on AVR a clone for one object's address turns its short pointer-relative
// accesses into 4-byte absolute ones). GCC only.
#if defined(__GNUC__) && !defined(__clang__)
#define FSW_NOCLONE __attribute__((noclone))
#else
#define FSW_NOCLONE
#endif

// Marks a constant table that lives in flash on AVR (read with flash_read).
#if FSW_USE_PROGMEM
#define FSW_FLASH PROGMEM
#else
#define FSW_FLASH
#endif

// RAM the C runtime does not clear at boot (AVR: .noinit), for what a
// reset must not erase (fsw_resume.h). Hosts have no reset: plain RAM.
#if defined(__AVR__)
#define FSW_NOINIT __attribute__((section(".noinit")))
#else
#define FSW_NOINIT
#endif

namespace fsw {

// The machine's evaluation type R (spec 4.5).
#if FSW_REAL_IS_FLOAT
typedef float Real;
#else
typedef double Real;
#endif

// Result codes. kOk is zero so `if (r != kOk)` reads naturally.
enum Result : uint8_t {
    kOk = 0,
    kErrTime = 1,       // G did not strictly increase since the previous step
    kErrFault = 2,      // a task's step reported a fault (generic code)
    kErrConfig = 3,     // a table or argument is invalid (divider 0, bad type)
    kErrRange = 4,      // an offset or length falls outside the state vector
};

// Element types of the languages (spec 2); values are stable (telemetry).
enum ElemType : uint8_t {
    kI8 = 0, kI16 = 1, kI32 = 2, kI64 = 3,
    kU8 = 4, kU16 = 5, kU32 = 6, kU64 = 7,
    kF32 = 8, kF64 = 9, kBool = 10,
};

// Size in bytes of an element type (0 for an unknown type): a power of two
// from the type's code (I8..I64 and U8..U64 are 1, 2, 4, 8 in order), a
// shift rather than a chain of compares.
constexpr uint8_t elem_size(uint8_t t) {
    return static_cast<uint8_t>(t > kBool ? 0u : t == kBool ? 1u : 1u << (t >= kF32 ? t - 6u : t & 3u));
}
static_assert(elem_size(kI8) == 1 && elem_size(kI16) == 2 && elem_size(kI32) == 4 && elem_size(kI64) == 8 &&
                  elem_size(kU8) == 1 && elem_size(kU16) == 2 && elem_size(kU32) == 4 && elem_size(kU64) == 8 &&
                  elem_size(kF32) == 4 && elem_size(kF64) == 8 && elem_size(kBool) == 1 && elem_size(11) == 0 &&
                  elem_size(255) == 0,
              "element sizes (spec 2)");

// Offsets into the state vector are 16 bits; this one means "no element".
typedef uint16_t ElemOff;
static const ElemOff kNoElement = 0xFFFFu;

// Index type of rolling windows (see FSW_WINDOW_INDEX_BITS).
#if FSW_WINDOW_INDEX_BITS == 16
typedef uint16_t WinIdx;
#else
typedef uint32_t WinIdx;
#endif

// Copies a constant table entry (marked FSW_FLASH) into RAM.
inline void flash_read(void* dst, const void* src, size_t n) {
#if FSW_USE_PROGMEM
    memcpy_P(dst, src, n);
#else
    memcpy(dst, src, n);
#endif
}

// A register named as changed, at a function's start: the registers the
// function saves then make one run from some register up to r17, and Y,
// which is what -mcall-prologues needs to save them through the shared
// routine (__prologue_saves__: 10 B of flash and as many back), where with
// a gap (avr-gcc's register allocation left r12 unused, say) it pushes and
// pops each in place, 4 B a register. The routine costs about 30 CPU
// cycles a call more: only where a function's listing shows such a gap
// and it does not run every cycle (send_batch: 40 B of flash, 0.8 us a
// cycle on the demo flight; roll_avg_push would give 20 B for 2.8 us: not
// used). At worst one more register saved. (AVR only.)
#define FSW_SAVES_IN_RUN(reg) __asm__ __volatile__("" ::: reg)

// `p` as the compiler no longer knows it: a static object that LTO inlines
// a function on (the executor, the link, in main()) is then addressed
// through a pointer register, its fields at displacements (ldd/std: 2 bytes
// of flash an access, as fast) rather than at their absolute addresses
// (lds/sts: 4 bytes).
template <class T>
inline T* by_pointer(T* p) {
#if defined(__AVR__)
    __asm__("" : "+e"(p));
#endif
    return p;
}

// One byte of a constant table (marked FSW_FLASH): a single load, no copy routine.
inline uint8_t flash_u8(const uint8_t* p) {
#if FSW_USE_PROGMEM
    return pgm_read_byte(p);
#else
    return *p;
#endif
}

// One field of a constant table entry (marked FSW_FLASH) of 1, 2 or 4
// bytes (an integer, an offset, a pointer): one or two word loads inline
// where flash_read would call the copy routine for the whole entry.
template <class T>
inline T flash_get(const T& field) {
#if FSW_USE_PROGMEM
    static_assert(sizeof(T) == 1 || sizeof(T) == 2 || sizeof(T) == 4, "flash_get reads 1, 2 or 4 bytes");
    T v;
    if (sizeof(T) == 1) {
        const uint8_t b = pgm_read_byte(&field);
        memcpy(&v, &b, 1);
    } else if (sizeof(T) == 2) {
        const uint16_t w = pgm_read_word(&field);
        memcpy(&v, &w, 2);
    } else {
        const uint32_t d = pgm_read_dword(&field);
        memcpy(&v, &d, sizeof v);
    }
    return v;
#else
    return field;
#endif
}

}  // namespace fsw

#endif  // FSW_TYPES_H
