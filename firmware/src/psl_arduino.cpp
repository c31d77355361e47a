// Arduino PSL: the PAL on top of the Arduino API (any board it covers), plus
// on AVR the watchdog and the reset cause read from MCUSR at boot.
#include "fsw_config.h"

#if FSW_PLATFORM_ARDUINO

#include <Arduino.h>

#include "fsw_clock.h"
#include "fsw_pal.h"

#if defined(__AVR__)
#include <avr/wdt.h>

// MCUSR must be read and cleared before anything else runs, or a watchdog
// reset would loop; .init3 runs before constructors and main(). A bootloader
// that clears MCUSR itself (some Optiboot versions) hides the cause.
static uint8_t fsw_mcusr_at_boot __attribute__((section(".noinit")));
extern "C" void fsw_capture_mcusr(void) __attribute__((naked, used, section(".init3")));
extern "C" void fsw_capture_mcusr(void) {
    fsw_mcusr_at_boot = MCUSR;
    MCUSR = 0;
    wdt_disable();
}

#if FSW_STACK_PAINT
// Paints the free RAM, from the end of the static data (`_end`, after .data,
// .bss and .noinit) to RAMEND, with FSW_STACK_PAINT_BYTE. .init3 runs after
// avr-libc has set the stack pointer to RAMEND (.init2) and before anything
// is pushed: naked, no call, only r24, r25 and Z, which nothing before
// .init4 (data copy, bss clear) expects to keep. .noinit is left alone.
extern "C" void fsw_paint_stack(void) __attribute__((naked, used, section(".init3")));
extern "C" void fsw_paint_stack(void) {
    __asm__ __volatile__(
        "ldi r30, lo8(_end)\n\t"
        "ldi r31, hi8(_end)\n\t"
        "ldi r24, %[paint]\n\t"
        "ldi r25, hi8(%[top])\n\t"
        "1: cpi r30, lo8(%[top])\n\t"
        "cpc r31, r25\n\t"
        "brsh 2f\n\t"
        "st Z+, r24\n\t"
        "rjmp 1b\n\t"
        "2:\n\t" ::[paint] "M"(FSW_STACK_PAINT_BYTE),
        [top] "i"(RAMEND + 1)
        : "r24", "r25", "r30", "r31", "memory");
}
#endif  // FSW_STACK_PAINT
#endif

namespace fsw {
namespace pal {

namespace {
Clock64 g_micros_ext;
Clock64 g_millis_ext;
}  // namespace

void begin() {}

uint32_t micros32() { return micros(); }
uint32_t millis32() { return millis(); }
uint64_t micros64() { return clock64_extend(g_micros_ext, micros()); }
uint64_t millis64() { return clock64_extend(g_millis_ext, millis()); }

uint16_t analog_read(uint8_t pin) { return static_cast<uint16_t>(analogRead(pin)); }
void analog_write(uint8_t pin, uint8_t duty) { analogWrite(pin, duty); }

#if defined(__AVR__)
// The background scan (adc_scan_start): what the ADC interrupt walks.
namespace {
struct AdcScan {
    const uint8_t* pin;      // FSW_FLASH: the pin being converted
    volatile uint16_t* raw;  // where its count goes
    uint8_t stride;
    volatile uint8_t left;   // conversions not yet stored; 0 when done
};
AdcScan g_scan = {0, 0, 0, 0};

// Starts converting a pin as analogRead does (AVcc reference, the pin's
// channel), with the conversion-complete interrupt on.
inline __attribute__((always_inline)) void adc_convert(uint8_t pin) {
    const uint8_t ch = static_cast<uint8_t>(pin >= A0 ? pin - A0 : pin);
#if defined(MUX5)
    ADCSRB = static_cast<uint8_t>((ADCSRB & ~_BV(MUX5)) | (((ch >> 3) & 1u) << MUX5));
#endif
    ADMUX = static_cast<uint8_t>(_BV(REFS0) | (ch & 7u));
    ADCSRA = static_cast<uint8_t>(ADCSRA | _BV(ADIF) | _BV(ADIE) | _BV(ADSC));  // ADIF: writing 1 clears it
}
}  // namespace

bool adc_scan_busy() { return g_scan.left != 0; }

bool adc_scan_start(const uint8_t* pins, uint8_t stride, uint8_t n, volatile uint16_t* raw) {
    if (adc_scan_busy()) return false;
    if (n == 0) return true;
    const IrqState saved = critical_enter();
    g_scan.pin = pins;
    g_scan.raw = raw;
    g_scan.stride = stride;
    g_scan.left = n;
    adc_convert(pgm_read_byte(pins));
    critical_exit(saved);
    return true;
}

}  // namespace pal
}  // namespace fsw

// A conversion ended: store its count, start the next or stop.
ISR(ADC_vect) {
    using fsw::pal::g_scan;
    const uint8_t lo = ADCL;  // ADCL first: it latches ADCH
    const uint8_t hi = ADCH;
    volatile uint16_t* raw = g_scan.raw;
    *raw = static_cast<uint16_t>(lo | (hi << 8));
    const uint8_t left = static_cast<uint8_t>(g_scan.left - 1);
    g_scan.left = left;
    if (left != 0) {
        g_scan.raw = raw + 1;
        g_scan.pin += g_scan.stride;
        fsw::pal::adc_convert(pgm_read_byte(g_scan.pin));
    } else {
        ADCSRA = static_cast<uint8_t>(ADCSRA & ~_BV(ADIE));
    }
}

namespace fsw {
namespace pal {
#else
// Another MCU: the counts are converted at once, analogRead by analogRead.
bool adc_scan_busy() { return false; }
bool adc_scan_start(const uint8_t* pins, uint8_t stride, uint8_t n, volatile uint16_t* raw) {
    for (uint8_t i = 0; i < n; ++i) raw[i] = static_cast<uint16_t>(analogRead(pins[i * stride]));
    return true;
}
#endif

void pin_mode(uint8_t pin, uint8_t mode) {
    pinMode(pin, mode == kOutput ? OUTPUT : mode == kInputPullup ? INPUT_PULLUP : INPUT);
}
bool digital_read(uint8_t pin) { return digitalRead(pin) == HIGH; }
void digital_write(uint8_t pin, bool high) { digitalWrite(pin, high ? HIGH : LOW); }

#if !defined(__AVR__)
// Outside AVR the Arduino API cannot save the interrupt state: sections
// do not nest there.
IrqState critical_enter() {
    noInterrupts();
    return 0;
}
void critical_exit(IrqState saved) {
    (void)saved;
    interrupts();
}
#endif

#if defined(__AVR__) && FSW_WATCHDOG
static uint8_t wdto_from_ms() {
    return FSW_WATCHDOG_MS == 15 ? WDTO_15MS : FSW_WATCHDOG_MS == 30 ? WDTO_30MS
         : FSW_WATCHDOG_MS == 60 ? WDTO_60MS : FSW_WATCHDOG_MS == 120 ? WDTO_120MS
         : FSW_WATCHDOG_MS == 250 ? WDTO_250MS : FSW_WATCHDOG_MS == 500 ? WDTO_500MS
         : FSW_WATCHDOG_MS == 1000 ? WDTO_1S : WDTO_2S;
}
void watchdog_begin() { wdt_enable(wdto_from_ms()); }
void watchdog_kick() { wdt_reset(); }
#else
void watchdog_begin() {}
void watchdog_kick() {}
#endif

#if defined(__AVR__)
uint8_t reset_cause() { return fsw_mcusr_at_boot; }
#else
uint8_t reset_cause() { return 0; }
#endif

}  // namespace pal
}  // namespace fsw

#endif  // FSW_PLATFORM_ARDUINO
