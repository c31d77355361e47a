// A state machine as a bytecode image (docs/bytecode.md): the verifier that
// refuses a bad image before it runs, and the VM that steps a verified one
// with the semantics of a generated machine's step().
#ifndef FSW_VM_H
#define FSW_VM_H

#include "fsw_config.h"  // FSW_VM_STACK, FSW_VM_PENDING
#include "fsw_machine.h"
#include "fsw_types.h"

namespace fsw {

// Values are stable: the host verifier (autocode/vmverify.py) returns the same.
enum VmReason : uint8_t {
    kVmOk = 0,
    kVmBadMagic = 1,     // not "FSMB"
    kVmBadVersion = 2,   // a format version this runtime does not read
    kVmBadReal = 3,      // compiled for the other evaluation type (f32 / f64)
    kVmBadSchema = 4,    // bound to another state vector (schema hash, element count)
    kVmBadSize = 5,      // the lengths in the header do not add up to the image
    kVmBadElement = 6,   // an element index or offset not the layout's, or its type not the layout's
    kVmBadLocal = 7,     // a local index out of range, or a local outside the locals
    kVmBadState = 8,     // no states, a state index out of range, a code offset out of range
    kVmBadWindow = 9,    // a window index, function or size out of range, or pushed out of order
    kVmBadJump = 10,     // a jump backward, out of its block, or into an instruction
    kVmBadStack = 11,    // underflow, deeper than the VM's stack or than declared, not empty at the end
    kVmBadOpcode = 12,   // an unknown opcode, or an operand past the code
    kVmBadEnd = 13,      // a block that does not end, unreachable code, an offset not at a block's start
    kVmBadPlace = 14,    // goto outside .entry/.step, a window push outside the prelude
    kVmTooNested = 15,   // more pending forward jumps than FSW_VM_PENDING
    kVmNoRam = 16,       // the caller's buffer is smaller than the image needs
    kVmBadMask = 17,     // (a reload slot) the state mask after the image: not a bit per state, or no state set
    kVmNoFeature = 18,   // a window function, value type or lock the VM was built without (vm_features)
};

// What a VM runs beyond what every image may use (U32, U64 and bool values,
// every instruction): a window function (bit 1 << function: 0 avg, 1 min,
// 2 max, 3 range, 4 median), values of another type (elements and locals),
// a locked state vector. An image that needs one the VM lacks is refused
// (kVmNoFeature).
enum VmFeature : uint16_t {
    kVmFeatAvg = 1, kVmFeatMin = 2, kVmFeatMax = 4, kVmFeatRange = 8, kVmFeatMedian = 16,
    kVmFeatF32 = 32, kVmFeatF64 = 64, kVmFeatLock = 128,
    kVmFeatI8 = 0x100, kVmFeatI16 = 0x200, kVmFeatI32 = 0x400, kVmFeatI64 = 0x800,
    kVmFeatU8 = 0x1000, kVmFeatU16 = 0x2000,
};
static const uint16_t kVmFeatWindows = 0x1F;  // any window function
static const uint16_t kVmFeatSigned = 0xF00;  // any signed integer type
static const uint16_t kVmFeatTypes = 0x3F60;  // every type
static const uint16_t kVmAllFeatures = 0x3FFF;

// The features of this program's VM. An application with a replaceable
// machine defines it in its generated code from its layout: the types of
// its state vector and of the machine's locals, the machine's window
// functions, the vector's lock option (docs/bytecode.md, "A board's VM"), a
// constant that LTO folds into the VM, dropping the code of the others. A
// program that links the VM defines it (kVmAllFeatures: every image runs);
// the native PSL has a weak kVmAllFeatures for host programs (libfswsm, the
// tests). Never weak on an AVR: avr-gcc 5.4 folds a weak constant's own
// value even where a strong one overrides it.
extern const uint16_t vm_features;

// An element of the state vector the image is bound to: offset and type.
struct VmElem {
    uint16_t off;
    uint8_t type;  // ElemType
};

// The layout of the running firmware's state vector, in element order.
struct VmLayout {
    const VmElem* elems;  // FSW_FLASH table (read a field at a time)
    uint16_t count;
    uint32_t schema;  // the state vector's schema hash
};

// The alignment of the caller's RAM buffer (`alignas(fsw::kVmRamAlign)`):
// that of Real and of the windows' indices, 1 on an AVR (which aligns
// nothing: no padding in front of the buffer), 8 where R is binary64 on a
// host. The image itself is read a byte at a time and needs none.
static const uint8_t kVmRamAlign = alignof(Real) > alignof(WinIdx) ? alignof(Real) : alignof(WinIdx);

// Bytes of RAM the image needs (windows, then locals): 0 for an image whose
// header cannot be read. vm_verify checks it against the caller's buffer,
// which must be aligned to kVmRamAlign.
uint32_t vm_ram_size(const uint8_t* image, uint16_t len);

// Checks every rule of docs/bytecode.md; kVmOk means vm_step may run it.
FSW_MUST_CHECK VmReason vm_verify(const uint8_t* image, uint16_t len, const VmLayout& layout, uint32_t ram_len);

// The same rules for an image kept in the EEPROM at `addr` (a loader's slot,
// fsw_reload.h), read there byte by byte, in one call (a board's boot).
FSW_MUST_CHECK VmReason vm_verify_eeprom(uint16_t addr, uint16_t len, const VmLayout& layout, uint32_t ram_len);

// A forward jump the verifier has seen and not yet reached: its target and
// the stack's depth there.
struct VmPending {
    uint16_t target;
    uint8_t depth;
};

// The verifier's state between the calls of a check in slices (RAM): what
// its one pass over the image has seen so far.
struct VmCheck {
    uint32_t ram;            // the windows' bytes, summed so far
    uint16_t i;              // the phase's index: a local, a window, a block offset, a state scanned
    uint16_t pc;             // the next instruction
    uint16_t declared;       // the image's block offsets, the prelude's included
    uint16_t matched;        // ... those found where a block starts
    uint16_t moving, still;  // the block offsets equal to pc (moving: entry and step)
    uint8_t phase, np, depth, deepest, pushed, flags;
    VmPending pend[FSW_VM_PENDING];
};

// vm_check_eeprom's answer while the check is not over (never a VmReason).
static const uint8_t kVmMore = 0xFF;

// The rules of vm_verify_eeprom over many calls, so that no call holds the
// CPU for long (a board checks an uploaded image between its machine's
// steps, fsw_reload.h): vm_check_begin, then vm_check_eeprom with the same
// arguments until it answers something else than kVmMore (the answer
// vm_verify_eeprom gives). A call does one unit of work at least (a local,
// a window, a block offset, a state's three compared with an instruction's
// address, an instruction: 14 reads at most) and stops before the next
// once it has read `budget` EEPROM bytes, the header's included (27 the
// first call, 10 the next ones): at most `budget` + 13 reads a call, or
// the header's and a unit's when `budget` is below the header's.
void vm_check_begin(VmCheck& c);
FSW_MUST_CHECK uint8_t vm_check_eeprom(VmCheck& c, uint16_t addr, uint16_t len, const VmLayout& layout, uint32_t ram_len,
                                       uint16_t budget);

// The image's locals inside `ram` (packed little-endian, in declaration order).
uint8_t* vm_locals(const uint8_t* image, uint8_t* ram);

// Back to the state before the first step in `initial` (a state id, 1..):
// the machine reset, locals at their initial values, windows empty.
void vm_reset(const uint8_t* image, uint8_t* ram, Machine& m, uint32_t initial);

// One step of a verified image (spec 4.6), as a generated step(): kErrTime
// (and nothing changed) when G did not increase.
FSW_MUST_CHECK Result vm_step(const uint8_t* image, const VmLayout& layout, uint8_t* sv, uint8_t* ram, Machine& m);

// Runs the current state's `.exit` (when the state was entered and not yet
// left): another machine takes over from this one (fsw_reload.h).
void vm_leave(const uint8_t* image, const VmLayout& layout, uint8_t* sv, uint8_t* ram, Machine& m);

}  // namespace fsw

#endif  // FSW_VM_H
