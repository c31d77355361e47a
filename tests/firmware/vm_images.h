// The images the VM suites build (test_vm.cpp: the verifier's rules;
// test_vm_step.cpp: the VM stepping them), over one state vector: G, S,
// x (F32), n (I16). Two programs, so that each fits an Uno's flash with
// the VM it tests.
#ifndef FSW_TEST_VM_IMAGES_H
#define FSW_TEST_VM_IMAGES_H
#include "test_support.h"
#if !defined(__AVR__)
#include "psl_native.h"
#endif

using namespace fsw;

// This program's VM: every feature but roll_median and F64 values, as on a
// board whose application has neither (test_feature_rules).
extern const uint16_t fsw::vm_features = kVmAllFeatures & ~(kVmFeatMedian | kVmFeatF64);


namespace {

// The state vector the images are bound to: G, S, x (F32), n (I16).
const VmElem kElems[] FSW_FLASH = {{0, kU64}, {8, kU32}, {12, kF32}, {16, kI16}};
const VmLayout kLayout = {kElems, 4, 0x12345678UL};
alignas(kVmRamAlign) uint8_t ram[128];

enum : uint8_t {
    END = 0x00, GOTO = 0x01, JMP = 0x02, JF = 0x03, AND = 0x04, OR = 0x05, CONST = 0x06, LDE = 0x07,
    STE = 0x08, LDL = 0x09, STL = 0x0A, LDT = 0x0B, ROLL = 0x0C, WPUSH = 0x0D, NEG = 0x10, ADD = 0x11,
    LT = 0x18, GT = 0x1A, NOT = 0x1E, TRUTH = 0x1F,
    JKEY = 0x20, JINT = 0x21, SETK = 0x22, IADD = 0x23, JCMP = 0x24,
};
// A typed instruction's variable: an element's byte offset (x at 12, n at
// 16), or a local's plus L0 << 8, or T; then its type.
const uint8_t L0 = 0x80, TLO = 0xFF, THI = 0xFF;
const uint16_t NO = 0xFFFFu;

// The good image's code. Blocks, at code offsets:
//   0  [A] .step: x > n: -> B; else l = l + l
//  25  [A] .exit: n = T
//  31  [B] .step: (x and l) or not l: -> A
//  55  prelude: push x into window 0 (roll_avg, N 4)
const uint8_t kCode[] = {
    LDE, 2, 0, kF32, LDE, 3, 0, kI16, GT, JF, 2, 0, GOTO, 1,  // 0..13
    LDL, 0, 0, LDL, 0, 0, ADD, STL, 0, 0, END,                 // 14..24 (l = l + l)
    LDT, STE, 3, 0, kI16, END,                                 // 25..30
    LDE, 2, 0, kF32, AND, 4, 0, LDL, 0, 0, TRUTH, OR, 4, 0,    // 31..44
    LDL, 0, 0, NOT, JF, 2, 0, GOTO, 0, END,                    // 45..54
    LDE, 2, 0, kF32, WPUSH, 0, END,                            // 55..61
};
const uint16_t kStep0 = 0, kExit0 = 25, kStep1 = 31, kPrelude = 55;

struct Image {
    uint8_t b[200];
    uint16_t len;
    uint16_t code;  // where the code starts in b
};

inline void put16(uint8_t* p, uint16_t v) {
    p[0] = static_cast<uint8_t>(v);
    p[1] = static_cast<uint8_t>(v >> 8);
}

// An image of the two states above with `code` (its blocks where `offs`,
// `prelude` say), one U8 local (initial 3) and one roll_avg over 4 samples.
inline void build(Image& im, const uint8_t* code, uint16_t n, const uint16_t offs[6], uint16_t prelude, uint8_t stack) {
    memset(im.b, 0, sizeof im.b);
    uint8_t* h = im.b;
    h[0] = 'F'; h[1] = 'S'; h[2] = 'M'; h[3] = 'B';
    h[4] = 3;
    h[5] = sizeof(Real);
    h[6] = 0;
    h[7] = stack;
    put16(h + 8, 0x5678);
    put16(h + 10, 0x1234);
    put16(h + 12, 4);  // elements
    put16(h + 14, 0);  // G, at 0
    put16(h + 16, 8);  // S, at 8
    h[18] = 2;         // states
    h[19] = 1;         // windows
    put16(h + 20, 1);  // locals
    put16(h + 22, 1);  // bytes of locals
    put16(h + 24, prelude);
    put16(h + 26, n);
    uint8_t* p = h + 28;
    for (int k = 0; k < 6; ++k, p += 2) put16(p, offs[k]);
    *p++ = kU8;  // local 0: U8 at 0
    put16(p, 0);
    p += 2;
    *p++ = 0;  // window 0: roll_avg, N 4
    *p++ = 0;
    put16(p, 4);
    p += 2;
    *p++ = 3;  // the local's initial value
    im.code = static_cast<uint16_t>(p - h);
    memcpy(p, code, n);
    im.len = static_cast<uint16_t>(im.code + n);
}

const uint16_t kOffs[6] = {NO, kStep0, kExit0, NO, kStep1, NO};

inline void good(Image& im) { build(im, kCode, sizeof kCode, kOffs, kPrelude, 2); }

inline VmReason verify(const Image& im) { return vm_verify(im.b, im.len, kLayout, sizeof ram); }

// The code of `good` with the byte at `at` (a code offset) set to `v`.
inline VmReason patched(uint16_t at, uint8_t v) {
    Image im;
    good(im);
    im.b[im.code + at] = v;
    return verify(im);
}

// An image whose state A's .step is `code` (ending the code but for the prelude).
inline void step_image(Image& im, const uint8_t* code, uint16_t n, uint8_t stack) {
    uint8_t all[120];
    memcpy(all, code, n);
    const uint8_t prelude[] = {LDE, 2, 0, kF32, WPUSH, 0, END};
    memcpy(all + n, prelude, sizeof prelude);
    const uint16_t offs[6] = {NO, 0, NO, NO, NO, NO};
    build(im, all, static_cast<uint16_t>(n + sizeof prelude), offs, n, stack);
}

inline VmReason with_step(const uint8_t* code, uint16_t n, uint8_t stack) {
    Image im;
    step_image(im, code, n, stack);
    return verify(im);
}

}  // namespace

#endif  // FSW_TEST_VM_IMAGES_H
