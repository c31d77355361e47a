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
const uint8_t kVersion = 1;
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
};

// N is 16 bits in the image: every runtime holds a window of 65535 samples.
static_assert(FSW_WINDOW_MAX_N >= 65535UL, "window sizes of the image");

enum WinFunc : uint8_t { kAvg = 0, kMin = 1, kMax = 2, kRange = 3, kMedian = 4 };

inline uint16_t u16(const uint8_t* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }
inline uint32_t u32(const uint8_t* p) {
    return static_cast<uint32_t>(u16(p)) | (static_cast<uint32_t>(u16(p + 2)) << 16);
}

// The verifier reads an image through a reader: in RAM (vm_verify), or in
// the EEPROM a loader keeps it in (vm_verify_eeprom), byte by byte.
struct RamImage {
    const uint8_t* im;
    uint8_t operator[](uint32_t i) const { return im[i]; }
};
struct EepromImage {
    uint16_t base;
    uint8_t operator[](uint32_t i) const { return pal::eeprom_read(static_cast<uint16_t>(base + i)); }
};
template <class Im>
inline uint16_t r16(const Im& im, uint32_t i) { return static_cast<uint16_t>(im[i] | (im[i + 1u] << 8)); }
template <class Im>
inline uint32_t r32(const Im& im, uint32_t i) {
    return static_cast<uint32_t>(r16(im, i)) | (static_cast<uint32_t>(r16(im, i + 2u)) << 16);
}

// Where the parts of an image start, as offsets into it (valid once the
// header was checked).
struct Offs {
    uint8_t states, windows;
    uint16_t locals, loc_size, prelude, code_size;
    uint32_t st;     // states: entry, step, exit code offsets (u16 each)
    uint32_t loc;    // locals: type (u8), offset (u16)
    uint32_t win;    // windows: function (u8), 0 (u8), N (u16)
    uint32_t init;   // the locals' initial bytes
    uint32_t code;
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
    o.st = kHeader;
    o.loc = o.st + 6u * o.states;
    o.win = o.loc + 3u * o.locals;
    o.init = o.win + 4u * o.windows;
    o.code = o.init + o.loc_size;
    o.total = o.code + o.code_size;
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

void parts(const uint8_t* im, Parts& p) {
    Offs o;
    offsets(RamImage{im}, o);
    p.states = o.states;
    p.windows = o.windows;
    p.locals = o.locals;
    p.loc_size = o.loc_size;
    p.prelude = o.prelude;
    p.code_size = o.code_size;
    p.st = im + o.st;
    p.loc = im + o.loc;
    p.win = im + o.win;
    p.init = im + o.init;
    p.code = im + o.code;
}

// Storage of a window of n samples in the VM's RAM: the state struct and its
// arrays, as the typed wrappers of fsw_window.h lay them, with WinIdx indices.
const uint32_t kAlign = kVmRamAlign;
inline uint32_t up(uint32_t x) { return (x + kAlign - 1u) / kAlign * kAlign; }
inline uint32_t ext_size(uint32_t n) {
    return up(sizeof(RollExtS<WinIdx>)) + up(n * sizeof(Real)) + up(n * sizeof(WinIdx));
}
uint32_t window_size(uint8_t func, uint32_t n) {
    switch (func) {
        case kAvg: return up(sizeof(RollAvgS<WinIdx>)) + up(n * sizeof(Real));
        case kMin:
        case kMax: return ext_size(n);
        case kRange: return 2u * ext_size(n);
        default: return up(sizeof(RollMedianS<WinIdx>)) + 2u * up(n * sizeof(Real));
    }
}

template <class Im>
uint32_t windows_size(const Im& im, const Offs& o) {
    uint32_t size = 0;
    for (uint8_t w = 0; w < o.windows; ++w) size += window_size(im[o.win + 4u * w], r16(im, o.win + 4u * w + 2u));
    return size;
}
uint32_t windows_size(const Parts& p) {
    uint32_t size = 0;
    for (uint8_t w = 0; w < p.windows; ++w) size += window_size(p.win[4u * w], u16(p.win + 4u * w + 2u));
    return size;
}

// Operand bytes after the opcode; 0xFF for an unknown opcode.
uint8_t operand_bytes(uint8_t op, uint8_t real) {
    switch (op) {
        case kEnd: case kLdt: case kNeg: case kAdd: case kSub: case kMul: case kDiv:
        case kLt: case kLe: case kGt: case kGe: case kEq: case kNe: case kNot: case kTruth:
            return 0;
        case kGoto: case kRoll: case kWpush: return 1;
        case kJmp: case kJf: case kAnd: case kOr: case kLdl: case kStl: return 2;
        case kLde: case kSte: return 3;
        case kConst: return real;
        default: return 0xFF;
    }
}

// How many of the image's declared block offsets equal `pc` (exit and prelude
// blocks counted apart: they may not transition).
template <class Im>
void count_offsets(const Im& im, const Offs& p, uint16_t pc, uint16_t& moving, uint16_t& still) {
    moving = 0;
    still = p.prelude == pc ? 1u : 0u;
    for (uint8_t s = 0; s < p.states; ++s) {
        moving = static_cast<uint16_t>(moving + (r16(im, p.st + 6u * s) == pc) + (r16(im, p.st + 6u * s + 2u) == pc));
        still = static_cast<uint16_t>(still + (r16(im, p.st + 6u * s + 4u) == pc));
    }
}

struct Pending {
    uint16_t target;
    uint8_t depth;
};

template <class Im>
VmReason verify_code(const Im& im, const Offs& p, const VmLayout& layout) {
    const uint8_t real = im[5];
    uint16_t declared = p.prelude != kNone ? 1u : 0u;
    for (uint16_t k = 0; k < 3u * p.states; ++k) {
        const uint16_t off = r16(im, p.st + 2u * k);
        if (off == kNone) continue;
        if (off >= p.code_size) return kVmBadState;
        ++declared;
    }
    if (p.prelude == kNone || p.prelude >= p.code_size) return kVmBadEnd;
    Pending pend[FSW_VM_PENDING];
    uint8_t np = 0, depth = 0, deepest = 0, pushed = 0;
    bool reachable = true, at_start = true, may_move = false, prelude = false;
    uint16_t matched = 0, pc = 0;
    while (pc < p.code_size) {
        if (at_start) {  // a block starts here: what may it do?
            uint16_t moving, still;
            count_offsets(im, p, pc, moving, still);
            if (moving != 0 && still != 0) return kVmBadPlace;
            matched = static_cast<uint16_t>(matched + moving + still);
            may_move = moving != 0;
            prelude = p.prelude == pc;
            pushed = 0;
            at_start = false;
            reachable = true;
        }
        for (uint8_t k = 0; k < np;) {  // jumps landing here
            if (pend[k].target < pc) return kVmBadJump;  // into an instruction
            if (pend[k].target == pc) {
                uint16_t moving, still;
                count_offsets(im, p, pc, moving, still);
                if (moving != 0 || still != 0) return kVmBadJump;  // into another block
                if (reachable && depth != pend[k].depth) return kVmBadStack;
                depth = pend[k].depth;
                reachable = true;
                pend[k] = pend[--np];
            } else {
                ++k;
            }
        }
        if (!reachable) return kVmBadEnd;
        const uint8_t op = im[p.code + pc];
        const uint8_t n = operand_bytes(op, real);
        if (n == 0xFF || static_cast<uint32_t>(pc) + 1u + n > p.code_size) return kVmBadOpcode;
        const uint32_t a = p.code + pc + 1u;  // the operands
        pc = static_cast<uint16_t>(pc + 1u + n);
        uint8_t pops = 0, pushes = 0;
        bool ends = false;
        switch (op) {
            case kEnd: ends = true; break;
            case kGoto:
                if (!may_move) return kVmBadPlace;
                if (im[a] >= p.states) return kVmBadState;
                ends = true;
                break;
            case kJmp: case kJf: case kAnd: case kOr: {
                pops = op == kJmp ? 0 : 1;
                if (depth < pops) return kVmBadStack;
                const uint32_t target = static_cast<uint32_t>(pc) + r16(im, a);
                if (target >= p.code_size) return kVmBadJump;
                if (np == FSW_VM_PENDING) return kVmTooNested;
                // and/or keep their left operand when they jump; jf drops it.
                pend[np].target = static_cast<uint16_t>(target);
                pend[np].depth = static_cast<uint8_t>(op == kJf ? depth - 1u : depth);
                ++np;
                if (op == kJmp) reachable = false;
                break;
            }
            case kConst: case kLdt: pushes = 1; break;
            case kLde: case kSte: {
                const uint16_t e = r16(im, a);
                if (e >= layout.count || flash_get(layout.elems[e].type) != im[a + 2u]) return kVmBadElement;
                if (op == kLde) pushes = 1; else pops = 1;
                break;
            }
            case kLdl: case kStl:
                if (r16(im, a) >= p.locals) return kVmBadLocal;
                if (op == kLdl) pushes = 1; else pops = 1;
                break;
            case kRoll:
                if (im[a] >= p.windows || (prelude && im[a] >= pushed)) return kVmBadWindow;
                pushes = 1;
                break;
            case kWpush:
                if (!prelude) return kVmBadPlace;
                if (im[a] != pushed) return kVmBadWindow;
                ++pushed;
                pops = 1;
                break;
            case kNeg: case kNot: case kTruth: pops = 1; pushes = 1; break;
            default: pops = 2; pushes = 1; break;  // arithmetic and comparisons
        }
        if (depth < pops) return kVmBadStack;
        depth = static_cast<uint8_t>(depth - pops + pushes);
        if (depth > deepest) deepest = depth;
        if (deepest > FSW_VM_STACK) return kVmBadStack;
        if (ends) {
            if (depth != 0) return kVmBadStack;
            reachable = false;
            if (np == 0) {  // the block is over
                if (prelude && pushed != p.windows) return kVmBadWindow;
                at_start = true;
            }
        }
    }
    if (np != 0) return kVmBadJump;
    if (!at_start) return kVmBadEnd;
    if (matched != declared) return kVmBadEnd;
    if (deepest != im[7]) return kVmBadStack;
    return kVmOk;
}

}  // namespace

namespace {

template <class Im>
VmReason verify(const Im& im, uint16_t len, const VmLayout& layout, uint32_t ram_len) {
    if (len < kHeader) return kVmBadSize;
    if (im[0] != 'F' || im[1] != 'S' || im[2] != 'M' || im[3] != 'B') return kVmBadMagic;
    if (im[4] != kVersion) return kVmBadVersion;
    if (im[5] != sizeof(Real)) return kVmBadReal;
    if ((im[6] & ~kFlagLock) != 0) return kVmBadVersion;
    if (r32(im, 8) != layout.schema || r16(im, 12) != layout.count) return kVmBadSchema;
    Offs p;
    offsets(im, p);
    if (p.total != len) return kVmBadSize;
    const uint16_t g = r16(im, 14), s = r16(im, 16);
    if (g >= layout.count || s >= layout.count || flash_get(layout.elems[g].type) != kU64 ||
        flash_get(layout.elems[s].type) != kU32)
        return kVmBadElement;
    if (p.states == 0) return kVmBadState;
    for (uint16_t k = 0; k < p.locals; ++k) {
        const uint8_t t = im[p.loc + 3u * k];
        const uint16_t off = r16(im, p.loc + 3u * k + 1u);
        if (elem_size(t) == 0 || static_cast<uint32_t>(off) + elem_size(t) > p.loc_size) return kVmBadLocal;
    }
    for (uint8_t w = 0; w < p.windows; ++w) {
        const uint16_t n = r16(im, p.win + 4u * w + 2u);
        if (im[p.win + 4u * w] > kMedian || im[p.win + 4u * w + 1u] != 0 || n == 0) return kVmBadWindow;
    }
    const VmReason r = verify_code(im, p, layout);
    if (r != kVmOk) return r;
    if (windows_size(im, p) + p.loc_size > ram_len) return kVmNoRam;
    return kVmOk;
}

}  // namespace

uint32_t vm_ram_size(const uint8_t* image, uint16_t len) {
    if (len < kHeader) return 0;
    Offs o;
    offsets(RamImage{image}, o);
    if (o.total > len) return 0;
    return windows_size(RamImage{image}, o) + o.loc_size;
}

VmReason vm_verify(const uint8_t* im, uint16_t len, const VmLayout& layout, uint32_t ram_len) {
    return verify(RamImage{im}, len, layout, ram_len);
}

VmReason vm_verify_eeprom(uint16_t addr, uint16_t len, const VmLayout& layout, uint32_t ram_len) {
    return verify(EepromImage{addr}, len, layout, ram_len);
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

// What one step of a verified image works on.
struct Run {
    const uint8_t* im;
    Parts p;
    const VmLayout* layout;
    uint8_t* sv;
    uint8_t* ram;
    uint8_t* loc;
    Machine* m;
    bool lock;
};

uint8_t* window_at(const Run& r, uint8_t w, uint8_t& func, uint16_t& n) {
    uint8_t* at = r.ram;
    for (uint8_t k = 0; k < w; ++k) at += window_size(r.p.win[4u * k], u16(r.p.win + 4u * k + 2u));
    func = r.p.win[4u * w];
    n = u16(r.p.win + 4u * w + 2u);
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

Real window_value(const Run& r, uint8_t w) {
    uint8_t func;
    uint16_t n;
    uint8_t* at = window_at(r, w, func, n);
    switch (func) {
        case kAvg: {
            // A power-of-two N multiplies by 1/N once full, as RollAvgN does.
            const Real inv = (n & (n - 1u)) == 0 ? Real(1) / Real(n) : Real(0);
            return roll_avg_mean<WinIdx>(*reinterpret_cast<RollAvgS<WinIdx>*>(at), n, inv);
        }
        case kMin:
        case kMax: return ext_value(at);
        case kRange: return ext_value(at) - ext_value(at + ext_size(n));
        default:
            return roll_median_value<WinIdx>(*reinterpret_cast<RollMedianS<WinIdx>*>(at),
                                             reinterpret_cast<Real*>(at + up(sizeof(RollMedianS<WinIdx>)) +
                                                                     up(n * static_cast<uint32_t>(sizeof(Real)))));
    }
}

void window_push(const Run& r, uint8_t w, Real x) {
    uint8_t func;
    uint16_t n;
    uint8_t* at = window_at(r, w, func, n);
    switch (func) {
        case kAvg:
            roll_avg_push<WinIdx>(*reinterpret_cast<RollAvgS<WinIdx>*>(at),
                                  reinterpret_cast<Real*>(at + up(sizeof(RollAvgS<WinIdx>))), n, x);
            break;
        case kMin: ext_push(at, n, false, x); break;
        case kMax: ext_push(at, n, true, x); break;
        case kRange:  // RollRangeN: the max part, then the min part
            ext_push(at, n, true, x);
            ext_push(at + ext_size(n), n, false, x);
            break;
        default: {
            Real* ring = reinterpret_cast<Real*>(at + up(sizeof(RollMedianS<WinIdx>)));
            roll_median_push<WinIdx>(*reinterpret_cast<RollMedianS<WinIdx>*>(at), ring,
                                     ring + up(n * static_cast<uint32_t>(sizeof(Real))) / sizeof(Real), n, x);
            break;
        }
    }
}

// Runs the block at `pc`: the state id it goes to (0: none).
uint32_t run_block(const Run& r, uint16_t pc) {
    Real st[FSW_VM_STACK];
    uint8_t sp = 0;
    const uint8_t* code = r.p.code;
    for (;;) {
        const uint8_t op = code[pc];
        const uint8_t* a = code + pc + 1;
        switch (op) {
            case kEnd: return 0;
            case kGoto: return static_cast<uint32_t>(a[0]) + 1u;
            case kJmp: pc = static_cast<uint16_t>(pc + 3u + u16(a)); continue;
            case kJf:
                --sp;
                pc = static_cast<uint16_t>(pc + 3u + (truthy(st[sp]) ? 0u : u16(a)));
                continue;
            case kAnd:
            case kOr:
                // `a and b`: a false leaves 0 and skips b; `a or b`: a true leaves 1.
                if (truthy(st[sp - 1u]) == (op == kOr)) {
                    st[sp - 1u] = real_from_truth(op == kOr);
                    pc = static_cast<uint16_t>(pc + 3u + u16(a));
                } else {
                    --sp;
                    pc = static_cast<uint16_t>(pc + 3u);
                }
                continue;
            case kConst: memcpy(&st[sp++], a, sizeof(Real)); pc = static_cast<uint16_t>(pc + 1u + sizeof(Real)); continue;
            case kLde: {
                const uint8_t* e = r.sv + flash_get(r.layout->elems[u16(a)].off);
                if (r.lock) {
                    SvGuard<true> g;
                    st[sp++] = read_elem(e, a[2]);
                } else {
                    st[sp++] = read_elem(e, a[2]);
                }
                pc = static_cast<uint16_t>(pc + 4u);
                continue;
            }
            case kSte: {
                uint8_t* e = r.sv + flash_get(r.layout->elems[u16(a)].off);
                --sp;
                if (r.lock) {
                    SvGuard<true> g;
                    write_elem(e, a[2], st[sp]);
                } else {
                    write_elem(e, a[2], st[sp]);
                }
                pc = static_cast<uint16_t>(pc + 4u);
                continue;
            }
            case kLdl:
            case kStl: {
                const uint8_t* l = r.p.loc + 3u * u16(a);
                uint8_t* at = r.loc + u16(l + 1);
                if (op == kLdl) st[sp++] = read_elem(at, l[0]);
                else write_elem(at, l[0], st[--sp]);
                pc = static_cast<uint16_t>(pc + 3u);
                continue;
            }
            case kLdt: st[sp++] = machine_T_real(*r.m); break;
            case kRoll: st[sp++] = window_value(r, a[0]); pc = static_cast<uint16_t>(pc + 2u); continue;
            case kWpush: window_push(r, a[0], st[--sp]); pc = static_cast<uint16_t>(pc + 2u); continue;
            case kNeg: st[sp - 1u] = -st[sp - 1u]; break;
            case kNot: st[sp - 1u] = real_from_truth(!truthy(st[sp - 1u])); break;
            case kTruth: st[sp - 1u] = real_from_truth(truthy(st[sp - 1u])); break;
            default: {
                const Real y = st[--sp];
                const Real x = st[sp - 1u];
                Real z;
                switch (op) {
                    case kAdd: z = x + y; break;
                    case kSub: z = x - y; break;
                    case kMul: z = x * y; break;
                    case kDiv: z = x / y; break;
                    case kLt: z = real_from_truth(x < y); break;
                    case kLe: z = real_from_truth(x <= y); break;
                    case kGt: z = real_from_truth(x > y); break;
                    case kGe: z = real_from_truth(x >= y); break;
                    case kEq: z = real_from_truth(x == y); break;
                    default: z = real_from_truth(x != y); break;
                }
                st[sp - 1u] = z;
                break;
            }
        }
        ++pc;  // the one-byte instructions
    }
}

}  // namespace

namespace {

void run_init(Run& r, const uint8_t* image, const VmLayout& layout, uint8_t* sv, uint8_t* ram, Machine& m) {
    r.im = image;
    parts(image, r.p);
    r.layout = &layout;
    r.sv = sv;
    r.ram = ram;
    r.loc = ram + windows_size(r.p);
    r.m = &m;
    r.lock = (image[6] & kFlagLock) != 0;
}

}  // namespace

Result vm_step(const uint8_t* image, const VmLayout& layout, uint8_t* sv, uint8_t* ram, Machine& m) {
    Run r;
    run_init(r, image, layout, sv, ram, m);
    uint8_t* g = sv + flash_get(layout.elems[u16(image + 14)].off);
    uint8_t* s = sv + flash_get(layout.elems[u16(image + 16)].off);
    if (r.lock) {  // as a generated step() over a locked state vector
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
    if (run_block(r, r.p.prelude) != 0) return kErrConfig;  // unreachable for a verified image
    if (m.state == 0 || m.state > r.p.states) return kOk;
    const uint8_t* blocks = r.p.st + 6u * (m.state - 1u);
    const uint16_t entry = u16(blocks), step = u16(blocks + 2), exit = u16(blocks + 4);
    uint32_t next = 0;
    if (m.entering != 0 && entry != kNone) next = run_block(r, entry);
    if (next == 0 && step != kNone) next = run_block(r, step);
    if (next != 0) {
        if (exit != kNone) (void)run_block(r, exit);
        machine_transition(m, next);
    }
    return kOk;
}

void vm_leave(const uint8_t* image, const VmLayout& layout, uint8_t* sv, uint8_t* ram, Machine& m) {
    if (m.started == 0 || m.pending != 0) return;  // no state entered, or the last one already left
    Run r;
    run_init(r, image, layout, sv, ram, m);
    if (m.state == 0 || m.state > r.p.states) return;
    const uint16_t exit = u16(r.p.st + 6u * (m.state - 1u) + 4u);
    if (exit != kNone) (void)run_block(r, exit);
}

}  // namespace fsw
