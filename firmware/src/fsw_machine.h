// State-machine bookkeeping (spec 4.6) for generated step() functions:
// current state, first-step flag, entry time, T in exact U64 arithmetic
// (worked out where it is read: G at the last step less G at the state's
// entry), and the "G must strictly increase" check.
#ifndef FSW_MACHINE_H
#define FSW_MACHINE_H

#include "fsw_convert.h"
#include "fsw_element.h"
#include "fsw_types.h"

namespace fsw {

// One per machine. Static, initialised with FSW_MACHINE_INIT(first state id)
// or machine_reset().
struct Machine {
    uint64_t last_g;    // G at the previous accepted step
    uint64_t entry_g;   // G at the first step of the current state
    uint32_t state;     // current state id (1, 2, ...)
    uint8_t pending;    // 1: the next step is the first in `state`
    uint8_t entering;   // 1: the current step is the first in `state`
    uint8_t started;    // 1: at least one step was accepted (last_g valid)
    // (No copy of T, the current step's last_g - entry_g: machine_T and the
    // functions below work it out from the two where it is read, 8 bytes of
    // RAM a machine less.)
};

#define FSW_MACHINE_INIT(initial_state) {0, 0, (initial_state), 1, 0, 0}

// What a flight's resume keeps of a Machine (docs/safety.md): all of it.
static const uint16_t kMachineKept = sizeof(Machine);

// Puts the machine in `initial_state`, as before its first step.
inline void machine_reset(Machine& m, uint32_t initial_state) {
    m.last_g = 0;
    m.entry_g = 0;
    m.state = initial_state;
    m.pending = 1;
    m.entering = 0;
    m.started = 0;
}

// Steps 1-2 of spec 4.6. kErrTime (and no change at all) when G is not
// strictly greater than at the previous step. Otherwise, on the first step
// in a state records the entry time and sets `entering` (the caller then
// writes m.state to S and runs .entry). T is then G - entry time.
FSW_MUST_CHECK inline Result machine_begin_step(Machine& m, uint64_t g) {
    if (m.started != 0 && g <= m.last_g) return kErrTime;
    m.started = 1;
    m.last_g = g;
    m.entering = m.pending;
    if (m.pending != 0) {
        m.entry_g = g;
        m.pending = 0;
    }
    return kOk;
}

// What generated step() functions call: machine_begin_step with G read from
// its element at `g`, and on a state's first step the state id written to
// the S element at `s` (U32). Out of line: one copy for all the machines.
// A Machine of all zeros (static storage, no initialiser: .bss, no copy of
// it in flash) is FSW_MACHINE_INIT(1) to machine_begin, the first state of
// every generated machine.
#if defined(__AVR__)
FSW_MUST_CHECK FSW_NOINLINE FSW_NOCLONE Result machine_begin(Machine& m, const uint8_t* g, uint8_t* s);
#else
FSW_MUST_CHECK inline Result machine_begin(Machine& m, const uint8_t* g, uint8_t* s) {
    if (m.state == 0 && m.started == 0) machine_reset(m, 1);  // a zero Machine
    if (machine_begin_step(m, load<uint64_t>(g)) != kOk) return kErrTime;
    if (m.entering != 0) store<uint32_t>(s, m.state);
    return kOk;
}
#endif

// Whether G at `g` is the G of the machine's last accepted step: a cycle
// that started in the same tick of a coarse clock as the one before (the
// cycle right after a late one can). A machine task then leaves the step
// for its next run rather than run one the step refuses (kErrTime, which
// safes the task); a G that went back is still the step's error.
inline bool machine_same_tick(const Machine& m, const uint8_t* g) {
    return m.started != 0 && memcmp(g, &m.last_g, sizeof m.last_g) == 0;  // bytes: no 64-bit compare inline
}

// T, the time spent in the current state (valid after machine_begin_step):
// G at the step less G at the state's entry.
inline uint64_t machine_T(const Machine& m) { return m.last_g - m.entry_g; }

// T saturated to 32 bits: for a constant c < 0xFFFFFFFF, `T op c` is
// `machine_T32(m) op c` (T >= 2^32 compares as 0xFFFFFFFF does), a 32-bit
// test where an 8-bit MCU would otherwise compare 8 bytes. Out of line on AVR.
#if defined(__AVR__)
FSW_NOINLINE uint32_t machine_T32(const Machine& m);
#else
inline uint32_t machine_T32(const Machine& m) {
    const uint64_t t = machine_T(m);
    return (t >> 32) != 0 ? 0xFFFFFFFFUL : static_cast<uint32_t>(t);
}
#endif

// `-> target`, called after the current state's .exit ran: the next step
// is the target's first (a state may transition to itself).
inline void machine_transition(Machine& m, uint32_t target) {
    m.state = target;
    m.pending = 1;
}

// R(T), what T reads as in an expression: real_from_U64(T), on AVR without
// the 64-bit conversion routine (a 32-bit conversion, exact scaling).
#if defined(__AVR__)
FSW_NOINLINE FSW_NOCLONE Real machine_T_real(const Machine& m);
#else
inline Real machine_T_real(const Machine& m) { return real_from_U64(machine_T(m)); }
#endif

// `x = T` for an integer x whose largest value is hi (< 2^32): R(T)
// converted to x's type, which for T >= 0 is R(T) saturated at hi: T itself
// where R holds it, else T rounded to R's precision (binary32: 24 bits,
// ties to even). No float code. Out of line: inline, its values took the
// registers of the machine's step around it (the rocket's mission spilled
// them to a stack frame).
FSW_NOINLINE uint32_t round_f32_saturated(uint32_t v, uint32_t hi);
inline uint32_t machine_T_int(const Machine& m, uint32_t hi) {
    const uint32_t v = machine_T32(m);
#if FSW_REAL_IS_FLOAT
    return round_f32_saturated(v, hi);
#else
    return v > hi ? hi : v;  // binary64 holds every T32 exactly; T >= 2^32 saturates
#endif
}

}  // namespace fsw

#endif  // FSW_MACHINE_H
