// Analog and digital I/O tasks (spec 6): constant channel tables moving
// values between pins and state vector elements, run as executor tasks.
#ifndef FSW_IO_H
#define FSW_IO_H

#include "fsw_convert.h"
#include "fsw_pal.h"
#include "fsw_types.h"

namespace fsw {

enum IoDir : uint8_t { kIoIn = 0, kIoInPullup = 1, kIoOut = 2 };

// Analog channel: inputs write `count * gain + offset` into an F32/F64
// element, where the generator folded the board's converter and the .aio's
// calibration (`volts * scale + offset`) into one multiply-add:
// gain = scale * vref / (2^bits - 1), computed on the host
// (fswkit.autocode.iotables.analog_gain), so no division runs on the MCU.
// Outputs drive PWM from an F32/F64 element in volts (0..vref).
struct AnalogChannel {
    Real gain;        // inputs: element units per ADC count
    Real offset;      // inputs: the element's value at count 0
    ElemOff off;      // element offset in the state vector
    uint8_t pin;      // board pin number (A0 = 14 on an Uno)
    uint8_t dir;      // kIoIn or kIoOut
    uint8_t type;     // kF32 or kF64
};

// A table of inputs only may sample in the background (`raw` set): each
// task run converts the counts the previous run's scan left in `raw`, then
// starts the next scan (pal::adc_scan_start), so the task never waits on
// the converter; an element then holds the inputs of one run earlier (one
// executor period of latency at the task's rate). io_analog_begin fills
// `raw` once, so the first run reads the pins as they were at boot. With
// `raw` null the task reads each pin as it runs (waiting on each conversion).
struct AnalogTable {
    const AnalogChannel* ch;  // FSW_FLASH rows
    uint8_t* sv;
    Real vref;        // ADC reference and PWM full scale, volts
    uint8_t n;
    uint8_t adc_bits; // ADC resolution: full scale is 2^bits - 1
    bool lock;        // state vector `lock` option
    volatile uint16_t* raw;  // n counts written in the background, or null
};

// Digital channel: a bool element mirrored from (kIoIn, kIoInPullup) or
// onto (kIoOut) a pin.
struct DigitalChannel {
    ElemOff off;
    uint8_t pin;
    uint8_t dir;
};

struct DigitalTable {
    const DigitalChannel* ch;  // FSW_FLASH rows
    uint8_t* sv;
    uint8_t n;
    bool lock;
};

// Checks the table and sets pin modes; a table sampled in the background
// (inputs only) is converted once, waiting. `table` points at an FSW_FLASH object.
FSW_MUST_CHECK Result io_analog_begin(const AnalogTable* table);

FSW_MUST_CHECK Result io_digital_begin(const DigitalTable* table);

// Executor task steps; ctx is the FSW_FLASH table. One pass over the table.
Result io_analog_task(void* ctx);
// The same for a table whose elements are all F32 (the generator picks it):
// it links no binary64 conversion, which AVR does in software.
Result io_analog_task_f32(void* ctx);
// The same for a table of F32 inputs only (the generator groups channels by
// direction): it links no PWM output either. A row of another type or
// direction is refused (kErrConfig), not served.
Result io_analog_in_task_f32(void* ctx);
Result io_digital_task(void* ctx);

// ---- digital channels, one call each (generated I/O tasks) -----------------
// `FSW_PIN(n, X, b)` names board pin n, which the generator resolved to bit b
// of port X. With FSW_AVR_PORTS (AVR) it is that port's registers, so the
// calls below compile to a few instructions (sbi/cbi, sbis) with nothing
// looked up at run time, and no PWM turn-off as digitalWrite does: a
// digital channel's pin is never a PWM output (a pin serves one channel;
// analog outputs only use PWM pins of their own) and the core's init()
// connects no timer to a pin. Otherwise it is the pin number, served by the
// PAL (pal::pin_mode, digital_read, digital_write).
#if FSW_AVR_PORTS
struct Pin {
    volatile uint8_t* in;   // PINx
    volatile uint8_t* ddr;  // DDRx
    volatile uint8_t* out;  // PORTx
    uint8_t mask;           // the pin's bit
};
#define FSW_PIN(n, port, bit) (::fsw::Pin{&PIN##port, &DDR##port, &PORT##port, static_cast<uint8_t>(1u << (bit))})

// Sets or clears the pin's bit of a port register: sbi/cbi (atomic) in the
// low I/O space, else with interrupts off (ATmega2560 ports H..L), as the
// Arduino core does.
inline __attribute__((always_inline)) void pin_reg_write(volatile uint8_t* r, uint8_t mask, bool set) {
    const bool low_io = reinterpret_cast<uintptr_t>(r) < 0x40u + __SFR_OFFSET;
    const pal::IrqState saved = low_io ? 0 : pal::critical_enter();
    if (set) {
        *r = static_cast<uint8_t>(*r | mask);
    } else {
        *r = static_cast<uint8_t>(*r & ~mask);
    }
    if (!low_io) pal::critical_exit(saved);
}

// A channel's pin mode at boot: kIoOut an output; kIoIn an input, pull-up
// off; kIoInPullup an input with the pull-up on (as pinMode).
inline __attribute__((always_inline)) void io_pin_begin(Pin pin, uint8_t dir) {
    pin_reg_write(pin.ddr, pin.mask, dir == kIoOut);
    if (dir != kIoOut) pin_reg_write(pin.out, pin.mask, dir == kIoInPullup);
}
// The bool element at `p` mirrors an input pin (1 high, 0 low).
inline __attribute__((always_inline)) void io_digital_in(Pin pin, uint8_t* p) {
    *p = (*pin.in & pin.mask) != 0 ? 1 : 0;  // one byte: no lock needed
}
// An output pin follows the bool element at `p` (any non-zero byte: high).
inline __attribute__((always_inline)) void io_digital_out(Pin pin, const uint8_t* p) {
    pin_reg_write(pin.out, pin.mask, *p != 0);
}
#else
struct Pin {
    uint8_t n;  // board pin number
};
#define FSW_PIN(n, port, bit) (::fsw::Pin{(n)})

inline void io_pin_begin(Pin pin, uint8_t dir) {
    pal::pin_mode(pin.n, dir == kIoOut ? pal::kOutput : dir == kIoInPullup ? pal::kInputPullup : pal::kInput);
}
inline void io_digital_in(Pin pin, uint8_t* p) { *p = pal::digital_read(pin.n) ? 1 : 0; }
inline void io_digital_out(Pin pin, const uint8_t* p) { pal::digital_write(pin.n, *p != 0); }
#endif

// A pin's level now, and a pin driven high or low (what io_digital_in/out do
// without an element): the pyro gate reads the arming pins and drives the
// pyro pin through these.
#if FSW_AVR_PORTS
inline __attribute__((always_inline)) bool io_pin_read(Pin pin) { return (*pin.in & pin.mask) != 0; }
inline __attribute__((always_inline)) void io_pin_write(Pin pin, bool high) { pin_reg_write(pin.out, pin.mask, high); }
#else
inline bool io_pin_read(Pin pin) { return pal::digital_read(pin.n); }
inline void io_pin_write(Pin pin, bool high) { pal::digital_write(pin.n, high); }
#endif

// ---- pyro channels: the run-time gate (docs/safety.md) -----------------------
// One per [pyro] channel, zero at boot (static storage): no pulse, the
// element last seen false. Kept across a reset in flight (fsw_resume.h),
// when the pulse in progress is dropped (pyro_resumed).
struct PyroGate {
    uint16_t left;   // runs of the outputs task the pin may still stay high
    uint8_t last;    // 1: the element was true at the previous run
    uint8_t status;  // kPyro* bits as of the last run: the health frame's
};

// A channel's status bits (PyroGate::status, one byte a channel in the
// health frame: docs/telemetry.md).
static const uint8_t kPyroArmed = 0x01;       // every arming pin read armed
static const uint8_t kPyroContinuity = 0x02;  // the continuity reading was at or above its minimum
static const uint8_t kPyroNoSense = 0x04;     // the channel declares no continuity input
static const uint8_t kPyroFired = 0x08;       // a pulse has started since the flight began (kept across a resume)
static const uint8_t kPyroFiring = 0x10;      // the pin is high
static const uint8_t kPyroRose = 0x20;        // the pin went high at this run: a new pulse

// The level of a pyro pin at this run of the outputs task. High only while
// the element is true, every arming input reads armed now (`armed`: the
// pins, read by the caller this run), the channel's machine is in one of
// its fire states (`fire`), and for at most `pulse` runs counted from the
// element's rise. Once low with the element still true (the pulse spent,
// a key dropped, the machine out of its fire states) it stays low until the
// element has been false and rises again: one pulse per rise. `sense` is
// kPyroContinuity, 0 (an open igniter) or kPyroNoSense, for the status.
FSW_NOINLINE bool pyro_gate(PyroGate& g, bool element, bool armed, bool fire, uint16_t pulse, uint8_t sense);

// After a resume: a pulse a reset cut short is not started again (the
// charge counts as fired the moment its pin went high; a brown-out caused
// by the firing current itself would otherwise fire it at every restart).
FSW_NOINLINE void pyro_resumed(PyroGate* g, uint8_t n);

// ---- analog inputs, one call each (generated I/O tasks) -----------------------
// Generated inputs tasks convert each analog input with one inline call on
// constants the generator computed (no table read at run time), from the
// counts of a background scan of a flash list of pins:
//     fsw::write_F32(sv + E_p, fsw::analog_value(fsw::io_analog_count(kAnalogInRaw, 0), 30.54741f, 76875.0f));
//     fsw::io_analog_scan(kAnalogInPins, 2, kAnalogInRaw);  // the next run's counts
// so an element holds the pins as they were one run earlier (the scan of
// the previous run), as with a table sampled in the background.

// Entry i of the scan's counts, read whole (interrupts off: the ADC's
// interrupt writes them; the scan has ended long before, all the same).
inline uint16_t io_analog_count(const volatile uint16_t* raw, uint8_t i) {
    const pal::IrqState saved = pal::critical_enter();
    const uint16_t v = raw[i];
    pal::critical_exit(saved);
    return v;
}
// Starts converting the n pins at `pins` (FSW_FLASH bytes) into raw, in the
// background (a scan still running is left to finish).
inline void io_analog_scan(const uint8_t* pins, uint8_t n, volatile uint16_t* raw) {
    (void)pal::adc_scan_start(pins, 1, n, raw);
}
// At boot: the first scan, waited for, so the task's first run reads the
// pins as they were then.
void io_analog_scan_begin(const uint8_t* pins, uint8_t n, volatile uint16_t* raw);

// The conversions the analog task applies (exposed for tests and docs).
// value = count * gain + offset, in R (two roundings: the host mirrors it
// exactly, fswkit.autocode.iotables.analog_value).
// An offset of +0 known when compiling (a generated call's literal) costs
// no float addition: adding +0 only turns -0 into +0, done here on the bits.
// A count as R: exact (every count has at most 16 bits). On AVR the 16-bit
// conversion of fsw_convert.h, which puts the float's bits together from the
// count's leading bit where the float library's routine works through 32
// bits: tested against the cast for every count (tests/firmware/test_io.cpp).
inline Real real_from_count(uint16_t count) { return real_from_U16(count); }
inline Real analog_value(uint16_t count, Real gain, Real offset) {
    const Real scaled = real_from_count(count) * gain;  // one rounding, never fused with the add
#if FSW_REAL_IS_FLOAT && defined(__GNUC__)
    if (__builtin_constant_p(offset) && offset == 0 && !__builtin_signbit(offset)) {
        uint32_t b;
        memcpy(&b, &scaled, sizeof b);
        return b == 0x80000000UL ? Real(0) : scaled;
    }
#endif
    return scaled + offset;
}
// The last count an input converted, and its value: analog_value_memo
// converts a count only when it changed since the input's last run. The
// same value bit for bit (analog_value is a function of the count alone:
// the gain and the offset are the call's constants), for a fraction of the
// runs: a reading at rest moves less than a count (the rocket's igniters'
// continuity, its barometer on the pad and under a parachute), where a
// conversion takes about 260 AVR cycles (a multiplication and an addition
// of floats). Zero before the first run: `key` is the count's complement,
// and the count 0xFFFF (key 0) is converted at every run.
struct AnalogMemo {
    uint16_t key;
    Real value;
};
// Inline, as analog_value: a literal +0 offset still costs no addition.
inline __attribute__((always_inline)) Real analog_value_memo(AnalogMemo& m, uint16_t count, Real gain, Real offset) {
    const uint16_t key = static_cast<uint16_t>(~count);
    if (key == 0 || key != m.key) {
        m.key = key;
        m.value = analog_value(count, gain, offset);
    }
    return m.value;
}
// The last count an input converted, where the input's element keeps its
// value: in an application whose machines are all generated (none replaced
// at run time), an element an input writes has no other writer (fsw check:
// no machine and no uplink SET writes it), so a count that did not change is
// neither converted nor written again, and the element still holds what its
// conversion gave, bit for bit. 2 bytes of RAM an input, where an
// AnalogMemo, which keeps the value too, takes 6. `key` is the count's
// complement, zero before the first run; the count 0xFFFF (key 0) is new at
// every run. True when the count is new (the key then set to it).
inline bool analog_count_new(uint16_t& key, uint16_t count) {
    const uint16_t k = static_cast<uint16_t>(~count);
    if (k != 0 && k == key) return false;
    key = k;
    return true;
}
// An analog input of a generated inputs task, FSW_FLASH: the F32 element
// at `off` takes count * gain + offset (the generator's constants).
struct AnalogInput {
    Real gain;
    Real offset;
    ElemOff off;
};
// The inputs task's analog inputs, one loop over their rows: input i's F32
// element takes analog_value_memo(memo[i], io_analog_count(raw, i), gain,
// offset), the same value bit for bit as a call of its own with the
// constants inline (an offset of +0 is not added on binary32 R: -0 turns
// +0 on the bits, as analog_value's shortcut does). A row's gain and offset are read out of
// flash only when its count changed; one copy of the conversion in flash
// for every input (about 110 B an input inline on AVR). Not for a state
// vector with `lock` (each write is then guarded: the generator calls one
// input at a time).
void io_analog_inputs(const AnalogInput* rows, uint8_t n, AnalogMemo* memo, const volatile uint16_t* raw,
                      uint8_t* sv);
// The same, each input through its key (analog_count_new): an element is
// converted and written only when its count is new (an application whose
// input elements have no other writer).
void io_analog_inputs_kept(const AnalogInput* rows, uint8_t n, uint16_t* keys, const volatile uint16_t* raw,
                           uint8_t* sv);
// duty = trunc(clamp(volts / vref * 255 + 0.5, 0, 255)); NaN -> 0.
uint8_t pwm_duty_from_volts(Real volts, Real vref);

}  // namespace fsw

#endif  // FSW_IO_H
