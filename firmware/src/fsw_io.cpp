// Analog and digital I/O task bodies: one pass over a constant channel table.
#include "fsw_io.h"

#include "fsw_app.h"
#include "fsw_element.h"
#include "fsw_pal.h"

namespace fsw {

uint8_t pwm_duty_from_volts(Real volts, Real vref) {
    return U8_from_real(volts / vref * Real(255) + Real(0.5));
}

bool pyro_gate(PyroGate& g, bool element, bool armed, bool fire, uint16_t pulse, uint8_t sense) {
    uint8_t status = static_cast<uint8_t>((g.status & kPyroFired) | sense | (armed ? kPyroArmed : 0));
    if (element && g.last == 0) g.left = pulse;  // a rise: a new pulse
    g.last = element ? 1 : 0;
    bool high = false;
    if (!element || !armed || !fire || g.left == 0) {
        g.left = 0;  // ended: low until the element falls and rises again
    } else {
        if (g.left == pulse) status |= kPyroRose | kPyroFired;
        --g.left;
        high = true;
        status |= kPyroFiring;
    }
    g.status = status;
    return high;
}

void pyro_resumed(PyroGate* g, uint8_t n) {
    for (uint8_t i = 0; i < n; ++i) {
        g[i].left = 0;
        g[i].status = static_cast<uint8_t>(g[i].status & ~(kPyroFiring | kPyroRose));
    }
}

static bool analog_type_ok(uint8_t t) { return t == kF32 || t == kF64; }

// The scan of a table sampled in the background, once, waited for: the
// task's first run reads these counts.
static Result first_scan(const AnalogTable& tab) {
    while (pal::adc_scan_busy()) {}
    if (!pal::adc_scan_start(&tab.ch->pin, sizeof(AnalogChannel), tab.n, tab.raw)) return kErrConfig;
    while (pal::adc_scan_busy()) {}
    return kOk;
}

Result io_analog_begin(const AnalogTable* table) {
    AnalogTable tab;
    flash_read(&tab, table, sizeof tab);
    if (tab.adc_bits == 0 || tab.adc_bits > 16 || !(tab.vref > 0)) return kErrConfig;
    for (uint8_t i = 0; i < tab.n; ++i) {
        AnalogChannel c;
        flash_read(&c, &tab.ch[i], sizeof c);
        if (!analog_type_ok(c.type) || (c.dir != kIoIn && c.dir != kIoOut)) return kErrConfig;
        if (tab.raw != 0 && c.dir != kIoIn) return kErrConfig;  // a scan converts every row
        if (c.dir == kIoOut) pal::pin_mode(c.pin, pal::kOutput);
    }
    return tab.raw != 0 ? first_scan(tab) : kOk;
}

void io_analog_scan_begin(const uint8_t* pins, uint8_t n, volatile uint16_t* raw) {
    while (pal::adc_scan_busy()) {}
    (void)pal::adc_scan_start(pins, 1, n, raw);  // nothing runs: it starts
    while (pal::adc_scan_busy()) {}
}

namespace {

// kAnyF64: rows may be F64 (else F32 only); kOutputs: rows may be outputs
// (else inputs only). A row outside what the instance serves is refused.
template <bool kAnyF64, bool kOutputs>
Result analog_task(void* ctx) {
    AnalogTable tab;
    flash_read(&tab, ctx, sizeof tab);
    const bool lock = app_has(kAppSvLock) && tab.lock;  // (fsw_app.h)
    for (uint8_t i = 0; i < tab.n; ++i) {
        AnalogChannel c;
        flash_read(&c, &tab.ch[i], sizeof c);
        if (!kAnyF64 && c.type != kF32) return kErrConfig;
        if (!kOutputs && c.dir != kIoIn) return kErrConfig;
        uint8_t* p = tab.sv + c.off;
        if (!kOutputs || c.dir == kIoIn) {
            uint16_t count;
            if (tab.raw != 0) {
                // the previous scan's count (it has ended: a scan takes well
                // under a period; read with interrupts off all the same)
                const pal::IrqState saved = pal::critical_enter();
                count = tab.raw[i];
                pal::critical_exit(saved);
            } else {
                count = pal::analog_read(c.pin);  // slow: ~100 us on AVR; before taking the lock
            }
            const Real v = analog_value(count, c.gain, c.offset);
            const pal::IrqState saved = lock ? pal::critical_enter() : 0;
            // Analog elements are F32 or F64 (checked at begin): no general
            // dispatch, which would link every type's conversions.
            if (kAnyF64 && c.type == kF64) write_F64(p, v); else write_F32(p, v);
            if (lock) pal::critical_exit(saved);
        } else {
            const pal::IrqState saved = lock ? pal::critical_enter() : 0;
            const Real volts = (kAnyF64 && c.type == kF64) ? read_F64(p) : read_F32(p);
            if (lock) pal::critical_exit(saved);
            pal::analog_write(c.pin, pwm_duty_from_volts(volts, tab.vref));
        }
    }
    // the next run's counts, converted in the background meanwhile (a scan
    // still running, which a period far shorter than it would cause, is
    // left to finish: the next run reads what it stored)
    if (tab.raw != 0) (void)pal::adc_scan_start(&tab.ch->pin, sizeof(AnalogChannel), tab.n, tab.raw);
    return kOk;
}

}  // namespace

namespace {

// A row's count * gain + offset, as analog_value gives it with the row's
// constants inline, bit for bit (its order; a +0 offset not added).
Real row_value(const AnalogInput* row, uint16_t count) {
    const Real scaled = real_from_count(count) * flash_get(row->gain);  // analog_value's, in its order
    const Real offset = flash_get(row->offset);
#if FSW_REAL_IS_FLOAT
    // an offset of +0 (its bits all 0) is not added: adding it only turns -0 into +0,
    // done on the bits as analog_value does for a literal +0 (no float addition)
    uint32_t ob, sb;
    memcpy(&ob, &offset, sizeof ob);
    memcpy(&sb, &scaled, sizeof sb);
    return ob != 0 ? scaled + offset : sb == 0x80000000UL ? Real(0) : scaled;
#else
    return scaled + offset;
#endif
}

}  // namespace

void io_analog_inputs(const AnalogInput* rows, uint8_t n, AnalogMemo* memo, const volatile uint16_t* raw,
                      uint8_t* sv) {
    for (uint8_t i = 0; i < n; ++i, ++rows, ++memo) {
        const uint16_t count = io_analog_count(raw, i);
        const uint16_t key = static_cast<uint16_t>(~count);
        if (key == 0 || key != memo->key) {  // (analog_value_memo: the row's constants read only then)
            memo->key = key;
            memo->value = row_value(rows, count);
        }
        write_F32(sv + flash_get(rows->off), memo->value);
    }
}

void io_analog_inputs_kept(const AnalogInput* rows, uint8_t n, uint16_t* keys, const volatile uint16_t* raw,
                           uint8_t* sv) {
    for (uint8_t i = 0; i < n; ++i, ++rows, ++keys) {
        const uint16_t count = io_analog_count(raw, i);
        if (analog_count_new(*keys, count)) write_F32(sv + flash_get(rows->off), row_value(rows, count));
    }
}

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
