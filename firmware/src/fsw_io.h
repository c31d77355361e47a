// Analog and digital I/O tasks (spec 6): constant channel tables moving
// values between pins and state vector elements, run as executor tasks.
#ifndef FSW_IO_H
#define FSW_IO_H

#include "fsw_types.h"

namespace fsw {

enum IoDir : uint8_t { kIoIn = 0, kIoInPullup = 1, kIoOut = 2 };

// Analog channel: inputs write `volts * scale + offset` into an F32/F64
// element; outputs drive PWM from an F32/F64 element in volts (0..vref).
struct AnalogChannel {
    Real scale;       // K (inputs; 1 for none)
    Real offset;      // B (inputs; 0 for none)
    ElemOff off;      // element offset in the state vector
    uint8_t pin;      // board pin number (A0 = 14 on an Uno)
    uint8_t dir;      // kIoIn or kIoOut
    uint8_t type;     // kF32 or kF64
};

struct AnalogTable {
    const AnalogChannel* ch;  // FSW_FLASH rows
    uint8_t* sv;
    Real vref;        // ADC reference and PWM full scale, volts
    uint8_t n;
    uint8_t adc_bits; // ADC resolution: full scale is 2^bits - 1
    bool lock;        // state vector `lock` option
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

// Checks the table and sets pin modes. `table` points at an FSW_FLASH object.
FSW_MUST_CHECK Result io_analog_begin(const AnalogTable* table);
FSW_MUST_CHECK Result io_digital_begin(const DigitalTable* table);

// Executor task steps; ctx is the FSW_FLASH table. One pass over the table.
Result io_analog_task(void* ctx);
// The same for a table whose elements are all F32 (the generator picks it):
// it links no binary64 conversion, which AVR does in software.
Result io_analog_task_f32(void* ctx);
Result io_digital_task(void* ctx);

// The conversions the analog task applies (exposed for tests and docs).
// volts = raw * vref / (2^bits - 1); value = volts * scale + offset.
Real analog_value_from_raw(uint16_t raw, Real vref, uint8_t adc_bits, Real scale, Real offset);
// duty = trunc(clamp(volts / vref * 255 + 0.5, 0, 255)); NaN -> 0.
uint8_t pwm_duty_from_volts(Real volts, Real vref);

}  // namespace fsw

#endif  // FSW_IO_H
