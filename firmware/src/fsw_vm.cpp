// The bytecode verifier and VM (docs/bytecode.md): one linear pass that
// checks an image, and a step that runs it over the runtime's own helpers
// (fsw_element.h, fsw_window.h, fsw_machine.h), so its bits are a generated
// machine's.
#include "fsw_vm.h"

#include "fsw_convert.h"
#include "fsw_element.h"
#include "fsw_pal.h"
#include "fsw_sv.h"
#include "fsw_window.h"

namespace fsw {

namespace {

// ---- the format (docs/bytecode.md, "The image") --------------------------------
const uint8_t kVersion = 3;
const uint16_t kHeader = 28;
const uint16_t kNone = 0xFFFFu;  // a state without this block
const uint8_t kFlagLock = 1;

enum Op : uint8_t {
    kEnd = 0x00, kGoto = 0x01, kJmp = 0x02, kJf = 0x03, kAnd = 0x04, kOr = 0x05,
    kConst = 0x06, kLde = 0x07, kSte = 0x08, kLdl = 0x09, kStl = 0x0A, kLdt = 0x0B,
    kRoll = 0x0C, kWpush = 0x0D,
    kNeg = 0x10, kAdd = 0x11, kSub = 0x12, kMul = 0x13, kDiv = 0x14,
    kLt = 0x18, kLe = 0x19, kGt = 0x1A, kGe = 0x1B, kEq = 0x1C, kNe = 0x1D,
    kNot = 0x1E, kTruth = 0x1F,
    // typed tests and stores (the generated code's fast paths; version 2)
    kJKey = 0x20, kJInt = 0x21, kSetK = 0x22, kIAdd = 0x23, kJCmp = 0x24,
};

// A typed instruction's variable (version 3): where it is, u16, and its
// type, u8: an element's byte offset in the state vector (below kRefLocal),
// a local's byte offset in the locals plus kRefLocal, or kRefT (T, kJInt
// only, with U64's type): the VM adds the offset to the state vector's or the
// locals' address, with no table to read.
const uint16_t kRefLocal = 0x8000u;
const uint16_t kRefT = 0xFFFFu;
const uint8_t kTypeT = 0xFE;   // ref_type's type of T
const uint8_t kVarBytes = 3;   // where, type
const uint8_t kJumpIf = 0x80;  // kJInt/kJCmp: jump when the test holds (else when it fails)
const uint8_t kKeyInclusive = 1, kKeyJumpIf = 2;  // kJKey's flags

inline bool is_int(uint8_t t) { return t <= kU64; }

// elem_size() of a type the verifier has checked, from a table in flash
// (no call, no shift loop on an AVR). (Forced inline: -Os would call these
// few instructions.)
#define FSW_VM_INLINE inline __attribute__((always_inline))
const uint8_t kSizes[kBool + 1] FSW_FLASH = {1, 2, 4, 8, 1, 2, 4, 8, 4, 8, 1};
FSW_VM_INLINE uint8_t size_of(uint8_t t) { return flash_get(kSizes[t]); }

// The order of x and c as one bit (the order functions' answer): x < c,
// x == c, x > c, unordered (a NaN).
const uint8_t kBelow = 1, kEqual = 2, kAbove = 4, kUnordered = 8;
// The comparisons' truth over that order: the bits of the orders for which
// each holds (<, <=, >, >=, ==, != in kLt..kNe's order).
const uint8_t kCmpMask[6] FSW_FLASH = {1, 3, 4, 6, 2, 5 | 8};  // != also holds unordered
FSW_VM_INLINE bool cmp_holds(uint8_t cmp, uint8_t order) {
    return (flash_get(kCmpMask[cmp & 7u]) & order) != 0;  // (a bit by a test, no shift loop on an AVR)
}

// N is 16 bits in the image: every runtime holds a window of 65535 samples.
static_assert(FSW_WINDOW_MAX_N >= 65535UL, "window sizes of the image");

enum WinFunc : uint8_t { kAvg = 0, kMin = 1, kMax = 2, kRange = 3, kMedian = 4 };

// Whether the VM was built with feature `f` (vm_features: a constant the
// application defines, so each test folds and the code of a feature the
// board does not have is dropped).
FSW_VM_INLINE bool has(uint16_t f) { return (vm_features & f) != 0; }
// Whether it takes values of type t (kVmNoFeature otherwise): U32, U64 and
// bool always (every layout has G and S), the others as built.
inline bool takes(uint8_t t) {
    switch (t) {
        case kI8: return has(kVmFeatI8);
        case kI16: return has(kVmFeatI16);
        case kI32: return has(kVmFeatI32);
        case kI64: return has(kVmFeatI64);
        case kU8: return has(kVmFeatU8);
        case kU16: return has(kVmFeatU16);
        case kF32: return has(kVmFeatF32);
        case kF64: return has(kVmFeatF64);
        default: return true;
    }
}
// Whether an integer of type t (a verified one) is signed: never where the
// VM takes no signed type.
FSW_VM_INLINE bool is_signed(uint8_t t) { return has(kVmFeatSigned) && t < kU8; }
// An element or local of a verified type read as R, and R written to one:
// read_elem and write_elem without the float types the VM was built
// without (their conversions, software binary64 on an AVR, go with them).
Real vm_read(const uint8_t* p, uint8_t t) {
#if FSW_REAL_IS_FLOAT
    if (t <= kU64) return read_int_elem(p, t);
    if (t == kF32 && has(kVmFeatF32)) return read_F32(p);
    if (t == kF64 && has(kVmFeatF64)) return read_F64(p);
    return read_bool(p);
#else
    return read_elem(p, t);
#endif
}
void vm_write(uint8_t* p, uint8_t t, Real r) {
#if FSW_REAL_IS_FLOAT
    if (t <= kU64) write_int_elem(p, t, r);
    else if (t == kF32 && has(kVmFeatF32)) write_F32(p, r);
    else if (t == kF64 && has(kVmFeatF64)) write_F64(p, r);
    else write_bool(p, r);
#else
    write_elem(p, t, r);
#endif
}

// The bytes of a float variable of type t (kJKey's, verified F32 or F64):
// a constant where the VM takes only one of them.
FSW_VM_INLINE uint8_t float_bytes(uint8_t t) {
    return !has(kVmFeatF32) ? 8 : !has(kVmFeatF64) ? 4 : t == kF64 ? 8 : 4;
}

inline uint16_t u16(const uint8_t* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }
inline uint32_t u32(const uint8_t* p) {
    return static_cast<uint32_t>(u16(p)) | (static_cast<uint32_t>(u16(p + 2)) << 16);
}

template <class Im>
inline uint16_t r16(const Im& im, uint16_t i) { return static_cast<uint16_t>(im[i] | (im[i + 1u] << 8)); }
template <class Im>
inline uint32_t r32(const Im& im, uint16_t i) {
    return static_cast<uint32_t>(r16(im, i)) | (static_cast<uint32_t>(r16(im, static_cast<uint16_t>(i + 2u))) << 16);
}

// Where the parts of an image start, as offsets into it: 16 bits, valid
// once the header was checked (the image's `total` bytes, which the header
// check compares with its length, at most 65535: every part lies within).
// The index arithmetic of the pass stays 16-bit, which on an 8-bit MCU is
// half the code of 32-bit sums.
struct Offs {
    uint8_t states, windows;
    uint16_t locals, loc_size, prelude, code_size;
    uint16_t loc;    // locals: type (u8), offset (u16); the states' entry, step, exit offsets are at kHeader
    uint16_t win;    // windows: function (u8), 0 (u8), N (u16)
    uint16_t code;   // the locals' initial bytes end here
    uint32_t total;  // bytes the header says the image has
};

template <class Im>
void offsets(const Im& im, Offs& o) {
    o.states = im[18];
    o.windows = im[19];
    o.locals = r16(im, 20);
    o.loc_size = r16(im, 22);
    o.prelude = r16(im, 24);
    o.code_size = r16(im, 26);
    const uint32_t loc = kHeader + 6u * o.states, win = loc + 3u * static_cast<uint32_t>(o.locals),
                   code = win + 4u * o.windows + o.loc_size;
    o.loc = static_cast<uint16_t>(loc);
    o.win = static_cast<uint16_t>(win);
    o.code = static_cast<uint16_t>(code);
    o.total = code + o.code_size;
}

// The same, as pointers into an image in RAM (the step's view).
struct Parts {
    uint8_t states, windows;
    uint16_t locals, loc_size, prelude, code_size;
    const uint8_t* st;
    const uint8_t* loc;
    const uint8_t* win;
    const uint8_t* init;
    const uint8_t* code;
};

// The parts a step reads: the header read again each step costs less than
// the RAM to keep it in. (A verified image's parts all lie within its at
// most 65535 bytes: 16-bit sums, as offsets() has them in 32 bits for an
// image not yet checked.)
inline void step_parts(const uint8_t* im, Parts& p) {
    p.states = im[18];
    p.windows = im[19];
    p.prelude = u16(im + 24);
    p.st = im + kHeader;
    p.loc = p.st + 6u * p.states;
    p.win = p.loc + 3u * u16(im + 20);
    p.code = p.win + 4u * p.windows + u16(im + 22);
}

// All of them.
void parts(const uint8_t* im, Parts& p) {
    step_parts(im, p);
    p.locals = u16(im + 20);
    p.loc_size = u16(im + 22);
    p.code_size = u16(im + 26);
    p.init = p.code - p.loc_size;
}

// Storage of a window of n samples in the VM's RAM: the state struct and its
// arrays, as the typed wrappers of fsw_window.h lay them, with WinIdx indices.
const uint32_t kAlign = kVmRamAlign;
inline uint32_t up(uint32_t x) { return (x + kAlign - 1u) / kAlign * kAlign; }
inline uint32_t ext_size(uint32_t n) {
    return up(sizeof(RollExtS<WinIdx>)) + up(n * sizeof(Real)) + up(n * sizeof(WinIdx));
}
// 0 for a function the VM was built without (an image that has one is
// refused before its windows are summed).
uint32_t window_size(uint8_t func, uint32_t n) {
    if (func == kAvg && has(kVmFeatAvg)) return up(sizeof(RollAvgS<WinIdx>)) + up(n * sizeof(Real));
    if ((func == kMin && has(kVmFeatMin)) || (func == kMax && has(kVmFeatMax))) return ext_size(n);
    if (func == kRange && has(kVmFeatRange)) return 2u * ext_size(n);
    if (func == kMedian && has(kVmFeatMedian)) return up(sizeof(RollMedianS<WinIdx>)) + 2u * up(n * sizeof(Real));
    return 0;
}

template <class Im>
uint32_t windows_size(const Im& im, const Offs& o) {
    uint32_t size = 0;
    if (!has(kVmFeatWindows)) return size;
    for (uint8_t w = 0; w < o.windows; ++w) {
        const uint16_t at = static_cast<uint16_t>(o.win + 4u * w);
        size += window_size(im[at], r16(im, static_cast<uint16_t>(at + 2u)));
    }
    return size;
}
// The windows' bytes of a verified image, from its table at `win`.
FSW_NOINLINE uint32_t ram_of_windows(const uint8_t* win, uint8_t windows) {
    uint32_t size = 0;
    for (uint8_t w = 0; w < windows; ++w) size += window_size(win[4u * w], u16(win + 4u * w + 2u));
    return size;
}
uint32_t windows_size(const Parts& p) {
    return has(kVmFeatWindows) ? ram_of_windows(p.win, p.windows) : 0;  // (a verified image has none without)
}

// Bytes of a typed instruction's operands after its variable of type `t`
// (kTypeT: T): a test's flags or comparison, its constant and its jump
// offset; kSetK's value; kIAdd's source and constant.
inline uint8_t typed_operands(uint8_t op, uint8_t t) {
    if (op == kIAdd) return kVarBytes + 4;
    const uint8_t size = t == kTypeT ? 4u : op == kJKey ? float_bytes(t) : elem_size(t);
    return op == kSetK ? size : static_cast<uint8_t>(1u + size + 2u);
}

// The reason that refuses `ref` where its type does not fit the instruction.
inline VmReason wrong_type(uint16_t ref) { return ref >= kRefLocal && ref != kRefT ? kVmBadLocal : kVmBadElement; }

// Whether the image's state vector is locked: never where the VM has no
// lock (the header's check refuses such an image before its code).
template <class Im>
FSW_VM_INLINE bool locked(const Im& im) { return has(kVmFeatLock) && (im[6] & kFlagLock) != 0; }

// The layout's first element at byte offset `off` (layout.count: none).
uint16_t elem_at(const VmLayout& layout, uint16_t off) {
    uint16_t e = 0;
    while (e < layout.count && flash_get(layout.elems[e].off) != off) ++e;
    return e;
}

// Why the typed instruction's variable `ref` of type `t` may not be (kVmOk:
// it may), and its type (kTypeT for T): T's type is U64's; an element's
// offset and type must be an element's of the layout (the first at that
// offset); a local's type one the VM takes, its bytes within the locals'.
// An image whose state vector is locked (kFlagLock) reads and writes
// elements through the general instructions, which take the lock. (One
// function for both readers of the image.)
FSW_NOINLINE VmReason var_rule(uint16_t loc_size, const VmLayout& layout, bool lock, uint16_t ref, uint8_t& t) {
    if (ref == kRefT) {
        if (t != kU64) return kVmBadElement;
        t = kTypeT;
    } else if (ref >= kRefLocal) {
        const uint8_t n = elem_size(t);
        const uint16_t off = static_cast<uint16_t>(ref - kRefLocal);  // (16-bit: unsigned on an AVR)
        if (n == 0 || n > loc_size || off > loc_size - n) return kVmBadLocal;
        if (!takes(t)) return kVmNoFeature;
    } else {
        if (lock) return kVmBadElement;
        const uint16_t e = elem_at(layout, ref);
        if (e == layout.count || flash_get(layout.elems[e].type) != t) return kVmBadElement;
    }
    return kVmOk;
}

// The typed instruction's variable at `a`: its operand, its type, and the
// rule's answer.
template <class Im>
VmReason ref_type(const Im& im, const Offs& p, const VmLayout& layout, uint16_t a, bool lock, uint8_t& t,
                  uint16_t& ref) {
    ref = r16(im, a);
    t = im[static_cast<uint16_t>(a + 2u)];
    return var_rule(p.loc_size, layout, lock, ref, t);
}

// ---- the verifier: one pass over the image, resumable -------------------------
// The pass goes through phases; its state between two calls is a VmCheck.
// A unit of work (a local, a window, a block offset, the block offsets of
// a state compared to pc, an instruction) is never cut: a call stops
// between two of them once its reader has read `budget` bytes.
enum CheckPhase : uint8_t { kChHeader = 0, kChLocals, kChWindows, kChOffsets, kChCode };
// VmCheck::flags in the code
const uint8_t kReachable = 1;  // the next instruction can be reached
const uint8_t kAtStart = 2;    // a block starts at pc
const uint8_t kMayMove = 4;    // the block may transition (an entry or step block)
const uint8_t kPrelude = 8;    // the block is the prelude
const uint8_t kScanned = 16;   // moving and still are pc's

// The header's fields, and where the parts lie.
template <class Im>
VmReason check_header(const Im& im, uint16_t len, const VmLayout& layout, Offs& p) {
    if (len < kHeader) return kVmBadSize;
    if (im[0] != 'F' || im[1] != 'S' || im[2] != 'M' || im[3] != 'B') return kVmBadMagic;
    if (im[4] != kVersion) return kVmBadVersion;
    if (im[5] != sizeof(Real)) return kVmBadReal;
    if ((im[6] & ~kFlagLock) != 0) return kVmBadVersion;
    if (r32(im, 8) != layout.schema || r16(im, 12) != layout.count) return kVmBadSchema;
    if ((im[6] & kFlagLock) != 0 && !has(kVmFeatLock)) return kVmNoFeature;  // (the schema holds the option)
    // Every type of the layout (a generated layout's always are: the VM's
    // code relies on it where it reads an element's type from the layout).
    if ((vm_features & kVmFeatTypes) != kVmFeatTypes)
        for (uint16_t e = 0; e < layout.count; ++e)
            if (!takes(flash_get(layout.elems[e].type))) return kVmNoFeature;
    offsets(im, p);
    if (p.total != len) return kVmBadSize;
    // G and S by their byte offsets (version 3), as a typed instruction's elements
    const uint16_t g = elem_at(layout, r16(im, 14)), s = elem_at(layout, r16(im, 16));
    if (g == layout.count || s == layout.count || flash_get(layout.elems[g].type) != kU64 ||
        flash_get(layout.elems[s].type) != kU32)
        return kVmBadElement;
    if (p.states == 0) return kVmBadState;
    return kVmOk;
}

// What the pass checks of each opcode (kOps), a byte each in flash rather
// than code each: its operand bytes (bits 0-1; kConst's are R's), the
// values it pops (bits 2-3) and pushes (bit 4), and the kind of its own
// rules (bits 5-7); kOpUnknown for no opcode.
enum OpKind : uint8_t {
    kKindPlain = 0, kKindEnd, kKindGoto, kKindJump, kKindTyped, kKindJCmp, kKindVar, kKindWindow
};
#define FSW_VM_OP(bytes, pops, pushes, kind) static_cast<uint8_t>((bytes) | (pops) << 2 | (pushes) << 4 | (kind) << 5)
const uint8_t kOpUnknown = 0xFF;  // (3 pops: no opcode's)
const uint8_t kOpInfo[kJCmp + 1] FSW_FLASH = {
    FSW_VM_OP(0, 0, 0, kKindEnd), FSW_VM_OP(1, 0, 0, kKindGoto),                                // END GOTO
    FSW_VM_OP(2, 0, 0, kKindJump), FSW_VM_OP(2, 1, 0, kKindJump),                               // JMP JF
    FSW_VM_OP(2, 1, 0, kKindJump), FSW_VM_OP(2, 1, 0, kKindJump),                               // AND OR
    FSW_VM_OP(0, 0, 1, kKindPlain),                                                             // CONST
    FSW_VM_OP(3, 0, 1, kKindVar), FSW_VM_OP(3, 1, 0, kKindVar),                                 // LDE STE
    FSW_VM_OP(2, 0, 1, kKindVar), FSW_VM_OP(2, 1, 0, kKindVar),                                 // LDL STL
    FSW_VM_OP(0, 0, 1, kKindPlain),                                                             // LDT
    FSW_VM_OP(1, 0, 1, kKindWindow), FSW_VM_OP(1, 1, 0, kKindWindow),                           // ROLL WPUSH
    kOpUnknown, kOpUnknown,
    FSW_VM_OP(0, 1, 1, kKindPlain),                                                             // NEG
    FSW_VM_OP(0, 2, 1, kKindPlain), FSW_VM_OP(0, 2, 1, kKindPlain),                             // ADD SUB
    FSW_VM_OP(0, 2, 1, kKindPlain), FSW_VM_OP(0, 2, 1, kKindPlain),                             // MUL DIV
    kOpUnknown, kOpUnknown, kOpUnknown,
    FSW_VM_OP(0, 2, 1, kKindPlain), FSW_VM_OP(0, 2, 1, kKindPlain), FSW_VM_OP(0, 2, 1, kKindPlain),  // LT LE GT
    FSW_VM_OP(0, 2, 1, kKindPlain), FSW_VM_OP(0, 2, 1, kKindPlain), FSW_VM_OP(0, 2, 1, kKindPlain),  // GE EQ NE
    FSW_VM_OP(0, 1, 1, kKindPlain), FSW_VM_OP(0, 1, 1, kKindPlain),                             // NOT TRUTH
    FSW_VM_OP(3, 0, 0, kKindTyped), FSW_VM_OP(3, 0, 0, kKindTyped),                             // JKEY JINT: the var,
    FSW_VM_OP(3, 0, 0, kKindTyped), FSW_VM_OP(3, 0, 0, kKindTyped),                             // SETK IADD: then its type's
    FSW_VM_OP(3, 2, 0, kKindJCmp),                                                              // JCMP
};
#undef FSW_VM_OP

// One instruction of the code (after the block offsets equal to pc were
// counted, when a block starts there or a jump lands there): kVmMore, or
// the pass's verdict once the code is over.
template <class Im>
uint8_t check_instruction(const Im& im, VmCheck& c, const Offs& p, const VmLayout& layout) {
    uint8_t& depth = c.depth;
    uint16_t pc = c.pc;
    if (pc >= p.code_size) {  // the end
        if (c.np != 0) return kVmBadJump;
        if ((c.flags & kAtStart) == 0) return kVmBadEnd;
        if (c.matched != c.declared) return kVmBadEnd;
        if (c.deepest != im[7]) return kVmBadStack;
        return kVmOk;
    }
    if ((c.flags & kAtStart) != 0) {  // a block starts here: what may it do?
        if (c.moving != 0 && c.still != 0) return kVmBadPlace;
        c.matched = static_cast<uint16_t>(c.matched + c.moving + c.still);
        c.flags = static_cast<uint8_t>(kReachable | (c.moving != 0 ? kMayMove : 0) | (p.prelude == pc ? kPrelude : 0));
        c.pushed = 0;
    }
    for (uint8_t k = 0; k < c.np;) {  // jumps landing here
        VmPending& j = c.pend[k];
        if (j.target < pc) return kVmBadJump;  // into an instruction
        if (j.target == pc) {
            if (c.moving != 0 || c.still != 0) return kVmBadJump;  // into another block
            if ((c.flags & kReachable) != 0 && depth != j.depth) return kVmBadStack;
            depth = j.depth;
            c.flags |= kReachable;
            j = c.pend[--c.np];
        } else {
            ++k;
        }
    }
    if ((c.flags & kReachable) == 0) return kVmBadEnd;
    const uint8_t op = im[p.code + pc];
    const uint8_t info = op < sizeof kOpInfo ? flash_get(kOpInfo[op]) : kOpUnknown;
    if (info == kOpUnknown) return kVmBadOpcode;
    const uint8_t n = op == kConst ? im[5] : static_cast<uint8_t>(info & 3u);  // (R's bytes: read where needed)
    if (n >= p.code_size - pc) return kVmBadOpcode;  // (pc < code_size)
    const uint16_t a = static_cast<uint16_t>(p.code + pc + 1u);  // the operands
    pc = static_cast<uint16_t>(pc + 1u + n);
    const uint8_t pops = static_cast<uint8_t>((info >> 2) & 3u), pushes = static_cast<uint8_t>((info >> 4) & 1u);
    uint8_t jump_depth = depth;
    uint16_t jump_at = 0;  // a jump's offset operand (0: the instruction does not jump)
    bool ends = false;
    const bool prelude = (c.flags & kPrelude) != 0;
    switch (info >> 5) {
        case kKindEnd: ends = true; break;
        case kKindGoto:
            if ((c.flags & kMayMove) == 0) return kVmBadPlace;
            if (im[a] >= p.states) return kVmBadState;
            ends = true;
            break;
        case kKindJump:
            if (depth < pops) return kVmBadStack;
            jump_at = a;
            // and/or keep their left operand when they jump; jf drops it.
            if (op == kJf) jump_depth = static_cast<uint8_t>(depth - 1u);
            if (op == kJmp) c.flags &= static_cast<uint8_t>(~kReachable);
            break;
        case kKindTyped: {
            if (depth != 0) return kVmBadStack;  // (the VM runs them outside the stack's code)
            // (each byte read once: the EEPROM verifier's reads a unit are bounded, fsw_vm.h)
            const bool lock = locked(im);
            uint16_t ref;
            uint8_t t;
            const VmReason why = ref_type(im, p, layout, a, lock, t, ref);
            if (why != kVmOk) return why;
            const bool fits = op == kJKey ? t == kF32 || t == kF64
                              : op == kJInt ? t == kTypeT || is_int(t) || t == kBool
                              : op == kSetK ? t != kTypeT
                                            : is_int(t);
            if (!fits) return wrong_type(ref);
            const uint16_t b = static_cast<uint16_t>(a + kVarBytes);  // the operands after the variable
            const uint8_t more = typed_operands(op, t);
            const uint8_t at = static_cast<uint8_t>(more - 2u);  // a test's jump offset, last
            if (more > p.code_size - pc) return kVmBadOpcode;  // (pc <= code_size)
            pc = static_cast<uint16_t>(pc + more);
            if (op == kSetK) {
                if (t == kBool && im[b] > 1u) return kVmBadOpcode;
            } else if (op == kIAdd) {
                uint16_t src;
                uint8_t ts;
                const VmReason w = ref_type(im, p, layout, b, lock, ts, src);
                if (w != kVmOk) return w;
                if (!is_int(ts)) return wrong_type(src);
                // |k| below 2^p (p = R's precision): every integer near k is exact in R.
                const int32_t k = static_cast<int32_t>(r32(im, static_cast<uint16_t>(b + kVarBytes)));
                if (im[5] == 4 && (k > 16777215L || k < -16777215L)) return kVmBadOpcode;
            } else {
                if (op == kJKey ? (im[b] & ~(kKeyInclusive | kKeyJumpIf)) != 0 : (im[b] & ~kJumpIf) > 5u)
                    return kVmBadOpcode;
                jump_at = static_cast<uint16_t>(b + at);
            }
            break;
        }
        case kKindJCmp:
            if ((im[a] & ~kJumpIf) > 5u) return kVmBadOpcode;
            if (depth < pops) return kVmBadStack;
            jump_at = static_cast<uint16_t>(a + 1u);
            jump_depth = static_cast<uint8_t>(depth - 2u);
            break;
        case kKindVar:
            if (op <= kSte) {  // an element
                const uint16_t e = r16(im, a);
                if (e >= layout.count || flash_get(layout.elems[e].type) != im[static_cast<uint16_t>(a + 2u)])
                    return kVmBadElement;
            } else if (r16(im, a) >= p.locals) {
                return kVmBadLocal;
            }
            break;
        case kKindWindow:
            if (op == kRoll) {
                if (im[a] >= p.windows || (prelude && im[a] >= c.pushed)) return kVmBadWindow;
            } else {
                if (!prelude) return kVmBadPlace;
                if (im[a] != c.pushed) return kVmBadWindow;
                ++c.pushed;
            }
            break;
        default: break;  // constants, T, arithmetic and comparisons: their pops and pushes alone
    }
    if (jump_at != 0) {  // a forward jump: its target and the depth there
        const uint16_t off = r16(im, jump_at);
        if (off >= p.code_size - pc) return kVmBadJump;  // (pc <= code_size)
        if (c.np == FSW_VM_PENDING) return kVmTooNested;
        c.pend[c.np].target = static_cast<uint16_t>(pc + off);
        c.pend[c.np].depth = jump_depth;
        ++c.np;
    }
    if (depth < pops) return kVmBadStack;
    depth = static_cast<uint8_t>(depth - pops + pushes);
    if (depth > c.deepest) c.deepest = depth;
    if (c.deepest > FSW_VM_STACK) return kVmBadStack;
    c.flags &= static_cast<uint8_t>(~(kAtStart | kScanned));
    if (ends) {
        if (depth != 0) return kVmBadStack;
        c.flags &= static_cast<uint8_t>(~kReachable);
        if (c.np == 0) {  // the block is over
            if (prelude && c.pushed != p.windows) return kVmBadWindow;
            c.flags |= kAtStart;
        }
    }
    c.pc = pc;
    c.i = 0;
    return kVmMore;
}

// The pass from where `c` left it, a unit of work at least, until its
// reader has read `budget` bytes (a RamImage counts none: to the end):
// kVmMore, or the verdict.
template <class Im>
uint8_t check(const Im& im, VmCheck& c, uint16_t len, const VmLayout& layout, uint32_t ram_len, uint16_t budget) {
    Offs p;
    if (c.phase == kChHeader) {
        const VmReason r = check_header(im, len, layout, p);
        if (r != kVmOk) return r;
        c.phase = kChLocals;
    } else {
        offsets(im, p);  // read again: 10 bytes a call, rather than 34 of RAM kept
    }
    for (bool first = true;; first = false) {
        if (!first && im.reads() >= budget) return kVmMore;  // (a unit a call at least: the check moves on)
        if (c.phase == kChLocals) {
            if (c.i < p.locals) {
                const uint16_t at = static_cast<uint16_t>(p.loc + 3u * c.i);
                const uint8_t t = im[at];
                const uint16_t off = r16(im, at + 1u);
                if (elem_size(t) == 0 || off > p.loc_size || elem_size(t) > p.loc_size - off) return kVmBadLocal;
                if (!takes(t)) return kVmNoFeature;
                ++c.i;
                continue;
            }
            c.phase = kChWindows;
            c.i = 0;
        } else if (c.phase == kChWindows) {
            if (c.i < p.windows) {
                const uint16_t at = static_cast<uint16_t>(p.win + 4u * c.i);
                const uint8_t func = im[at];
                const uint16_t n = r16(im, at + 2u);
                if (func > kMedian || im[at + 1u] != 0 || n == 0) return kVmBadWindow;
                if (!has(static_cast<uint16_t>(1u << func))) return kVmNoFeature;
                c.ram += window_size(func, n);
                ++c.i;
                continue;
            }
            c.phase = kChOffsets;
            c.i = 0;
            c.declared = p.prelude != kNone ? 1u : 0u;
        } else if (c.phase == kChOffsets) {
            if (c.i < 3u * p.states) {
                const uint16_t off = r16(im, static_cast<uint16_t>(kHeader + 2u * c.i));
                ++c.i;
                if (off == kNone) continue;
                if (off >= p.code_size) return kVmBadState;
                ++c.declared;
                continue;
            }
            if (p.prelude == kNone || p.prelude >= p.code_size) return kVmBadEnd;
            c.phase = kChCode;
            c.i = 0;
            c.flags = kReachable | kAtStart;
        } else {
            const uint16_t pc = c.pc;
            if ((c.flags & kScanned) == 0 && pc < p.code_size) {
                // The block offsets equal to pc, needed where a block starts
                // or a jump lands: a state's three a unit (exit blocks and
                // the prelude counted apart: they may not transition). Byte
                // by byte: an offset whose low byte differs costs one read,
                // which in an EEPROM is most of the cost.
                bool lands = (c.flags & kAtStart) != 0;
                for (uint8_t k = 0; k < c.np && !lands; ++k) lands = c.pend[k].target == pc;
                if (lands) {
                    if (c.i == 0) {
                        c.moving = 0;
                        c.still = p.prelude == pc ? 1u : 0u;
                    }
                    if (c.i < p.states) {
                        const uint8_t lo = static_cast<uint8_t>(pc), hi = static_cast<uint8_t>(pc >> 8);
                        uint16_t at = static_cast<uint16_t>(kHeader + 6u * c.i);
                        for (uint8_t k = 0; k < 3; ++k, at = static_cast<uint16_t>(at + 2u)) {
                            if (im[at] != lo || im[at + 1u] != hi) continue;
                            if (k < 2) ++c.moving;
                            else ++c.still;
                        }
                        ++c.i;
                        continue;
                    }
                } else {
                    c.moving = 0;
                    c.still = 0;
                }
                c.flags |= kScanned;
            }
            const uint8_t r = check_instruction(im, c, p, layout);
            if (r == kVmMore) continue;
            if (r != kVmOk) return r;
            if (c.ram + p.loc_size > ram_len) return kVmNoRam;
            return kVmOk;
        }
    }
}

// The verifier reads an image through a reader: in RAM (vm_verify), or in
// the EEPROM a loader keeps it in (vm_verify_eeprom, vm_check_eeprom), byte
// by byte, counting its reads.
struct RamImage {
    const uint8_t* im;
    uint8_t operator[](uint16_t i) const { return im[i]; }
    uint16_t reads() const { return 0; }
};
struct EepromImage {
    uint16_t base;
    mutable uint16_t n;
    uint8_t operator[](uint16_t i) const {
        ++n;
        return pal::eeprom_read(static_cast<uint16_t>(base + i));
    }
    uint16_t reads() const { return n; }
};

}  // namespace

uint32_t vm_ram_size(const uint8_t* image, uint16_t len) {
    if (len < kHeader) return 0;
    Offs o;
    offsets(RamImage{image}, o);
    if (o.total > len) return 0;
    return windows_size(RamImage{image}, o) + o.loc_size;
}

void vm_check_begin(VmCheck& c) { memset(&c, 0, sizeof c); }

VmReason vm_verify(const uint8_t* im, uint16_t len, const VmLayout& layout, uint32_t ram_len) {
    VmCheck c;
    vm_check_begin(c);
    return static_cast<VmReason>(check(RamImage{im}, c, len, layout, ram_len, 1));  // reads none: to the end
}

uint8_t vm_check_eeprom(VmCheck& c, uint16_t addr, uint16_t len, const VmLayout& layout, uint32_t ram_len,
                        uint16_t budget) {
    return check(EepromImage{addr, 0}, c, len, layout, ram_len, budget);
}

VmReason vm_verify_eeprom(uint16_t addr, uint16_t len, const VmLayout& layout, uint32_t ram_len) {
    VmCheck c;
    vm_check_begin(c);
    uint8_t r;
    do {
        r = vm_check_eeprom(c, addr, len, layout, ram_len, 0xFFFFu);
    } while (r == kVmMore);
    return static_cast<VmReason>(r);
}

uint8_t* vm_locals(const uint8_t* image, uint8_t* ram) {
    Parts p;
    parts(image, p);
    return ram + windows_size(p);
}

void vm_reset(const uint8_t* image, uint8_t* ram, Machine& m, uint32_t initial) {
    Parts p;
    parts(image, p);
    const uint32_t wsize = windows_size(p);
    memset(ram, 0, static_cast<size_t>(wsize));  // every window empty: all-zero state
    memcpy(ram + wsize, p.init, p.loc_size);
    machine_reset(m, initial);
}

namespace {

// What one step of a verified image works on: the parts it reads, as
// pointers (the header read again each step costs less than the RAM to
// keep them).
struct Run {
    const uint8_t* code;
    const uint8_t* loc;   // the locals' table: type (u8), offset (u16)
    const uint8_t* win;   // the windows' table: function (u8), 0, N (u16)
    const VmElem* elems;  // the layout's element table (FSW_FLASH)
    uint8_t* sv;
    uint8_t* ram;
    uintptr_t local_ref;  // the locals' address in ram less kRefLocal: a typed local's at local_ref + its operand
    Machine* m;
    bool lock;
};

uint8_t* window_at(const Run& r, uint8_t w, uint8_t& func, uint16_t& n) {
    uint8_t* at = r.ram + ram_of_windows(r.win, w);  // the windows before it
    func = r.win[4u * w];
    n = u16(r.win + 4u * w + 2u);
    return at;
}

Real ext_value(uint8_t* at) {
    return roll_ext_value(*reinterpret_cast<RollExtS<WinIdx>*>(at),
                          reinterpret_cast<Real*>(at + up(sizeof(RollExtS<WinIdx>))));
}

void ext_push(uint8_t* at, uint16_t n, bool max, Real x) {
    RollExtS<WinIdx>& s = *reinterpret_cast<RollExtS<WinIdx>*>(at);
    Real* vals = reinterpret_cast<Real*>(at + up(sizeof s));
    WinIdx* seqs = reinterpret_cast<WinIdx*>(at + up(sizeof s) + up(n * static_cast<uint32_t>(sizeof(Real))));
    if (max) roll_max_push<WinIdx>(s, vals, seqs, n, x);
    else roll_min_push<WinIdx>(s, vals, seqs, n, x);
}

// A window's value and push, each function's code only where the VM was
// built with it (a verified image has no other).
Real window_value(const Run& r, uint8_t w) {
    uint8_t func;
    uint16_t n;
    uint8_t* at = window_at(r, w, func, n);
    if (func == kAvg && has(kVmFeatAvg)) {
        // A power-of-two N multiplies by 1/N once full, as RollAvgN does.
        const Real inv = (n & (n - 1u)) == 0 ? Real(1) / Real(n) : Real(0);
        return roll_avg_mean<WinIdx>(*reinterpret_cast<RollAvgS<WinIdx>*>(at), n, inv);
    }
    if ((func == kMin && has(kVmFeatMin)) || (func == kMax && has(kVmFeatMax))) return ext_value(at);
    if (func == kRange && has(kVmFeatRange)) return ext_value(at) - ext_value(at + ext_size(n));
    if (func == kMedian && has(kVmFeatMedian))
        return roll_median_value<WinIdx>(*reinterpret_cast<RollMedianS<WinIdx>*>(at),
                                         reinterpret_cast<Real*>(at + up(sizeof(RollMedianS<WinIdx>)) +
                                                                 up(n * static_cast<uint32_t>(sizeof(Real)))));
    return 0;
}

void window_push(const Run& r, uint8_t w, Real x) {
    uint8_t func;
    uint16_t n;
    uint8_t* at = window_at(r, w, func, n);
    if (func == kAvg && has(kVmFeatAvg)) {
        roll_avg_push<WinIdx>(*reinterpret_cast<RollAvgS<WinIdx>*>(at),
                              reinterpret_cast<Real*>(at + up(sizeof(RollAvgS<WinIdx>))), n, x);
    } else if (func == kMin && has(kVmFeatMin)) {
        ext_push(at, n, false, x);
    } else if (func == kMax && has(kVmFeatMax)) {
        ext_push(at, n, true, x);
    } else if (func == kRange && has(kVmFeatRange)) {  // RollRangeN: the max part, then the min part
        ext_push(at, n, true, x);
        ext_push(at + ext_size(n), n, false, x);
    } else if (func == kMedian && has(kVmFeatMedian)) {
        Real* ring = reinterpret_cast<Real*>(at + up(sizeof(RollMedianS<WinIdx>)));
        roll_median_push<WinIdx>(*reinterpret_cast<RollMedianS<WinIdx>*>(at), ring,
                                 ring + up(n * static_cast<uint32_t>(sizeof(Real))) / sizeof(Real), n, x);
    }
}

// Where the typed instruction's variable (not T) at `v` is, and its type.
FSW_VM_INLINE uint8_t* ref_at(const Run& r, const uint8_t* v, uint8_t& t) {
    t = v[2];
    const uint16_t w = u16(v);
    return reinterpret_cast<uint8_t*>(((w & kRefLocal) != 0 ? r.local_ref : reinterpret_cast<uintptr_t>(r.sv)) + w);
}

// The order of the n-byte little-endian numbers at x and c, compared from
// their top down as unsigned ones after `flip` is xored into both top
// bytes (0x80: as signed ones): kBelow, kEqual or kAbove. A 16-bit word at a time (n
// even; a byte for n = 1): no 64-bit arithmetic on an 8-bit MCU, and half
// the loop's turns over the equal high bytes of a small value.
FSW_VM_INLINE uint8_t le_order(const uint8_t* x, const uint8_t* c, uint8_t n, uint8_t flip) {
    if (n == 1) {
        const uint8_t a = static_cast<uint8_t>(x[0] ^ flip), b = static_cast<uint8_t>(c[0] ^ flip);
        return a < b ? kBelow : a > b ? kAbove : kEqual;
    }
    x += n;
    c += n;
    const uint16_t top = static_cast<uint16_t>(flip << 8);
    uint16_t a = static_cast<uint16_t>(load<uint16_t>(x - 2) ^ top), b = static_cast<uint16_t>(load<uint16_t>(c - 2) ^ top);
    for (;;) {
        if (a != b) return a < b ? kBelow : kAbove;
        n = static_cast<uint8_t>(n - 2u);
        if (n == 0) return kEqual;
        x -= 2;
        c -= 2;
        a = load<uint16_t>(x - 2);
        b = load<uint16_t>(c - 2);
    }
}

// Whether the n-byte float at x (4 or 8) is a NaN: fsw_f64.h's f64_is_nan
// and f32_is_nan, inline (a call would make kJKey's function save
// registers around it on every test, for a case that is rare).
FSW_VM_INLINE bool is_nan(const uint8_t* x, uint8_t n) {
    if (n == 8) {
        if ((x[7] & 0x7Fu) != 0x7Fu || (x[6] & 0xF0u) != 0xF0u) return false;
        return ((x[6] & 0x0Fu) | x[5] | x[4] | x[3] | x[2] | x[1] | x[0]) != 0;
    }
    if ((x[3] & 0x7Fu) != 0x7Fu || (x[2] & 0x80u) == 0) return false;
    return ((x[2] & 0x7Fu) | x[1] | x[0]) != 0;
}

#if defined(__AVR__)
// key_holds of a float not a NaN (n = 4 or 8 bytes), on an AVR: its key's
// bytes (x's, ending at `xe`, xored with `neg`, 0xFF for a negative x, the
// top one with `neg` | 0x80: a negative x's every bit flipped, another's
// sign bit) against the constant's (ending at `ce`) from the top down,
// left at the first that differs, unrolled (7 cycles a byte, against the
// loop's 14), in scratch registers and the pointer registers: no register
// saves.
#define FSW_VM_KEY_TOP "ld %0, -X\n\t" "eor %0, %6\n\t" "ld %1, -Z\n\t" "cp %0, %1\n\t" "brne 1f\n\t"
#define FSW_VM_KEY_BYTE "ld %0, -X\n\t" "eor %0, %4\n\t" "ld %1, -Z\n\t" "cp %0, %1\n\t" "brne 1f\n\t"
#define FSW_VM_KEY_END                                                                            \
    "mov %0, %5\n\t" /* every byte equal: inclusive */                                         \
    "rjmp 2f\n"                                                                                 \
    "1:\n\t"                                                                                   \
    "ldi %0, 0\n\t" /* below (ldi leaves the flags: C is key < c) */                          \
    "brlo 2f\n\t"                                                                              \
    "ldi %0, 1\n" /* above */                                                                   \
    "2:"
FSW_VM_INLINE bool key_holds_avr(const uint8_t* xe, const uint8_t* ce, uint8_t n, uint8_t neg, bool inclusive) {
    uint8_t a, b;
    const uint8_t top = static_cast<uint8_t>(neg | 0x80u), incl = inclusive ? 1 : 0;
    if (n == 8) {
        __asm__(FSW_VM_KEY_TOP FSW_VM_KEY_BYTE FSW_VM_KEY_BYTE FSW_VM_KEY_BYTE FSW_VM_KEY_BYTE FSW_VM_KEY_BYTE
                    FSW_VM_KEY_BYTE FSW_VM_KEY_BYTE FSW_VM_KEY_END
                : "=&d"(a), "=&r"(b), "+x"(xe), "+z"(ce)
                : "r"(neg), "r"(incl), "r"(top)
                : "cc", "memory");
    } else {
        __asm__(FSW_VM_KEY_TOP FSW_VM_KEY_BYTE FSW_VM_KEY_BYTE FSW_VM_KEY_BYTE FSW_VM_KEY_END
                : "=&d"(a), "=&r"(b), "+x"(xe), "+z"(ce)
                : "r"(neg), "r"(incl), "r"(top)
                : "cc", "memory");
    }
    (void)b;
    return a != 0;
}
#undef FSW_VM_KEY_TOP
#undef FSW_VM_KEY_BYTE
#undef FSW_VM_KEY_END
#endif

// kJKey's test: whether the key of the float at `x` (n = 4 or 8 bytes; a
// NaN reads as +0, fsw_f64.h) is greater than (inclusive: at least) the key
// at `c`. The key flips every bit of a negative pattern and the sign bit
// of any other: built a byte at a time, compared from the top.
FSW_VM_INLINE bool key_holds(const uint8_t* x, uint8_t n, const uint8_t* c, bool inclusive) {
    c += n;
    if (is_nan(x, n)) {  // +0's key: 0x80, then zeros
        if (*--c != 0x80u) return 0x80u > *c;
        while (--n != 0)
            if (*--c != 0) return false;
        return inclusive;
    }
#if defined(__AVR__)
    return key_holds_avr(x + n, c, n, (x[n - 1u] & 0x80u) != 0 ? 0xFF : 0x00, inclusive);
#else
    x += n;
    const uint8_t neg = (x[-1] & 0x80u) != 0 ? 0xFF : 0x00;
    uint8_t k = static_cast<uint8_t>(*--x ^ (neg | 0x80u));  // a negative key flips the sign bit too
    for (;;) {
        const uint8_t b = *--c;
        if (k != b) return k > b;
        if (--n == 0) return inclusive;
        k = static_cast<uint8_t>(*--x ^ neg);
    }
#endif
}

#if defined(__AVR__)
// The order of the 8-byte unsigned little-endian numbers at x and c (kJInt
// of a U64): on an AVR in one compare chain from the low byte up, as
// generated code compares two 8-byte integers (cp, then cpc: C is x < c, Z
// every byte equal), in two scratch registers and the pointer registers:
// no loop, no register saves (a 16-bit word loop: 29 cycles more a test on
// the tank's counter, whose high words are equal).
FSW_VM_INLINE uint8_t u64_order(const uint8_t* x, const uint8_t* c) {
    uint8_t a, b;
    __asm__("ld %0, X+\n\t" "ld %1, Z+\n\t" "cp %0, %1\n\t"
            "ld %0, X+\n\t" "ld %1, Z+\n\t" "cpc %0, %1\n\t"
            "ld %0, X+\n\t" "ld %1, Z+\n\t" "cpc %0, %1\n\t"
            "ld %0, X+\n\t" "ld %1, Z+\n\t" "cpc %0, %1\n\t"
            "ld %0, X+\n\t" "ld %1, Z+\n\t" "cpc %0, %1\n\t"
            "ld %0, X+\n\t" "ld %1, Z+\n\t" "cpc %0, %1\n\t"
            "ld %0, X+\n\t" "ld %1, Z+\n\t" "cpc %0, %1\n\t"
            "ld %0, X+\n\t" "ld %1, Z+\n\t" "cpc %0, %1\n\t"
            "ldi %0, %4\n\t"  // kBelow (ldi leaves the flags)
            "brlo 1f\n\t"
            "ldi %0, %5\n\t"  // kEqual
            "breq 1f\n\t"
            "ldi %0, %6\n"     // kAbove
            "1:"
            : "=&d"(a), "=&r"(b), "+x"(x), "+z"(c)
            : "M"(kBelow), "M"(kEqual), "M"(kAbove)
            : "cc", "memory");
    (void)b;
    return a;
}
#endif

// kJInt's order of the variable at `x` (type t; T: op_jint_t)
// against the constant at `c`.
// (n: the type's size, read once by the caller)
FSW_VM_INLINE uint8_t int_order(const uint8_t* x, uint8_t t, uint8_t n, const uint8_t* c) {
    if (t == kBool) {  // 0 or 1 against any byte (the compiler writes 0 or 1)
        const uint8_t v = load_bool(x) ? 1 : 0;
        return v < c[0] ? kBelow : v > c[0] ? kAbove : kEqual;
    }
#if defined(__AVR__)
    if (n == 8 && !is_signed(t)) return u64_order(x, c);  // (a signed one: le_order's flip)
#endif
    return le_order(x, c, n, is_signed(t) ? 0x80 : 0x00);
}

template <bool Narrow>
struct IntFast {
    typedef int64_t T;
    typedef uint64_t U;
};
template <>
struct IntFast<true> {
    typedef int32_t T;
    typedef uint32_t U;
};

// The integers of kIAdd's fast path: |x| <= 2^p - 1 - |k| and x + k, with p
// R's precision (24 or 53), fit this type with a byte to spare.
typedef IntFast<sizeof(Real) == 4>::T Wide;
typedef IntFast<sizeof(Real) == 4>::U UWide;

// The largest value of each integer type narrower than 8 bytes, in a
// Wide (kIAdd's clamp; unused for the 8-byte types).
const uint32_t kIntMax[8] FSW_FLASH = {127UL, 32767UL, 2147483647UL, 0, 255UL, 65535UL, 4294967295UL, 0};

// x (of type ts) as a Wide when it is one, else false. Bytes above Wide's
// are only checked (no 64-bit arithmetic on an AVR).
FSW_VM_INLINE bool as_wide(const uint8_t* x, uint8_t ts, Wide& a) {
    const uint8_t ns = size_of(ts), wb = sizeof(Wide);
    const bool sign = is_signed(ts);
    if (ns > wb) {  // 8 bytes into a 32-bit Wide: the high word must be the low one's sign, in a word compare
        a = load<Wide>(x);
        return load<uint32_t>(x + 4) == (a < 0 ? 0xFFFFFFFFUL : 0UL) && (sign || a >= 0);
    }
    if (ns == wb) {
        a = load<Wide>(x);
        return sign || a >= 0;  // an unsigned value past Wide's range is not one
    }
    if (ns == 4) a = sign ? static_cast<Wide>(load<int32_t>(x)) : static_cast<Wide>(load<uint32_t>(x));
    else if (ns == 2) a = sign ? static_cast<Wide>(load<int16_t>(x)) : static_cast<Wide>(load<uint16_t>(x));
    else a = sign ? static_cast<Wide>(static_cast<int8_t>(x[0])) : static_cast<Wide>(x[0]);
    return true;
}

// `d = x + k` for integers d and x (kIAdd): the integer sum clamped to d's
// range when |x| + |k| <= 2^p - 1 (x, x + k and the sum exact in R), else
// the sum in R as the general instructions compute it. Bytes of d above
// Wide's are filled with the sum's sign.
void int_add(uint8_t* d, uint8_t td, const uint8_t* x, uint8_t ts, int32_t k) {
    const UWide exact = sizeof(Real) == 4 ? static_cast<UWide>(0xFFFFFFUL) : static_cast<UWide>(0x1FFFFFFFFFFFFFULL);
    Wide v;
    // |x| + |k| in unsigned arithmetic: |x| <= 2^31 (2^63), |k| < 2^24 in
    // binary32 (a verifier's rule), < 2^31 in binary64: no wrap
    if (!as_wide(x, ts, v) ||
        (v < 0 ? UWide(0) - static_cast<UWide>(v) : static_cast<UWide>(v)) +
                (k < 0 ? UWide(0) - static_cast<UWide>(static_cast<Wide>(k)) : static_cast<UWide>(k)) >
            exact) {
        vm_write(d, td, vm_read(x, ts) + real_from_I32(k));
        return;
    }
    v += k;
    const uint8_t nd = size_of(td);
    const bool sign = is_signed(td);
    if (!sign && v < 0) v = 0;
    // d narrower than Wide (where the VM takes such a type): its range
    if (nd < sizeof(Wide) && (sizeof(Wide) > 4 || has(kVmFeatI8 | kVmFeatI16 | kVmFeatU8 | kVmFeatU16))) {
        const Wide hi = static_cast<Wide>(flash_get(kIntMax[td]));
        if (v > hi) v = hi;
        if (sign && v < -hi - 1) v = -hi - 1;
    }
    // its low bytes, little-endian, by a store of the size (no copy loop);
    // an 8-byte d from a 32-bit Wide: the high word the sum's sign (only a
    // signed d is negative here)
    if (nd == 8) {
        store<Wide>(d, v);
        if (sizeof(Wide) == 4) store<uint32_t>(d + 4, v < 0 ? 0xFFFFFFFFUL : 0UL);
    } else if (nd == 4) {
        store<uint32_t>(d, static_cast<uint32_t>(v));
    } else if (nd == 2) {
        store<uint16_t>(d, static_cast<uint16_t>(v));
    } else {
        d[0] = static_cast<uint8_t>(v);
    }
}

// The typed instructions: each takes its opcode's address and returns the
// next instruction's (a jump's target when it jumps). The tests and the
// constant store run inline in run_block's loop (no call, no register
// saves each); the sum is a function of its own, whose many registers
// run_block would otherwise save on every block.
FSW_VM_INLINE const uint8_t* op_setk(const Run& r, const uint8_t* ip) {
    uint8_t t;
    uint8_t* x = ref_at(r, ip + 1, t);
    const uint8_t* v = ip + 4;
    x[0] = *v++;  // (a flag's one byte without the loop; no call: a leaf saves fewer registers)
    for (uint8_t n = size_of(t); --n != 0;) *++x = *v++;
    return v;
}

FSW_NOINLINE const uint8_t* op_iadd(const Run& r, const uint8_t* ip) {
    uint8_t td, ts;
    uint8_t* d = ref_at(r, ip + 1, td);
    const uint8_t* x = ref_at(r, ip + 4, ts);
    int_add(d, td, x, ts, static_cast<int32_t>(u32(ip + 7)));
    return ip + 11;
}

// kIAdd of a counter, the machines' commonest sum: a U64 from a U64 plus k
// (0 <= k < 2^24, as the compiler writes `n = n + 1`), in 32-bit words,
// int_add's integer path where x + k < 2^24 (exact in R: no clamp); else
// null. Inline in run_block: a leaf of few registers.
FSW_VM_INLINE const uint8_t* op_count(const Run& r, const uint8_t* ip) {
    if (ip[3] != kU64 || ip[6] != kU64 || ip[10] != 0) return nullptr;  // (k < 2^24: its top byte 0)
    uint8_t t;
    const uint8_t* x = ref_at(r, ip + 4, t);
    const uint32_t lo = load<uint32_t>(x), v = lo + u32(ip + 7);  // (both below 2^24: no wrap)
    if (load<uint32_t>(x + 4) != 0 || lo > 0xFFFFFFUL || v > 0xFFFFFFUL) return nullptr;
    uint8_t* d = ref_at(r, ip + 1, t);
    store<uint32_t>(d, v);
    store<uint32_t>(d + 4, 0);
    return ip + 11;
}

// The end of a test's instruction (its jump offset `o`, 2 bytes, last):
// where to go on when the test `holds`, under the instruction's `jump_if`.
FSW_VM_INLINE const uint8_t* test_end(const uint8_t* o, bool holds, bool jump_if) {
    return holds == jump_if ? o + 2 + u16(o) : o + 2;
}

FSW_VM_INLINE const uint8_t* op_jkey(const Run& r, const uint8_t* ip) {
    uint8_t t;
    const uint8_t* x = ref_at(r, ip + 1, t);
    const uint8_t n = float_bytes(t);
    const uint8_t flags = ip[4];
    const bool holds = key_holds(x, n, ip + 5, (flags & kKeyInclusive) != 0);
    return test_end(ip + 5 + n, holds, (flags & kKeyJumpIf) != 0);
}

// kJInt of T: a function of its own, which calls machine_T32, so that the
// test of a variable calls nothing and saves few registers.
FSW_NOINLINE const uint8_t* op_jint_t(const Run& r, const uint8_t* ip) {
    const uint32_t v = machine_T32(*r.m), c = u32(ip + 5);
    const bool holds = cmp_holds(ip[4], v < c ? kBelow : v > c ? kAbove : kEqual);
    return test_end(ip + 9, holds, (ip[4] & kJumpIf) != 0);
}

FSW_VM_INLINE const uint8_t* op_jint(const Run& r, const uint8_t* ip) {
    if (ip[1] == 0xFFu && ip[2] == 0xFFu) return op_jint_t(r, ip);  // kRefT
    uint8_t t;
    const uint8_t* x = ref_at(r, ip + 1, t);
    const uint8_t flags = ip[4];
    const uint8_t n = size_of(t);
    const bool holds = cmp_holds(flags, int_order(x, t, n, ip + 5));
    return test_end(ip + 5 + n, holds, (flags & kJumpIf) != 0);
}

// truthy() in one place (two float compares a call on an AVR), for the
// operand stack's tests.
FSW_NOINLINE bool vm_truthy(Real r) { return truthy(r); }

// The order of two R values for kJCmp and the comparisons (a NaN: unordered).
uint8_t real_order(Real x, Real y) { return x < y ? kBelow : x > y ? kAbove : x == y ? kEqual : kUnordered; }

// Code that evaluates on the operand stack, from `pc` (at depth 0) to the
// instruction after the one that empties the stack again: where the block
// goes on. Apart from run_block, so that the stack's frame is only set up
// for such code. (Typed instructions run at depth 0 only, a verifier's rule:
// never here.)
FSW_NOINLINE uint16_t run_stack(const Run& r, uint16_t pc) {
    Real st[FSW_VM_STACK];
    uint8_t sp = 0;
    const uint8_t* code = r.code;
    for (bool first = true;; first = false) {
        if (!first && sp == 0) return pc;  // the stack is empty again
        const uint8_t op = code[pc];
        const uint8_t* a = code + pc + 1;
        switch (op) {
            case kEnd:
            case kGoto: return pc;  // unreachable: a verified block ends at depth 0
            case kJmp: pc = static_cast<uint16_t>(pc + 3u + u16(a)); continue;
            case kJf:
                --sp;
                pc = static_cast<uint16_t>(pc + 3u + (vm_truthy(st[sp]) ? 0u : u16(a)));
                continue;
            case kAnd:
            case kOr:
                // `a and b`: a false leaves 0 and skips b; `a or b`: a true leaves 1.
                if (vm_truthy(st[sp - 1u]) == (op == kOr)) {
                    st[sp - 1u] = real_from_truth(op == kOr);
                    pc = static_cast<uint16_t>(pc + 3u + u16(a));
                } else {
                    --sp;
                    pc = static_cast<uint16_t>(pc + 3u);
                }
                continue;
            case kConst: memcpy(&st[sp++], a, sizeof(Real)); pc = static_cast<uint16_t>(pc + 1u + sizeof(Real)); continue;
            case kLde: {
                const uint8_t* e = r.sv + flash_get(r.elems[u16(a)].off);
                if (has(kVmFeatLock) && r.lock) {  // (folded away where the VM has no lock)
                    SvGuard<true> g;
                    st[sp++] = vm_read(e, a[2]);
                } else {
                    st[sp++] = vm_read(e, a[2]);
                }
                pc = static_cast<uint16_t>(pc + 4u);
                continue;
            }
            case kSte: {
                uint8_t* e = r.sv + flash_get(r.elems[u16(a)].off);
                --sp;
                if (has(kVmFeatLock) && r.lock) {
                    SvGuard<true> g;
                    vm_write(e, a[2], st[sp]);
                } else {
                    vm_write(e, a[2], st[sp]);
                }
                pc = static_cast<uint16_t>(pc + 4u);
                continue;
            }
            case kLdl:
            case kStl: {
                const uint8_t* l = r.loc + 3u * u16(a);
                uint8_t* at = reinterpret_cast<uint8_t*>(r.local_ref + kRefLocal + u16(l + 1));
                if (op == kLdl) st[sp++] = vm_read(at, l[0]);
                else vm_write(at, l[0], st[--sp]);
                pc = static_cast<uint16_t>(pc + 3u);
                continue;
            }
            case kJCmp: {
                sp = static_cast<uint8_t>(sp - 2u);
                const bool holds = cmp_holds(a[0], real_order(st[sp], st[sp + 1u]));
                pc = static_cast<uint16_t>(test_end(a + 1, holds, (a[0] & kJumpIf) != 0) - code);
                continue;
            }
            case kLdt: st[sp++] = machine_T_real(*r.m); break;
            case kRoll:
                st[sp++] = has(kVmFeatWindows) ? window_value(r, a[0]) : Real(0);  // (none in a verified image without)
                pc = static_cast<uint16_t>(pc + 2u);
                continue;
            case kWpush:
                --sp;
                if (has(kVmFeatWindows)) window_push(r, a[0], st[sp]);
                pc = static_cast<uint16_t>(pc + 2u);
                continue;
            case kNeg: st[sp - 1u] = -st[sp - 1u]; break;
            case kNot:
            case kTruth: st[sp - 1u] = real_from_truth(vm_truthy(st[sp - 1u]) == (op == kTruth)); break;
            default: {
                const Real y = st[--sp];
                const Real x = st[sp - 1u];
                Real z;
                switch (op) {
                    case kAdd: z = x + y; break;
                    case kSub: z = x - y; break;
                    case kMul: z = x * y; break;
                    case kDiv: z = x / y; break;
                    // the comparisons (kLt..kNe: kCmpMask's order) by the one
                    // order of x and y that kJCmp takes: no compare of its own each
                    default: z = real_from_truth(cmp_holds(static_cast<uint8_t>(op - kLt), real_order(x, y))); break;
                }
                st[sp - 1u] = z;
                break;
            }
        }
        ++pc;  // the one-byte instructions
    }
}

// Runs the block at `pc`: the state id it goes to (0: none). Typed
// instructions (inline: no call each) and jumps run here, stack code in
// run_stack.
FSW_NOINLINE uint16_t run_block(const Run& r, uint16_t pc) {
    const uint8_t* ip = r.code + pc;
    for (;;) {
        switch (*ip) {
            case kEnd: return 0;
            case kGoto: return static_cast<uint16_t>(ip[1] + 1u);
            case kJmp: ip += 3 + u16(ip + 1); continue;
            case kJKey: ip = op_jkey(r, ip); continue;
            case kJInt: ip = op_jint(r, ip); continue;
            case kSetK: ip = op_setk(r, ip); continue;
            case kIAdd: {
                const uint8_t* next = op_count(r, ip);
                ip = next != nullptr ? next : op_iadd(r, ip);
                continue;
            }
            default: ip = r.code + run_stack(r, static_cast<uint16_t>(ip - r.code)); continue;
        }
    }
}

}  // namespace

namespace {

// The step's view of a verified image (whose parts all lie within its at
// most 65535 bytes: 16-bit sums); its state table is at kHeader.
FSW_VM_INLINE void run_init(Run& r, const uint8_t* image, const VmLayout& layout, uint8_t* sv, uint8_t* ram,
                            Machine& m) {
    r.loc = image + kHeader + 6u * image[18];
    r.win = r.loc + 3u * u16(image + 20);
    r.code = r.win + 4u * image[19] + u16(image + 22);
    r.elems = layout.elems;
    r.sv = sv;
    r.ram = ram;
    uint8_t* locals = ram;
    if (has(kVmFeatWindows) && image[19] != 0) locals += ram_of_windows(r.win, image[19]);  // (none where the VM takes none)
    r.local_ref = reinterpret_cast<uintptr_t>(locals) - kRefLocal;
    r.m = &m;
    r.lock = has(kVmFeatLock) && (image[6] & kFlagLock) != 0;  // (a verified image is locked only where built so)
}

}  // namespace

Result vm_step(const uint8_t* image, const VmLayout& layout, uint8_t* sv, uint8_t* ram, Machine& m) {
    Run r;
    run_init(r, image, layout, sv, ram, m);
    uint8_t* g = sv + u16(image + 14);
    uint8_t* s = sv + u16(image + 16);
    if (has(kVmFeatLock) && r.lock) {  // as a generated step() over a locked state vector
        uint64_t now;
        {
            SvGuard<true> lock;
            now = load<uint64_t>(g);
        }
        if (machine_begin_step(m, now) != kOk) return kErrTime;
        if (m.entering != 0) {
            SvGuard<true> lock;
            store<uint32_t>(s, m.state);
        }
    } else if (machine_begin(m, g, s) != kOk) {
        return kErrTime;
    }
    const uint16_t prelude = u16(image + 24);
    if (r.code[prelude] != kEnd && run_block(r, prelude) != 0) return kErrConfig;  // unreachable when verified
    const uint32_t index = m.state - 1u;  // (state 0, none: past every state)
    if (index >= image[18]) return kOk;
    // the state's .entry, .step and .exit, each read where it is needed
    const uint8_t* blocks = image + kHeader + 6u * static_cast<uint8_t>(index);
    uint16_t next = 0;
    if (m.entering != 0 && u16(blocks) != kNone) next = run_block(r, u16(blocks));
    if (next == 0 && u16(blocks + 2) != kNone) next = run_block(r, u16(blocks + 2));
    if (next != 0) {
        if (u16(blocks + 4) != kNone) (void)run_block(r, u16(blocks + 4));
        machine_transition(m, next);
    }
    return kOk;
}

void vm_leave(const uint8_t* image, const VmLayout& layout, uint8_t* sv, uint8_t* ram, Machine& m) {
    if (m.started == 0 || m.pending != 0) return;  // no state entered, or the last one already left
    Run r;
    run_init(r, image, layout, sv, ram, m);
    if (m.state == 0 || m.state > image[18]) return;
    const uint16_t exit = u16(image + kHeader + 6u * (m.state - 1u) + 4u);
    if (exit != kNone) (void)run_block(r, exit);
}

}  // namespace fsw
