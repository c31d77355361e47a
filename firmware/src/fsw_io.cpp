// Analog and digital I/O task bodies: one pass over a constant channel table.
#include "fsw_io.h"

#include "fsw_element.h"
#include "fsw_pal.h"

namespace fsw {

Real analog_value_from_raw(uint16_t raw, Real vref, uint8_t adc_bits, Real scale, Real offset) {
    const Real full = static_cast<Real>((1UL << adc_bits) - 1UL);
    const Real volts = static_cast<Real>(raw) * vref / full;
    return volts * scale + offset;
}

uint8_t pwm_duty_from_volts(Real volts, Real vref) {
    return U8_from_real(volts / vref * Real(255) + Real(0.5));
}

static bool analog_type_ok(uint8_t t) { return t == kF32 || t == kF64; }

Result io_analog_begin(const AnalogTable* table) {
    AnalogTable tab;
    flash_read(&tab, table, sizeof tab);
    if (tab.adc_bits == 0 || tab.adc_bits > 16 || !(tab.vref > 0)) return kErrConfig;
    for (uint8_t i = 0; i < tab.n; ++i) {
        AnalogChannel c;
        flash_read(&c, &tab.ch[i], sizeof c);
        if (!analog_type_ok(c.type) || (c.dir != kIoIn && c.dir != kIoOut)) return kErrConfig;
        if (c.dir == kIoOut) pal::pin_mode(c.pin, pal::kOutput);
    }
    return kOk;
}

namespace {

// kAnyF64: rows may be F64 (else F32 only); kOutputs: rows may be outputs
// (else inputs only). A row outside what the instance serves is refused.
template <bool kAnyF64, bool kOutputs>
Result analog_task(void* ctx) {
    AnalogTable tab;
    flash_read(&tab, ctx, sizeof tab);
    for (uint8_t i = 0; i < tab.n; ++i) {
        AnalogChannel c;
        flash_read(&c, &tab.ch[i], sizeof c);
        if (!kAnyF64 && c.type != kF32) return kErrConfig;
        if (!kOutputs && c.dir != kIoIn) return kErrConfig;
        uint8_t* p = tab.sv + c.off;
        if (!kOutputs || c.dir == kIoIn) {
            // Read (slow: ~100 us on AVR) before taking the lock.
            const Real v = analog_value_from_raw(pal::analog_read(c.pin), tab.vref, tab.adc_bits,
                                                 c.scale, c.offset);
            const pal::IrqState saved = tab.lock ? pal::critical_enter() : 0;
            // Analog elements are F32 or F64 (checked at begin): no general
            // dispatch, which would link every type's conversions.
            if (kAnyF64 && c.type == kF64) write_F64(p, v); else write_F32(p, v);
            if (tab.lock) pal::critical_exit(saved);
        } else {
            const pal::IrqState saved = tab.lock ? pal::critical_enter() : 0;
            const Real volts = (kAnyF64 && c.type == kF64) ? read_F64(p) : read_F32(p);
            if (tab.lock) pal::critical_exit(saved);
            pal::analog_write(c.pin, pwm_duty_from_volts(volts, tab.vref));
        }
    }
    return kOk;
}

}  // namespace

Result io_analog_task(void* ctx) { return analog_task<true, true>(ctx); }
Result io_analog_task_f32(void* ctx) { return analog_task<false, true>(ctx); }
Result io_analog_in_task_f32(void* ctx) { return analog_task<false, false>(ctx); }

Result io_digital_begin(const DigitalTable* table) {
    DigitalTable tab;
    flash_read(&tab, table, sizeof tab);
    for (uint8_t i = 0; i < tab.n; ++i) {
        DigitalChannel c;
        flash_read(&c, &tab.ch[i], sizeof c);
        switch (c.dir) {
            case kIoIn: pal::pin_mode(c.pin, pal::kInput); break;
            case kIoInPullup: pal::pin_mode(c.pin, pal::kInputPullup); break;
            case kIoOut: pal::pin_mode(c.pin, pal::kOutput); break;
            default: return kErrConfig;
        }
    }
    return kOk;
}

Result io_digital_task(void* ctx) {
    DigitalTable tab;
    flash_read(&tab, ctx, sizeof tab);
    for (uint8_t i = 0; i < tab.n; ++i) {
        DigitalChannel c;
        flash_read(&c, &tab.ch[i], sizeof c);
        uint8_t* p = tab.sv + c.off;
        if (c.dir == kIoOut) {
            pal::digital_write(c.pin, *p != 0);  // one byte: no lock needed
        } else {
            *p = pal::digital_read(c.pin) ? 1 : 0;
        }
    }
    return kOk;
}

}  // namespace fsw
