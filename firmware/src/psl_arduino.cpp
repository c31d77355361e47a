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
