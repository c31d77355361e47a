// libfswsm (fswsm.h): the runtime's VM behind a C ABI for host programs.
// Everything that runs a machine is the runtime's own (fsw_vm.cpp and the
// helpers it calls); this file keeps a machine's pieces together in a
// handle, checks every argument before the runtime sees it (the VM trusts a
// verified image and checks nothing while it runs), reads layout files and
// says in words what it refused. Heap allowed: this is a host library.
#include "fswsm.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "fsw_element.h"
#include "fsw_machine.h"
#include "fsw_pal.h"
#include "fsw_sv.h"
#include "fsw_types.h"
#include "fsw_vm.h"

// ---- the runtime's platform layer, as far as the VM uses it ------------------------
// The critical section the VM takes for a `lock` state vector.
// The runtime's PAL names it; a host has no interrupts to turn off, so it is
// a re-entrant lock as in psl_native.cpp: a step on one thread and an
// element access on another over the same caller memory are serialised,
// as a task and an interrupt are on a board. (This lock is the library's
// only process-wide object; it holds no machine's state.)
namespace fsw {
// libfswsm runs every image of its evaluation type: a VM with every feature.
extern const uint16_t vm_features = kVmAllFeatures;

namespace pal {
namespace {
void* g_owner;
__thread unsigned t_depth;
__thread char t_token;
}  // namespace

IrqState critical_enter() {
    void* const me = &t_token;
    if (__atomic_load_n(&g_owner, __ATOMIC_ACQUIRE) == me) {
        ++t_depth;
        return 0;
    }
    void* expected = 0;
    while (!__atomic_compare_exchange_n(&g_owner, &expected, me, true, __ATOMIC_ACQUIRE, __ATOMIC_RELAXED))
        expected = 0;
    t_depth = 1;
    return 0;
}

void critical_exit(IrqState saved) {
    (void)saved;
    if (--t_depth == 0) __atomic_store_n(&g_owner, static_cast<void*>(0), __ATOMIC_RELEASE);
}

// fsw_vm.cpp can also verify an image kept in a board's EEPROM
// (vm_verify_eeprom); a host has none, and the library never calls it: the
// PAL's read is an erased chip's.
uint8_t eeprom_read(uint16_t addr) {
    (void)addr;
    return 0xFF;
}
}  // namespace pal
}  // namespace fsw

struct fswsm {
    // the layout
    fsw::VmElem* elems;
    uint32_t count;
    uint32_t schema;
    uint32_t sv_size;
    bool has_layout;
    char** names;       // count entries (NULL: no name), from a layout file
    char** aliases;     // count entries (NULL: no alias)
    char** state_names; // n_state_names entries, state id k + 1
    uint32_t n_state_names;
    uint8_t layout_real;  // the layout file's `real` (32, 64), 0 when it said none or came by fswsm_set_layout
    // the image
    uint8_t* image;
    uint32_t image_len;
    uint8_t* ram;
    uint32_t states;
    int reason;
    // the state vector (the caller's)
    uint8_t* sv;
    // the machine's bookkeeping
    fsw::Machine m;
    char err[512];
};

namespace {

const uint32_t kHeader = 28;  // docs/bytecode.md, "The image"

const char* const kTypeNames[] = {"I8", "I16", "I32", "I64", "U8", "U16", "U32", "U64", "F32", "F64", "bool"};

// The words of docs/bytecode.md's table (autocode/vmverify.py REASONS).
const char* const kReasons[] = {
    "ok",
    "bad magic (not a state-machine image)",
    "a format version or flags this runtime does not read",
    "compiled for the other evaluation type (f32/f64)",
    "bound to another state vector (schema hash or element count)",
    "the lengths in the header do not add up to the image",
    "an element index or offset not the layout's, or its type not the layout's",
    "a local index out of range, or a local outside the locals",
    "no states, a state index out of range, or a code offset out of range",
    "a window index, function or size out of range, or pushed out of order",
    "a jump backward, out of its block, or into an instruction",
    "stack underflow, deeper than the VM's stack or than declared, or not empty at the end",
    "an unknown opcode, or an operand past the code",
    "a block that does not end, unreachable code, or an offset not at a block's start",
    "goto outside .entry/.step, or a window push outside the prelude",
    "more pending forward jumps than the verifier tracks",
    "the RAM buffer is smaller than the image needs",
    "the state mask after the image is not a bit per state of it, or no state in it allows a switch",
    "a window function, value type or lock the board's VM was built without",
};
const char* const kReasonNames[] = {
    "kVmOk", "kVmBadMagic", "kVmBadVersion", "kVmBadReal", "kVmBadSchema", "kVmBadSize", "kVmBadElement",
    "kVmBadLocal", "kVmBadState", "kVmBadWindow", "kVmBadJump", "kVmBadStack", "kVmBadOpcode", "kVmBadEnd",
    "kVmBadPlace", "kVmTooNested", "kVmNoRam", "kVmBadMask", "kVmNoFeature",
};
const int kReasonCount = static_cast<int>(sizeof kReasons / sizeof kReasons[0]);
static_assert(sizeof kReasonNames / sizeof kReasonNames[0] == sizeof kReasons / sizeof kReasons[0],
              "a name for every reason's words");
static_assert(sizeof kReasons / sizeof kReasons[0] == fsw::kVmNoFeature + 1, "the words of every VmReason");

struct CodeText {
    int code;
    const char* name;
    const char* text;
};
const CodeText kCodes[] = {
    {FSWSM_OK, "FSWSM_OK", "ok"},
    {FSWSM_STEP_TIME, "FSWSM_STEP_TIME", "G did not increase since the previous step: nothing changed"},
    {FSWSM_STEP_CONFIG, "FSWSM_STEP_CONFIG", "the runtime refused to run the image"},
    {FSWSM_E_ARG, "FSWSM_E_ARG", "a null handle or pointer, or an argument out of its range"},
    {FSWSM_E_NOMEM, "FSWSM_E_NOMEM", "out of memory"},
    {FSWSM_E_VERIFY, "FSWSM_E_VERIFY", "the verifier refused the image"},
    {FSWSM_E_REAL, "FSWSM_E_REAL", "the image was compiled for the other evaluation type (f32/f64) than this library's"},
    {FSWSM_E_SCHEMA, "FSWSM_E_SCHEMA", "the image is bound to another state vector (schema hash or element count)"},
    {FSWSM_E_LAYOUT, "FSWSM_E_LAYOUT", "the layout is not valid"},
    {FSWSM_E_FILE, "FSWSM_E_FILE", "the file cannot be read"},
    {FSWSM_E_NO_LAYOUT, "FSWSM_E_NO_LAYOUT", "no layout given yet"},
    {FSWSM_E_NO_IMAGE, "FSWSM_E_NO_IMAGE", "no image loaded yet"},
    {FSWSM_E_NO_SV, "FSWSM_E_NO_SV", "no state vector bound yet"},
    {FSWSM_E_SMALL, "FSWSM_E_SMALL", "the buffer is smaller than the state vector"},
    {FSWSM_E_INDEX, "FSWSM_E_INDEX", "element index out of range"},
    {FSWSM_E_NAME, "FSWSM_E_NAME", "no element or state of that name"},
    {FSWSM_E_VALUE, "FSWSM_E_VALUE", "the element's type cannot hold the value"},
    {FSWSM_E_SIZE, "FSWSM_E_SIZE", "a length that is not the element's size, or an image too long"},
    {FSWSM_E_STATE, "FSWSM_E_STATE", "state id out of range"},
};

const CodeText* code_text(int code) {
    for (size_t k = 0; k < sizeof kCodes / sizeof kCodes[0]; ++k)
        if (kCodes[k].code == code) return &kCodes[k];
    return 0;
}

// Records the refusal's message on the handle and returns its code.
__attribute__((format(printf, 3, 4))) int fail(fswsm* h, int code, const char* fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(h->err, sizeof h->err, fmt, ap);
    va_end(ap);
    return code;
}

// "WHERE: " before the handle's message (a long path is cut, the message kept).
void prefix(fswsm* h, const char* where) {
    char msg[sizeof h->err];
    size_t n = strlen(where);
    if (n > 200) n = 200;
    memcpy(msg, where, n);
    msg[n] = ':';
    msg[n + 1] = ' ';
    size_t m = strlen(h->err);
    if (m > sizeof msg - n - 3) m = sizeof msg - n - 3;
    memcpy(msg + n + 2, h->err, m);
    msg[n + 2 + m] = 0;
    memcpy(h->err, msg, sizeof msg);
}

// A getter's refusal: the code's own words as the message.
int refuse(const fswsm* h, int code) {
    const CodeText* c = code_text(code);
    return fail(const_cast<fswsm*>(h), code, "%s", c != 0 ? c->text : "refused");
}

int ok(fswsm* h) {
    h->err[0] = 0;
    return FSWSM_OK;
}

char* dup(const char* s, size_t n) {
    char* d = static_cast<char*>(malloc(n + 1));
    if (d != 0) {
        memcpy(d, s, n);
        d[n] = 0;
    }
    return d;
}

void free_names(char** names, uint32_t n) {
    if (names == 0) return;
    for (uint32_t k = 0; k < n; ++k) free(names[k]);
    free(names);
}

void drop_image(fswsm* h) {
    free(h->image);
    free(h->ram);
    h->image = 0;
    h->ram = 0;
    h->image_len = 0;
    h->states = 0;
}

void drop_layout(fswsm* h) {
    drop_image(h);
    free(h->elems);
    free_names(h->names, h->count);
    free_names(h->aliases, h->count);
    free_names(h->state_names, h->n_state_names);
    h->elems = 0;
    h->names = h->aliases = h->state_names = 0;
    h->count = h->n_state_names = 0;
    h->schema = h->sv_size = 0;
    h->has_layout = false;
    h->sv = 0;
}

// A new layout, checked; names and state names (may be NULL) become the handle's.
int install_layout(fswsm* h, const uint16_t* offsets, const uint8_t* types, uint32_t count, uint32_t schema,
                   uint32_t sv_size, char** names, char** aliases, char** state_names, uint32_t n_states) {
    if (count > 0xFFFFu) return fail(h, FSWSM_E_LAYOUT, "a layout of %u elements: at most 65535", count);
    for (uint32_t k = 0; k < count; ++k) {
        const uint32_t size = fsw::elem_size(types[k]);
        if (size == 0) return fail(h, FSWSM_E_LAYOUT, "element %u: unknown type code %u", k, types[k]);
        if (static_cast<uint32_t>(offsets[k]) + size > sv_size)
            return fail(h, FSWSM_E_LAYOUT, "element %u (%s at offset %u) ends past the state vector's %u bytes", k,
                        kTypeNames[types[k]], offsets[k], sv_size);
    }
    fsw::VmElem* elems = static_cast<fsw::VmElem*>(malloc(sizeof(fsw::VmElem) * (count ? count : 1)));
    if (elems == 0) return fail(h, FSWSM_E_NOMEM, "out of memory for a layout of %u elements", count);
    for (uint32_t k = 0; k < count; ++k) {
        elems[k].off = offsets[k];
        elems[k].type = types[k];
    }
    // no two elements share a byte: in offset order, each ends where the next may start
    uint32_t* order = static_cast<uint32_t*>(malloc(sizeof(uint32_t) * (count ? count : 1)));
    if (order == 0) {
        free(elems);
        return fail(h, FSWSM_E_NOMEM, "out of memory for a layout of %u elements", count);
    }
    for (uint32_t k = 0; k < count; ++k) order[k] = (static_cast<uint32_t>(offsets[k]) << 16) | k;
    qsort(order, count, sizeof(uint32_t), [](const void* a, const void* b) -> int {
        const uint32_t x = *static_cast<const uint32_t*>(a), y = *static_cast<const uint32_t*>(b);
        return x < y ? -1 : x > y ? 1 : 0;
    });
    for (uint32_t k = 1; k < count; ++k) {
        const uint32_t a = order[k - 1u] & 0xFFFFu, b = order[k] & 0xFFFFu;  // a's offset first
        if (static_cast<uint32_t>(offsets[a]) + fsw::elem_size(types[a]) > offsets[b]) {
            const uint32_t lo = a < b ? a : b, hi = a < b ? b : a;  // named in layout order
            free(order);
            free(elems);
            return fail(h, FSWSM_E_LAYOUT, "elements %u (offset %u, %u bytes) and %u (offset %u) overlap", lo,
                        offsets[lo], fsw::elem_size(types[lo]), hi, offsets[hi]);
        }
    }
    free(order);
    drop_layout(h);
    h->elems = elems;
    h->count = count;
    h->schema = schema;
    h->sv_size = sv_size;
    h->names = names;
    h->aliases = aliases;
    h->state_names = state_names;
    h->n_state_names = n_states;
    h->layout_real = 0;  // a layout file's parse sets it after
    h->has_layout = true;
    return ok(h);
}

// ---- layout files (docs/cli.md, `fsw compile --layout`) ---------------------------

const int kMaxTokens = 8;

// Splits `line` (modified) into whitespace-separated tokens, up to '#'.
int tokens(char* line, char** tok) {
    int n = 0;
    char* p = line;
    for (;;) {
        while (*p == ' ' || *p == '\t' || *p == '\r') ++p;
        if (*p == 0 || *p == '#') return n;
        if (n == kMaxTokens) return kMaxTokens + 1;
        tok[n++] = p;
        while (*p != 0 && *p != ' ' && *p != '\t' && *p != '\r' && *p != '#') ++p;
        if (*p == '#') {
            *p = 0;
            return n;
        }
        if (*p != 0) *p++ = 0;
    }
}

// A whole unsigned number (decimal, or hex with 0x) no larger than `max`.
bool number(const char* s, uint64_t max, uint64_t& out) {
    if (*s == 0 || *s == '-' || *s == '+' || *s == ' ') return false;
    errno = 0;
    char* end;
    const unsigned long long v = strtoull(s, &end, 0);
    if (errno != 0 || *end != 0 || v > max) return false;
    out = v;
    return true;
}

int type_code(const char* name) {
    for (int t = 0; t <= fsw::kBool; ++t)
        if (strcmp(name, kTypeNames[t]) == 0) return t;
    return -1;
}

struct Parsed {
    uint16_t* offsets;
    uint8_t* types;
    char** names;
    char** aliases;
    char** states;
    uint64_t count, n_states, schema, size;
    uint8_t real;  // the `real` line's bits, 0 without one
    bool has_count, has_states, has_schema, has_size, has_version;
    uint32_t seen, seen_states;
};

void free_parsed(Parsed& p) {
    free(p.offsets);
    free(p.types);
    free_names(p.names, static_cast<uint32_t>(p.count));
    free_names(p.aliases, static_cast<uint32_t>(p.count));
    free_names(p.states, static_cast<uint32_t>(p.n_states));
}

bool name_ok(const char* s) {
    if (*s == 0) return false;
    for (const char* c = s; *c != 0; ++c)
        if (!(*c == '_' || (*c >= '0' && *c <= '9') || (*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z')))
            return false;
    return true;
}

// One line of a layout file; 0 or an error (message written).
int parse_line(fswsm* h, Parsed& p, char* line, unsigned ln, const char* where) {
    char* t[kMaxTokens];
    const int n = tokens(line, t);
    if (n == 0) return 0;
    if (n > kMaxTokens) return fail(h, FSWSM_E_LAYOUT, "%s:%u: too many fields", where, ln);
    uint64_t v;
    if (!p.has_version) {
        if (strcmp(t[0], "fswsm-layout") != 0 || n != 2)
            return fail(h, FSWSM_E_LAYOUT, "%s:%u: not a layout file (its first line must be `fswsm-layout 1`)",
                        where, ln);
        if (strcmp(t[1], "1") != 0)
            return fail(h, FSWSM_E_LAYOUT, "%s:%u: layout format %s: this library reads format 1", where, ln, t[1]);
        p.has_version = true;
        return 0;
    }
    const char* key = t[0];
    if (strcmp(key, "real") == 0) {  // the image's R, for the reader: the image's header is what counts
        if (n != 2 || (strcmp(t[1], "32") != 0 && strcmp(t[1], "64") != 0))
            return fail(h, FSWSM_E_LAYOUT, "%s:%u: `real` takes 32 or 64", where, ln);
        p.real = static_cast<uint8_t>(t[1][0] == '3' ? 32 : 64);  // held to the image's once it comes
        return 0;
    }
    if (strcmp(key, "schema") == 0 || strcmp(key, "size") == 0) {
        const bool schema = key[1] == 'c';
        if (n != 2 || !number(t[1], schema ? 0xFFFFFFFFull : 0x10007ull, v))
            return fail(h, FSWSM_E_LAYOUT, "%s:%u: `%s` takes a number%s", where, ln, key,
                        schema ? " (0x + 8 hex digits)" : " of bytes");
        if (schema ? p.has_schema : p.has_size) return fail(h, FSWSM_E_LAYOUT, "%s:%u: a second `%s`", where, ln, key);
        if (schema) {
            p.schema = v;
            p.has_schema = true;
        } else {
            p.size = v;
            p.has_size = true;
        }
        return 0;
    }
    if (strcmp(key, "elements") == 0 || strcmp(key, "states") == 0) {
        const bool elems = key[0] == 'e';
        if (n != 2 || !number(t[1], elems ? 0xFFFFull : 255ull, v))
            return fail(h, FSWSM_E_LAYOUT, "%s:%u: `%s` takes a count (at most %u)", where, ln, key,
                        elems ? 65535u : 255u);
        if (elems ? p.has_count : p.has_states) return fail(h, FSWSM_E_LAYOUT, "%s:%u: a second `%s`", where, ln, key);
        if (!elems && v == 0) return fail(h, FSWSM_E_LAYOUT, "%s:%u: `states 0`: a machine has a state at least", where, ln);
        const size_t k = v ? static_cast<size_t>(v) : 1u;
        if (elems) {
            p.count = v;
            p.has_count = true;
            p.offsets = static_cast<uint16_t*>(calloc(k, sizeof(uint16_t)));
            p.types = static_cast<uint8_t*>(calloc(k, 1));
            p.names = static_cast<char**>(calloc(k, sizeof(char*)));
            p.aliases = static_cast<char**>(calloc(k, sizeof(char*)));
            if (!p.offsets || !p.types || !p.names || !p.aliases) return fail(h, FSWSM_E_NOMEM, "out of memory");
        } else {
            p.n_states = v;
            p.has_states = true;
            p.states = static_cast<char**>(calloc(k, sizeof(char*)));
            if (!p.states) return fail(h, FSWSM_E_NOMEM, "out of memory");
        }
        return 0;
    }
    if (strcmp(key, "element") == 0) {
        if (!p.has_count) return fail(h, FSWSM_E_LAYOUT, "%s:%u: `element` before `elements N`", where, ln);
        if (n != 6 && n != 7)
            return fail(h, FSWSM_E_LAYOUT, "%s:%u: `element` takes INDEX NAME TYPE OFFSET SIZE [ALIAS]", where, ln);
        if (!number(t[1], 0xFFFFull, v) || v != p.seen)
            return fail(h, FSWSM_E_LAYOUT, "%s:%u: element index %s: expected %u (elements in layout order)", where,
                        ln, t[1], p.seen);
        if (p.seen >= p.count)
            return fail(h, FSWSM_E_LAYOUT, "%s:%u: more elements than `elements %u` says", where, ln,
                        static_cast<unsigned>(p.count));
        if (!name_ok(t[2])) return fail(h, FSWSM_E_LAYOUT, "%s:%u: `%s` is not a name", where, ln, t[2]);
        const int type = type_code(t[3]);
        if (type < 0) return fail(h, FSWSM_E_LAYOUT, "%s:%u: unknown type `%s`", where, ln, t[3]);
        uint64_t off, size;
        if (!number(t[4], 0xFFFFull, off)) return fail(h, FSWSM_E_LAYOUT, "%s:%u: offset `%s`", where, ln, t[4]);
        if (!number(t[5], 8ull, size) || size != fsw::elem_size(static_cast<uint8_t>(type)))
            return fail(h, FSWSM_E_LAYOUT, "%s:%u: size %s is not a %s's %u", where, ln, t[5], t[3],
                        fsw::elem_size(static_cast<uint8_t>(type)));
        if (n == 7 && !name_ok(t[6])) return fail(h, FSWSM_E_LAYOUT, "%s:%u: `%s` is not a name", where, ln, t[6]);
        if (n == 7 && ((strcmp(t[6], "G") == 0 && type != fsw::kU64) || (strcmp(t[6], "S") == 0 && type != fsw::kU32)))
            return fail(h, FSWSM_E_LAYOUT, "%s:%u: `%s` aliased %s is a %s: %s is a %s", where, ln, t[2], t[6], t[3],
                        t[6], t[6][0] == 'G' ? "U64" : "U32");
        for (uint32_t k = 0; k < p.seen; ++k) {  // a name or an alias names one element, whichever it meets
            const char* clash = strcmp(p.names[k], t[2]) == 0 || (p.aliases[k] && strcmp(p.aliases[k], t[2]) == 0)
                                    ? t[2]
                                : n == 7 && (strcmp(p.names[k], t[6]) == 0 || (p.aliases[k] && strcmp(p.aliases[k], t[6]) == 0))
                                    ? t[6]
                                    : 0;
            if (clash != 0) return fail(h, FSWSM_E_LAYOUT, "%s:%u: a second element named `%s`", where, ln, clash);
        }
        p.offsets[p.seen] = static_cast<uint16_t>(off);
        p.types[p.seen] = static_cast<uint8_t>(type);
        p.names[p.seen] = dup(t[2], strlen(t[2]));
        if (p.names[p.seen] == 0) return fail(h, FSWSM_E_NOMEM, "out of memory");
        if (n == 7) {
            p.aliases[p.seen] = dup(t[6], strlen(t[6]));
            if (p.aliases[p.seen] == 0) return fail(h, FSWSM_E_NOMEM, "out of memory");
        }
        ++p.seen;
        return 0;
    }
    if (strcmp(key, "state") == 0) {
        if (!p.has_states) return fail(h, FSWSM_E_LAYOUT, "%s:%u: `state` before `states N`", where, ln);
        if (n != 3) return fail(h, FSWSM_E_LAYOUT, "%s:%u: `state` takes ID NAME", where, ln);
        if (!number(t[1], 255ull, v) || v != p.seen_states + 1u)
            return fail(h, FSWSM_E_LAYOUT, "%s:%u: state id %s: expected %u (states in file order)", where, ln, t[1],
                        p.seen_states + 1u);
        if (p.seen_states >= p.n_states)
            return fail(h, FSWSM_E_LAYOUT, "%s:%u: more states than `states %u` says", where, ln,
                        static_cast<unsigned>(p.n_states));
        if (!name_ok(t[2])) return fail(h, FSWSM_E_LAYOUT, "%s:%u: `%s` is not a name", where, ln, t[2]);
        p.states[p.seen_states] = dup(t[2], strlen(t[2]));
        if (p.states[p.seen_states] == 0) return fail(h, FSWSM_E_NOMEM, "out of memory");
        ++p.seen_states;
        return 0;
    }
    return fail(h, FSWSM_E_LAYOUT, "%s:%u: unknown line `%s`", where, ln, key);
}

int parse_layout(fswsm* h, const char* text, const char* where) {
    Parsed p;
    memset(&p, 0, sizeof p);
    const size_t len = strlen(text);
    char* buf = dup(text, len);
    if (buf == 0) return fail(h, FSWSM_E_NOMEM, "out of memory");
    int r = 0;
    unsigned ln = 0;
    char* line = buf;
    while (r == 0 && line != 0) {
        ++ln;
        char* nl = strchr(line, '\n');
        if (nl != 0) *nl = 0;
        r = parse_line(h, p, line, ln, where);
        line = nl != 0 ? nl + 1 : 0;
    }
    free(buf);
    if (r == 0) {
        const char* missing = !p.has_version ? "`fswsm-layout 1` line (an empty file, or not a layout)"
                              : !p.has_schema ? "`schema`"
                              : !p.has_size   ? "`size`"
                              : !p.has_count  ? "`elements`"
                                              : 0;
        if (missing != 0) r = fail(h, FSWSM_E_LAYOUT, "%s: no %s", where, missing);
        else if (p.seen != p.count)
            r = fail(h, FSWSM_E_LAYOUT, "%s: %u element lines, `elements %u` says", where, p.seen,
                     static_cast<unsigned>(p.count));
        else if (p.seen_states != p.n_states)
            r = fail(h, FSWSM_E_LAYOUT, "%s: %u state lines, `states %u` says", where, p.seen_states,
                     static_cast<unsigned>(p.n_states));
    }
    if (r == 0) {
        r = install_layout(h, p.offsets, p.types, static_cast<uint32_t>(p.count), static_cast<uint32_t>(p.schema),
                           static_cast<uint32_t>(p.size), p.names, p.aliases, p.states,
                           static_cast<uint32_t>(p.n_states));
        if (r == 0) {
            p.names = p.aliases = p.states = 0;  // the handle's now
            h->layout_real = p.real;
        }
        else prefix(h, where);
    }
    free_parsed(p);
    return r;
}

// A whole file in memory (NUL-terminated), or NULL with the error written.
char* read_file(fswsm* h, const char* path, size_t& len, int& code) {
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {  // a FIFO or a device would block, or never end
        code = fail(h, FSWSM_E_FILE, "cannot read %s: not a regular file", path);
        return 0;
    }
    FILE* f = fopen(path, "rb");
    if (f == 0) {
        code = fail(h, FSWSM_E_FILE, "cannot read %s: %s", path, strerror(errno));
        return 0;
    }
    size_t cap = 4096;
    len = 0;
    char* buf = static_cast<char*>(malloc(cap + 1));
    while (buf != 0) {
        len += fread(buf + len, 1, cap - len, f);
        if (len < cap) break;
        if (cap >= (1u << 24)) {  // no layout or image is near this
            free(buf);
            fclose(f);
            code = fail(h, FSWSM_E_FILE, "%s: larger than 16 MiB: not an image or a layout", path);
            return 0;
        }
        cap *= 2;
        char* more = static_cast<char*>(realloc(buf, cap + 1));
        if (more == 0) free(buf);
        buf = more;
    }
    const bool bad = ferror(f) != 0;
    fclose(f);
    if (buf == 0) {
        code = fail(h, FSWSM_E_NOMEM, "out of memory reading %s", path);
        return 0;
    }
    if (bad) {
        free(buf);
        code = fail(h, FSWSM_E_FILE, "cannot read %s", path);
        return 0;
    }
    buf[len] = 0;
    return buf;
}

// ---- values -----------------------------------------------------------------------

double get_double(const uint8_t* p, uint8_t type) {
    using namespace fsw;
    switch (type) {
        case kI8: return load<int8_t>(p);
        case kI16: return load<int16_t>(p);
        case kI32: return load<int32_t>(p);
        case kI64: return static_cast<double>(load<int64_t>(p));
        case kU8: return *p;
        case kU16: return load<uint16_t>(p);
        case kU32: return load<uint32_t>(p);
        case kU64: return static_cast<double>(load<uint64_t>(p));
        case kF32: return load<float>(p);
        case kF64: return load<double>(p);
        default: return *p != 0 ? 1.0 : 0.0;
    }
}

// Whether `v` is an integer in [lo, hi) (bounds are powers of two or 0: exact).
bool integral_in(double v, double lo, double hi) { return v == v && v >= lo && v < hi && floor(v) == v; }

bool set_double(uint8_t* p, uint8_t type, double v) {
    using namespace fsw;
    switch (type) {
        case kI8: if (!integral_in(v, -128.0, 128.0)) return false; store<int8_t>(p, static_cast<int8_t>(v)); return true;
        case kI16: if (!integral_in(v, -32768.0, 32768.0)) return false; store<int16_t>(p, static_cast<int16_t>(v)); return true;
        case kI32:
            if (!integral_in(v, -2147483648.0, 2147483648.0)) return false;
            store<int32_t>(p, static_cast<int32_t>(v));
            return true;
        case kI64:
            if (!integral_in(v, -9223372036854775808.0, 9223372036854775808.0)) return false;
            store<int64_t>(p, static_cast<int64_t>(v));
            return true;
        case kU8: if (!integral_in(v, 0.0, 256.0)) return false; *p = static_cast<uint8_t>(v); return true;
        case kU16: if (!integral_in(v, 0.0, 65536.0)) return false; store<uint16_t>(p, static_cast<uint16_t>(v)); return true;
        case kU32:
            if (!integral_in(v, 0.0, 4294967296.0)) return false;
            store<uint32_t>(p, static_cast<uint32_t>(v));
            return true;
        case kU64:
            if (!integral_in(v, 0.0, 18446744073709551616.0)) return false;
            store<uint64_t>(p, static_cast<uint64_t>(v));
            return true;
        case kF32: store<float>(p, static_cast<float>(v)); return true;
        case kF64: store<double>(p, v); return true;
        default:
            if (v != 0.0 && v != 1.0) return false;
            *p = v != 0.0 ? 1 : 0;
            return true;
    }
}

// An element access: the handle, its state vector and the index checked.
int element(fswsm* h, uint32_t index) {
    if (!h->has_layout) return fail(h, FSWSM_E_NO_LAYOUT, "no layout given yet");
    if (index >= h->count)
        return fail(h, FSWSM_E_INDEX, "element index %u out of range: the layout has %u elements (0..%u)", index,
                    h->count, h->count ? h->count - 1u : 0u);
    if (h->sv == 0) return fail(h, FSWSM_E_NO_SV, "no state vector bound yet (fswsm_bind)");
    return FSWSM_OK;
}

const char* elem_label(const fswsm* h, uint32_t index) {
    return h->names != 0 && h->names[index] != 0 ? h->names[index] : "";
}

}  // namespace

// ---- the library -----------------------------------------------------------------------

extern "C" {

int fswsm_real_bytes(void) { return static_cast<int>(sizeof(fsw::Real)); }

int fswsm_abi(void) { return FSWSM_ABI; }

const char* fswsm_error_name(int code) {
    const CodeText* c = code_text(code);
    return c != 0 ? c->name : "unknown";
}

const char* fswsm_error_text(int code) {
    const CodeText* c = code_text(code);
    return c != 0 ? c->text : "unknown code";
}

const char* fswsm_reason_text(int reason) {
    return reason >= 0 && reason < kReasonCount ? kReasons[reason] : "unknown reason";
}

const char* fswsm_type_name(int type) { return type >= 0 && type <= fsw::kBool ? kTypeNames[type] : ""; }

int fswsm_type_size(int type) { return type >= 0 && type <= 255 ? fsw::elem_size(static_cast<uint8_t>(type)) : 0; }

fswsm* fswsm_create(void) {
    fswsm* h = static_cast<fswsm*>(calloc(1, sizeof(fswsm)));
    if (h != 0) fsw::machine_reset(h->m, 1);
    return h;
}

void fswsm_destroy(fswsm* h) {
    if (h == 0) return;
    drop_layout(h);
    free(h);
}

const char* fswsm_last_error(const fswsm* h) { return h != 0 ? h->err : "a null handle"; }

int fswsm_reason(const fswsm* h) { return h != 0 ? h->reason : 0; }

// ---- the layout -------------------------------------------------------------------------

int fswsm_set_layout(fswsm* h, const uint16_t* offsets, const uint8_t* types, uint32_t count, uint32_t schema,
                     uint32_t sv_size) {
    if (h == 0) return FSWSM_E_ARG;
    if (count != 0 && (offsets == 0 || types == 0)) return fail(h, FSWSM_E_ARG, "fswsm_set_layout: null array");
    return install_layout(h, offsets, types, count, schema, sv_size, 0, 0, 0, 0);
}

int fswsm_layout_text(fswsm* h, const char* text) {
    if (h == 0) return FSWSM_E_ARG;
    if (text == 0) return fail(h, FSWSM_E_ARG, "fswsm_layout_text: null text");
    return parse_layout(h, text, "layout");
}

int fswsm_layout_file(fswsm* h, const char* path) {
    if (h == 0) return FSWSM_E_ARG;
    if (path == 0) return fail(h, FSWSM_E_ARG, "fswsm_layout_file: null path");
    size_t len;
    int code = 0;
    char* text = read_file(h, path, len, code);
    if (text == 0) return code;
    if (strlen(text) != len) {
        free(text);
        return fail(h, FSWSM_E_LAYOUT, "%s: not a text file (a NUL byte)", path);
    }
    const int r = parse_layout(h, text, path);
    free(text);
    return r;
}

int fswsm_sv_size(const fswsm* h, uint32_t* size) {
    if (h == 0) return FSWSM_E_ARG;
    if (size == 0) return refuse(h, FSWSM_E_ARG);
    if (!h->has_layout) return refuse(h, FSWSM_E_NO_LAYOUT);
    *size = h->sv_size;
    return FSWSM_OK;
}

int fswsm_element_count(const fswsm* h, uint32_t* count) {
    if (h == 0) return FSWSM_E_ARG;
    if (count == 0) return refuse(h, FSWSM_E_ARG);
    if (!h->has_layout) return refuse(h, FSWSM_E_NO_LAYOUT);
    *count = h->count;
    return FSWSM_OK;
}

int fswsm_schema(const fswsm* h, uint32_t* schema) {
    if (h == 0) return FSWSM_E_ARG;
    if (schema == 0) return refuse(h, FSWSM_E_ARG);
    if (!h->has_layout) return refuse(h, FSWSM_E_NO_LAYOUT);
    *schema = h->schema;
    return FSWSM_OK;
}

int fswsm_element_info(const fswsm* h, uint32_t index, uint8_t* type, uint32_t* offset, uint32_t* size) {
    if (h == 0) return FSWSM_E_ARG;
    if (!h->has_layout) return refuse(h, FSWSM_E_NO_LAYOUT);
    if (index >= h->count) return refuse(h, FSWSM_E_INDEX);
    if (type != 0) *type = h->elems[index].type;
    if (offset != 0) *offset = h->elems[index].off;
    if (size != 0) *size = fsw::elem_size(h->elems[index].type);
    return FSWSM_OK;
}

const char* fswsm_element_name(const fswsm* h, uint32_t index) {
    if (h == 0 || !h->has_layout || index >= h->count) return 0;
    return elem_label(h, index);
}

int fswsm_element_index(const fswsm* h, const char* name, uint32_t* index) {
    if (h == 0) return FSWSM_E_ARG;
    if (name == 0 || index == 0) return refuse(h, FSWSM_E_ARG);
    if (!h->has_layout) return refuse(h, FSWSM_E_NO_LAYOUT);
    for (uint32_t k = 0; k < h->count; ++k) {
        if ((h->names != 0 && h->names[k] != 0 && strcmp(h->names[k], name) == 0) ||
            (h->aliases != 0 && h->aliases[k] != 0 && strcmp(h->aliases[k], name) == 0)) {
            *index = k;
            return FSWSM_OK;
        }
    }
    return fail(const_cast<fswsm*>(h), FSWSM_E_NAME, "no element named `%s` in the layout", name);
}

// ---- the image ----------------------------------------------------------------------------

int fswsm_load_image(fswsm* h, const uint8_t* image, uint32_t len) {
    if (h == 0) return FSWSM_E_ARG;
    if (image == 0) return fail(h, FSWSM_E_ARG, "fswsm_load_image: null image");
    if (!h->has_layout) return fail(h, FSWSM_E_NO_LAYOUT, "no layout given yet: the image is verified against it");
    if (len > 0xFFFFu) {
        h->reason = fsw::kVmBadSize;
        return fail(h, FSWSM_E_SIZE, "an image of %u bytes: the format holds at most 65535", len);
    }
    // R first, by the header's byte 5, with a message that says which library to use.
    if (len >= 6 && memcmp(image, "FSMB", 4) == 0 && image[5] != sizeof(fsw::Real)) {
        h->reason = fsw::kVmBadReal;
        if (image[5] == 4 || image[5] == 8)
            return fail(h, FSWSM_E_REAL, "the image is binary%u (R = %u bytes) and this library is libfswsm%u "
                        "(binary%u): load it with libfswsm%u", image[5] * 8u, image[5],
                        static_cast<unsigned>(sizeof(fsw::Real)) * 8u, static_cast<unsigned>(sizeof(fsw::Real)) * 8u,
                        image[5] * 8u);
        return fail(h, FSWSM_E_REAL, "the image's R is %u bytes: neither binary32 (4) nor binary64 (8)", image[5]);
    }
    if (h->layout_real != 0 && h->layout_real != sizeof(fsw::Real) * 8u) {
        h->reason = 0;
        return fail(h, FSWSM_E_REAL, "the layout is of binary%u images, and this library is libfswsm%u (binary%u): "
                    "a layout of another compile of the machine", h->layout_real,
                    static_cast<unsigned>(sizeof(fsw::Real)) * 8u, static_cast<unsigned>(sizeof(fsw::Real)) * 8u);
    }
    const uint32_t ram_size = len >= kHeader ? fsw::vm_ram_size(image, static_cast<uint16_t>(len)) : 0;
    uint8_t* copy = static_cast<uint8_t*>(malloc(len ? len : 1));
    uint8_t* ram = static_cast<uint8_t*>(malloc(ram_size ? ram_size : 1));  // malloc: aligned for any Real
    if (copy == 0 || ram == 0) {
        free(copy);
        free(ram);
        return fail(h, FSWSM_E_NOMEM, "out of memory for an image of %u bytes", len);
    }
    memcpy(copy, image, len);
    fsw::VmLayout layout = {h->elems, static_cast<uint16_t>(h->count), h->schema};
    const fsw::VmReason why = fsw::vm_verify(copy, static_cast<uint16_t>(len), layout, ram_size);
    h->reason = why;
    if (why != fsw::kVmOk) {
        free(copy);
        free(ram);
        if (why == fsw::kVmBadSchema) {
            // The header was read (len >= 28): its schema hash and element count.
            const uint32_t schema = static_cast<uint32_t>(image[8]) | (static_cast<uint32_t>(image[9]) << 8) |
                                    (static_cast<uint32_t>(image[10]) << 16) | (static_cast<uint32_t>(image[11]) << 24);
            return fail(h, FSWSM_E_SCHEMA, "the image is bound to state vector 0x%08x of %u elements, the layout "
                        "is 0x%08x of %u elements (reason 4, kVmBadSchema: %s)", static_cast<unsigned>(schema),
                        static_cast<unsigned>(image[12] | (image[13] << 8)), static_cast<unsigned>(h->schema),
                        static_cast<unsigned>(h->count), kReasons[why]);
        }
        return fail(h, why == fsw::kVmBadReal ? FSWSM_E_REAL : FSWSM_E_VERIFY,
                    "the verifier refused the image: reason %d, %s: %s", static_cast<int>(why),
                    why < kReasonCount ? kReasonNames[why] : "?", why < kReasonCount ? kReasons[why] : "?");
    }
    // what the layout's names say of the image: its states, and the elements it calls G and S
    if (h->n_state_names != 0 && h->n_state_names != copy[18]) {
        const unsigned states = copy[18];
        free(copy);
        free(ram);
        return fail(h, FSWSM_E_LAYOUT, "the layout names %u states and the image has %u: a layout of another "
                    "machine", h->n_state_names, states);
    }
    for (uint32_t k = 0; h->aliases != 0 && k < h->count; ++k) {
        const char* alias = h->aliases[k];
        if (alias == 0 || (strcmp(alias, "G") != 0 && strcmp(alias, "S") != 0)) continue;
        const unsigned at = alias[0] == 'G' ? 14u : 16u;  // the header's G and S: their byte offsets
        const unsigned off = static_cast<unsigned>(copy[at] | (copy[at + 1u] << 8));
        unsigned index = 0;  // the element there (the verifier found one)
        while (index < h->count && h->elems[index].off != off) ++index;
        if (index != k) {
            free(copy);
            free(ram);
            return fail(h, FSWSM_E_LAYOUT, "the layout calls element %u %s, and the image's %s is element %u: a "
                        "layout of another state vector", k, alias, alias, index);
        }
    }
    drop_image(h);
    h->image = copy;
    h->image_len = len;
    h->ram = ram;
    h->states = copy[18];
    fsw::vm_reset(h->image, h->ram, h->m, 1);
    return ok(h);
}

int fswsm_load_image_file(fswsm* h, const char* path) {
    if (h == 0) return FSWSM_E_ARG;
    if (path == 0) return fail(h, FSWSM_E_ARG, "fswsm_load_image_file: null path");
    size_t len;
    int code = 0;
    char* data = read_file(h, path, len, code);
    if (data == 0) return code;
    if (len > 0xFFFFu) {
        free(data);
        h->reason = fsw::kVmBadSize;
        return fail(h, FSWSM_E_SIZE, "%s: %u bytes: an image holds at most 65535", path, static_cast<unsigned>(len));
    }
    const int r = fswsm_load_image(h, reinterpret_cast<const uint8_t*>(data), static_cast<uint32_t>(len));
    free(data);
    if (r != FSWSM_OK) prefix(h, path);
    return r;
}

int fswsm_state_count(const fswsm* h, uint32_t* states) {
    if (h == 0) return FSWSM_E_ARG;
    if (states == 0) return refuse(h, FSWSM_E_ARG);
    if (h->image == 0) return refuse(h, FSWSM_E_NO_IMAGE);
    *states = h->states;
    return FSWSM_OK;
}

const char* fswsm_state_name(const fswsm* h, uint32_t id) {
    if (h == 0 || id == 0) return 0;
    const uint32_t n = h->image != 0 ? h->states : h->n_state_names;
    if (id > n) return 0;
    return id <= h->n_state_names && h->state_names[id - 1u] != 0 ? h->state_names[id - 1u] : "";
}

int fswsm_state_id(const fswsm* h, const char* name, uint32_t* id) {
    if (h == 0) return FSWSM_E_ARG;
    if (name == 0 || id == 0) return refuse(h, FSWSM_E_ARG);
    for (uint32_t k = 0; k < h->n_state_names; ++k) {
        if (h->state_names[k] != 0 && strcmp(h->state_names[k], name) == 0) {
            *id = k + 1u;
            return FSWSM_OK;
        }
    }
    return fail(const_cast<fswsm*>(h), FSWSM_E_NAME, "no state named `%s` in the layout", name);
}

// ---- running ----------------------------------------------------------------------------------

int fswsm_bind(fswsm* h, uint8_t* sv, uint32_t len) {
    if (h == 0) return FSWSM_E_ARG;
    if (!h->has_layout) return fail(h, FSWSM_E_NO_LAYOUT, "no layout given yet: it says how large the buffer must be");
    if (sv == 0) {
        h->sv = 0;
        return ok(h);
    }
    if (len < h->sv_size)
        return fail(h, FSWSM_E_SMALL, "a buffer of %u bytes: the state vector has %u", len, h->sv_size);
    h->sv = sv;
    return ok(h);
}

int fswsm_reset(fswsm* h, uint32_t id) {
    if (h == 0) return FSWSM_E_ARG;
    if (h->image == 0) return fail(h, FSWSM_E_NO_IMAGE, "no image loaded yet");
    if (id == 0 || id > h->states)
        return fail(h, FSWSM_E_STATE, "state id %u out of range: the machine has states 1..%u", id, h->states);
    fsw::vm_reset(h->image, h->ram, h->m, id);
    return ok(h);
}

int fswsm_step(fswsm* h) {
    if (h == 0) return FSWSM_E_ARG;
    if (h->image == 0) return fail(h, FSWSM_E_NO_IMAGE, "no image loaded yet");
    if (h->sv == 0) return fail(h, FSWSM_E_NO_SV, "no state vector bound yet (fswsm_bind)");
    fsw::VmLayout layout = {h->elems, static_cast<uint16_t>(h->count), h->schema};
    const fsw::Result r = fsw::vm_step(h->image, layout, h->sv, h->ram, h->m);
    if (r == fsw::kErrTime) return fail(h, FSWSM_STEP_TIME, "G did not increase: %llu after %llu",
                                        static_cast<unsigned long long>(fsw::load<uint64_t>(
                                            h->sv + (h->image[14] | (h->image[15] << 8)))),
                                        static_cast<unsigned long long>(h->m.last_g));
    if (r != fsw::kOk) return fail(h, static_cast<int>(r), "the runtime refused the step (Result %d)", static_cast<int>(r));
    return ok(h);
}

int fswsm_state(const fswsm* h, uint32_t* id) {
    if (h == 0) return FSWSM_E_ARG;
    if (id == 0) return refuse(h, FSWSM_E_ARG);
    if (h->image == 0) return refuse(h, FSWSM_E_NO_IMAGE);
    *id = h->m.state;
    return FSWSM_OK;
}

int fswsm_time_in_state(const fswsm* h, uint64_t* t) {
    if (h == 0) return FSWSM_E_ARG;
    if (t == 0) return refuse(h, FSWSM_E_ARG);
    if (h->image == 0) return refuse(h, FSWSM_E_NO_IMAGE);
    *t = machine_T(h->m);
    return FSWSM_OK;
}

// ---- elements ----------------------------------------------------------------------------------

int fswsm_get(const fswsm* h, uint32_t index, double* value) {
    if (h == 0) return FSWSM_E_ARG;
    fswsm* w = const_cast<fswsm*>(h);  // for the message only
    if (value == 0) return fail(w, FSWSM_E_ARG, "fswsm_get: null value pointer");
    const int r = element(w, index);
    if (r != FSWSM_OK) return r;
    const fsw::VmElem& e = h->elems[index];
    fsw::SvGuard<true> g;
    *value = get_double(h->sv + e.off, e.type);
    return FSWSM_OK;
}

int fswsm_set(fswsm* h, uint32_t index, double value) {
    if (h == 0) return FSWSM_E_ARG;
    const int r = element(h, index);
    if (r != FSWSM_OK) return r;
    const fsw::VmElem& e = h->elems[index];
    bool done;
    {
        fsw::SvGuard<true> g;
        done = set_double(h->sv + e.off, e.type, value);
    }
    if (!done)
        return fail(h, FSWSM_E_VALUE, "element %u %s (%s) cannot hold %.17g%s", index, elem_label(h, index),
                    kTypeNames[e.type], value,
                    e.type == fsw::kBool ? ": a bool takes 0 or 1" : ": an integer element takes a whole number "
                                                                     "inside its range");
    return ok(h);
}

int fswsm_get_raw(const fswsm* h, uint32_t index, void* out, uint32_t len) {
    if (h == 0) return FSWSM_E_ARG;
    fswsm* w = const_cast<fswsm*>(h);
    if (out == 0) return fail(w, FSWSM_E_ARG, "fswsm_get_raw: null buffer");
    const int r = element(w, index);
    if (r != FSWSM_OK) return r;
    const fsw::VmElem& e = h->elems[index];
    if (len != fsw::elem_size(e.type))
        return fail(w, FSWSM_E_SIZE, "element %u %s is a %s of %u bytes, not %u", index, elem_label(h, index),
                    kTypeNames[e.type], fsw::elem_size(e.type), len);
    fsw::SvGuard<true> g;
    memcpy(out, h->sv + e.off, len);
    return FSWSM_OK;
}

int fswsm_set_raw(fswsm* h, uint32_t index, const void* in, uint32_t len) {
    if (h == 0) return FSWSM_E_ARG;
    if (in == 0) return fail(h, FSWSM_E_ARG, "fswsm_set_raw: null buffer");
    const int r = element(h, index);
    if (r != FSWSM_OK) return r;
    const fsw::VmElem& e = h->elems[index];
    if (len != fsw::elem_size(e.type))
        return fail(h, FSWSM_E_SIZE, "element %u %s is a %s of %u bytes, not %u", index, elem_label(h, index),
                    kTypeNames[e.type], fsw::elem_size(e.type), len);
    fsw::SvGuard<true> g;
    memcpy(h->sv + e.off, in, len);
    return ok(h);
}

}  // extern "C"
