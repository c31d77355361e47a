// Arduino PSL: the PAL on top of the Arduino API (any board it covers), plus
// on AVR the watchdog and the reset cause read from MCUSR at boot.
#include "fsw_config.h"

#if FSW_PLATFORM_ARDUINO

#include <Arduino.h>

#include "fsw_clock.h"
#include "fsw_pal.h"

#if defined(__AVR__)
#include <avr/sleep.h>
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

#if defined(__AVR__) && FSW_SLEEP
void boot() {
#if defined(ADCSRA)
    // ADEN and the prescaler to 125 kHz or the nearest below (init()'s values)
    ADCSRA = static_cast<uint8_t>(_BV(ADEN) | (F_CPU >= 16000000L  ? 7u
                                               : F_CPU >= 8000000L ? 6u
                                               : F_CPU >= 4000000L ? 5u
                                               : F_CPU >= 2000000L ? 4u
                                               : F_CPU >= 1000000L ? 3u
                                                                   : 1u));
#endif
#if defined(UCSR0B)
    UCSR0B = 0;  // a bootloader may leave the UART on: pins 0 and 1 are free until the console takes them
#endif
    sei();
}
#endif

#if FSW_SLEEP
// ---- The cycle timer: Timer1 (16-bit) in CTC mode, clk/8 ---------------------
// A cycle of P us is n equal sub-periods of S = P / n us (n the smallest
// power of two with S <= 32000: cycle_settings, fsw_pal.h); OCR1A = S x ticks/us - 1 ends each, its
// compare interrupt (or cycle_wait(), when it waits for it) counts them and
// keeps the clock. OCR1B wakes the CPU FSW_WAKE_EARLY_US before a sub-period
// ends; in the last one cycle_wait() then spins, interrupts off, until the
// count wraps, so a cycle starts within one spin (8 CPU cycles) of its time,
// whatever handler ran when the CPU woke.
CycleTimer g_ct;  // (fsw_pal.h)
CycleSettings g_cs;

namespace {

// The microseconds past g_ct.ms at the running sub-period's start (< 1000),
// where a sub-period is no whole number of milliseconds: apart from g_ct, so
// that LTO drops it where the application's constant period never reads it
// (2 bytes of the rocket's RAM at 100 Hz). (The cycle's sub-period count
// stays in g_ct: the handler clears it every cycle, and without that store
// the handler's 2 cycles fewer moved the demo flight's ADC readings against
// the plant's steps, and its apogee by 20 ms.)
uint16_t g_ct_ms_frac;

// A sub-period ended (compare interrupt, or cycle_wait() that waited for it,
// interrupts off): the clock moves on; true when a cycle is due.
__attribute__((noinline)) bool sub_period_ended() {
    g_ct.base_us += ct_sub_us();
    g_ct.ms += ct_sub_ms();
    if (ct_sub_frac() != 0) {  // (else ms_frac stays 0: a sub-period of whole milliseconds)
        uint16_t f = static_cast<uint16_t>(g_ct_ms_frac + ct_sub_frac());
        if (f >= 1000u) {
            f = static_cast<uint16_t>(f - 1000u);
            ++g_ct.ms;
        }
        g_ct_ms_frac = f;
    }
    if (ct_last() != 0 && g_ct.sub != ct_last()) {  // (one sub-period a cycle: `sub` stays 0)
        ++g_ct.sub;
        return false;
    }
    g_ct.sub = 0;
    return true;
}

// The last stretch's sleep (cycle_wait): where the application has no
// sensor parts, and its period is a constant (fsw_app.h app_period_us: the
// clock's count of a sub-period is then the short code the lead below was
// measured on) long enough to sleep in. (The TWI's handler is left on: its
// control register starts the bus's next step when written, and a sensor
// application keeps the spin from the early wake-up, FSW_WAKE_EARLY_US.)
inline __attribute__((always_inline)) bool stretch_sleeps() {
    return !app_has(kAppSensors) && app_period_us != 0 && !ct_spin();
}
// Where compare B wakes the CPU the second time: before the count wraps by
// the wake-up (about 25 CPU cycles: the interrupt, compare B's handler),
// the clock's count of the ending sub-period and the test of the wrap
// (about 50 more for a sub-period of whole milliseconds that ends a cycle:
// 77 in all on the rocket, avr-g++ 7.3), in timer ticks of 8 CPU cycles
// (clk/8): 12 (96 cycles), 8 more for a sub-period with a fraction of a
// millisecond to count (the millisecond it completes every few cycles is
// about 40 cycles more: 400 Hz), 2 more where a cycle has several: the
// spin after it waits out the rest, two or three ticks. (A wake-up that
// reaches the count's flag after the wrap would count the cycle late, and
// one that ends its count after the wrap starts the cycle that much late:
// the margin is about 20 CPU cycles on the rocket; tests/regression/
// test_the_last_microseconds_before_a_cycle_are_slept_not_spun.py flies
// the three cases. An early wake-up shorter than this lead,
// FSW_WAKE_EARLY_US, finds the count past it: it spins, as before.)
inline __attribute__((always_inline)) uint16_t stretch_wake() {
    const uint16_t lead = static_cast<uint16_t>(12u + (ct_sub_frac() != 0 ? 8u : 0u) + (ct_last() != 0 ? 2u : 0u));
    return static_cast<uint16_t>(ct_top() - lead);
}

// The kit's interrupt sources but the timer's, held off through the last
// stretch (stretch_sleeps), so that none delays the cycle's start: the
// UART's (receive, transmit: a byte takes 85 us at 115,200 baud, and the
// UART's buffers hold the next), the ADC's, each 2.5 to 5.5 us, and the
// EEPROM's ready (about 2 us, once a byte written by the background
// writers: the parameter store's, the recorder's, the reload's, the
// features that have one, kAppEepromWriters). Each interrupt's flag stays as it is (the ADC's written 0,
// which leaves it alone; the EEPROM's has none to clear), so each runs
// once released.
const uint16_t kAppEepromWriters = kAppParams | kAppLog | kAppReload;
struct HeldIrqs {
    uint8_t ucsrb;  // the UART's control bits
    uint8_t adie;   // the ADC's interrupt enable, as it was
    uint8_t eerie;  // the EEPROM-ready interrupt enable, as it was
};
#if !defined(UCSR0B)
#define FSW_HELD_UCSRB 0
#else
#define FSW_HELD_UCSRB (_BV(RXCIE0) | _BV(TXCIE0) | _BV(UDRIE0))
#endif
inline __attribute__((always_inline)) HeldIrqs hold_irqs() {
    HeldIrqs h = {0, 0, 0};
    if (!stretch_sleeps()) return h;
#if defined(UCSR0B)
    h.ucsrb = UCSR0B;
    UCSR0B = static_cast<uint8_t>(h.ucsrb & ~FSW_HELD_UCSRB);
#endif
#if defined(ADCSRA)
    const uint8_t a = ADCSRA;
    h.adie = static_cast<uint8_t>(a & _BV(ADIE));
    ADCSRA = static_cast<uint8_t>(a & ~(_BV(ADIE) | _BV(ADIF)));
#endif
#if defined(EECR) && defined(EERIE)
    if (app_has(kAppEepromWriters)) {
        h.eerie = static_cast<uint8_t>(EECR & _BV(EERIE));
        EECR = static_cast<uint8_t>(EECR & ~_BV(EERIE));  // (as its handler does: EEPE written 1 without EEMPE starts nothing)
    }
#endif
    return h;
}
inline __attribute__((always_inline)) void release_irqs(const HeldIrqs& h) {
    if (!stretch_sleeps()) return;
#if defined(UCSR0B)
    UCSR0B = h.ucsrb;
#endif
#if defined(ADCSRA)
    ADCSRA = static_cast<uint8_t>((ADCSRA & ~_BV(ADIF)) | h.adie);
#endif
#if defined(EECR) && defined(EERIE)
    if (app_has(kAppEepromWriters)) EECR = static_cast<uint8_t>(EECR | h.eerie);
#endif
}

}  // namespace

void cycle_timer_begin(uint32_t period_us) {
    // (for the application's constant period, worked out when compiling)
    const CycleSettings s = cycle_settings(period_us);
    const IrqState saved = critical_enter();
    // The clock counts from here; the cycle's sub-period count, the reasons
    // and `running` start at 0 (one clear: a store a field was 4 bytes of
    // flash a byte).
    memset(&g_ct, 0, sizeof g_ct);
    if (ct_sub_frac() != 0) g_ct_ms_frac = 0;  // (where it is: it is read)
    if (app_period_us == 0) g_cs = s;  // else each is a constant where it is read (ct_*)
    g_ct.due = 1;  // the first cycle: at once, on time (why: kCycleOnTime, 0)
    TIMSK0 = static_cast<uint8_t>(TIMSK0 & ~_BV(TOIE0));  // the core's millis() stops here
    TCCR1A = 0;
    TCCR1B = 0;
    TCNT1 = 0;
    OCR1A = s.top;
    OCR1B = s.early;
    TIFR1 = static_cast<uint8_t>(_BV(OCF1A) | _BV(OCF1B));  // writing 1 clears a flag
    TIMSK1 = static_cast<uint8_t>(_BV(OCIE1A) | (s.spin ? 0 : _BV(OCIE1B)));
    TCCR1B = static_cast<uint8_t>(_BV(WGM12) | _BV(CS11));  // CTC on OCR1A, clk/8: counting
    critical_exit(saved);
}

uint8_t cycle_wait(uint8_t& skipped, bool background) {
    for (uint8_t pass = 0;; ++pass) {
        cli();
        if (g_ct.due != 0) {  // a start passed (late), or the first cycle
            skipped = static_cast<uint8_t>(g_ct.due - 1u);
            const uint8_t why = g_ct.why;
            g_ct.due = 0;
            g_ct.why = kCycleOnTime;
            g_ct.running = 1;
            sei();
            return why;
        }
        if ((ct_last() == 0 || g_ct.sub == ct_last()) && TCNT1 >= ct_early()) {
            // The last stretch, interrupts off. Where the application has
            // no sensor parts (no TWI handler), the kit's other interrupt
            // sources are held off until the cycle starts, and the CPU
            // sleeps again until compare B, moved to a few ticks before
            // the count wraps (stretch_wake), wakes it, its only interrupt then
            // (compare A's off too): it wakes at the same instruction
            // every cycle and spins only the rest, a tick or two (a
            // sleeping CPU is no awake time; the spin from the early
            // wake-up was 11 us a cycle on the rocket). Anything else
            // that wakes it (an interrupt not the kit's) sleeps it again
            // (compare B's handler clears SE); should one hold the CPU
            // past the wrap, the count's flag below tells. A wake-up the
            // count is already at (a short FSW_WAKE_EARLY_US, handlers
            // that held the CPU since the early one) is the spin's.
            const HeldIrqs held = hold_irqs();
            if (stretch_sleeps() && static_cast<uint16_t>(TCNT1 + 1u) < stretch_wake() &&
                (TIFR1 & _BV(OCF1A)) == 0) {
                OCR1B = stretch_wake();  // (compare B's flag: its handler, which woke the CPU, cleared it)
                TIMSK1 = _BV(OCIE1B);
                SMCR = _BV(SE);
                __asm__ __volatile__(
                    "sei\n\t"
                    "1:  sleep\n\t"
                    "    in   __tmp_reg__, %[smcr]\n\t"
                    "    sbrc __tmp_reg__, %[se]\n\t"
                    "    rjmp 1b\n\t"
                    "    cli\n\t" ::[smcr] "I"(_SFR_IO_ADDR(SMCR)),
                    [se] "I"(SE)
                    : "memory");
                OCR1B = ct_early();
                TIMSK1 = static_cast<uint8_t>(_BV(OCIE1A) | _BV(OCIE1B));  // (cycle_timer_begin's: no spin)
            }
            // This sub-period's end is counted first (nothing reads the
            // clock before the count wraps: interrupts are off), in time
            // the spin would wait out anyway, then the spin until the
            // count wraps to 0. Should it have wrapped meanwhile (the
            // compare's flag is set: handlers held the CPU almost all the
            // way from the wake-up to the cycle's time), the cycle starts
            // up to the count's few microseconds late: counted late.
            (void)sub_period_ended();
            skipped = 0;
            g_ct.running = 1;
            const uint8_t why = (TIFR1 & _BV(OCF1A)) != 0 ? kCycleLateOther : kCycleOnTime;
            while (TCNT1 >= ct_early()) {
            }
            TIFR1 = _BV(OCF1A);  // (counted above)
            release_irqs(held);  // (what they held runs now, as after the spin)
            sei();
            return why;
        }
        // Background work (the link's service, the EEPROM writers) between
        // cycles, but none started in the last FSW_BACKGROUND_GUARD_US before
        // one: a pass that began there could hold the CPU past its start.
        if (ct_spin() || (pass != 0 && background && !((ct_last() == 0 || g_ct.sub == ct_last()) && TCNT1 >= ct_quiet()))) {
            sei();
            return kCycleNotDue;
        }
        // Sleep; sei's next instruction runs before any interrupt, so a
        // wake-up cannot be lost between the test above and the sleep. The
        // timer's compare handlers clear the sleep enable bit (SE): a sleep
        // after one of them ran is no sleep, so none is lost between the
        // loop's test of SE and its next sleep either.
        SMCR = _BV(SE);  // idle mode (SM2..0 = 0): timers, UART and ADC run on
        if (background) {
            __asm__ __volatile__("sei\n\tsleep" ::: "memory");
        } else {
            // Without background work only the timer's compare interrupts
            // bring the loop anything (a cycle due, the last stretch): after
            // another (the UART's transmit, about 18 a cycle on the demo
            // flight; the ADC's) the CPU sleeps again at once, as long as SE
            // is set: a handler returns to the next of 4 `sleep`
            // instructions in a row, which sleeps again in its one cycle,
            // and the loop tests SE once a run of them (a wake-up about 1.5
            // cycles on average; 5 when it tested SE after each
            // `sleep`, 8 when it tested a flag the compare handlers set,
            // with interrupts off around the test). Once a compare handler
            // has cleared SE, the run's sleeps left are a cycle each.
            __asm__ __volatile__(
                "sei\n\t"
                "1:\n\t"
                ".rept 4\n\t"
                "    sleep\n\t"
                ".endr\n\t"
                "    in   __tmp_reg__, %[smcr]\n\t"
                "    sbrc __tmp_reg__, %[se]\n\t"
                "    rjmp 1b\n\t" ::[smcr] "I"(_SFR_IO_ADDR(SMCR)),
                [se] "I"(SE)
                : "memory");
        }
        SMCR = 0;
    }
}

void cycle_end() { g_ct.running = 0; }

FSW_NOINLINE uint32_t micros32() { return micros32_inline(); }  // out of line as before: its callers elsewhere as they were

uint32_t millis32() {
    const IrqState saved = critical_enter();
    const uint16_t t = TCNT1;
    const uint16_t frac = ct_sub_frac() != 0 ? g_ct_ms_frac : 0u;  // (stays 0 for whole milliseconds)
    uint16_t f = static_cast<uint16_t>(frac + t / FSW_T1_TICKS_PER_US);  // < 1000 + 32000
    uint32_t ms = g_ct.ms;
    if ((TIFR1 & _BV(OCF1A)) != 0 && t < ct_early()) {  // a sub-period ended, not yet counted (micros32_inline)
        ms += ct_sub_ms();
        f = static_cast<uint16_t>(f + ct_sub_frac());
    }
    critical_exit(saved);
    while (f >= 1000u) {  // at most 33 times
        f = static_cast<uint16_t>(f - 1000u);
        ++ms;
    }
    return ms;
}
#else
uint32_t micros32() { return micros(); }
uint32_t millis32() { return millis(); }
#endif
uint64_t micros64() { return clock64_extend(g_micros_ext, micros32()); }
uint64_t millis64() { return clock64_extend(g_millis_ext, millis32()); }

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
#if !defined(MUX5) && FSW_USE_PROGMEM
// Naked (4 times a cycle on the rocket): it saves only the three registers
// and the status register it uses, where the compiler's handler also saved
// r0, r1, r18 and r25 and cleared r1; the C handler below, in assembly. The
// count's two bytes go through one register (r24), ADCL first: 4 cycles a
// conversion less than through two (the push and pop of r25).
ISR(ADC_vect, ISR_NAKED) {
    __asm__ __volatile__(
        "push r24\n\t"
        "in   r24, __SREG__\n\t"
        "push r24\n\t"
        "push r30\n\t"
        "push r31\n\t"
        "lds  r30, %[raw]\n\t"
        "lds  r31, %[raw]+1\n\t"
        "lds  r24, %[adcl]\n\t"  // ADCL first: it latches ADCH
        "st   Z+, r24\n\t"
        "lds  r24, %[adch]\n\t"
        "st   Z+, r24\n\t"
        "lds  r24, %[left]\n\t"
        "subi r24, 1\n\t"
        "sts  %[left], r24\n\t"
        "breq 1f\n\t"
        "sts  %[raw], r30\n\t"  // the next count's place
        "sts  %[raw]+1, r31\n\t"
        "lds  r30, %[pin]\n\t"  // the next pin (no r1 = 0 assumed: ldi leaves the carry)
        "lds  r31, %[pin]+1\n\t"
        "lds  r24, %[stride]\n\t"
        "add  r30, r24\n\t"
        "ldi  r24, 0\n\t"
        "adc  r31, r24\n\t"
        "sts  %[pin], r30\n\t"
        "sts  %[pin]+1, r31\n\t"
        "lpm  r30, Z\n\t"  // adc_convert: the pin's channel, the reference, the start
        "cpi  r30, %[a0]\n\t"
        "brlo 2f\n\t"
        "subi r30, %[a0]\n\t"
        "2:\n\t"
        "andi r30, 7\n\t"
        "ori  r30, %[refs]\n\t"
        "sts  %[admux], r30\n\t"
        "lds  r24, %[adcsra]\n\t"
        "ori  r24, %[start]\n\t"
        "rjmp 3f\n\t"
        "1:\n\t"
        "lds  r24, %[adcsra]\n\t"  // the last: the interrupt off
        "andi r24, %[stop]\n\t"
        "3:\n\t"
        "sts  %[adcsra], r24\n\t"
        "pop  r31\n\t"
        "pop  r30\n\t"
        "pop  r24\n\t"
        "out  __SREG__, r24\n\t"
        "pop  r24\n\t"
        "reti\n\t" ::[adcl] "n"(_SFR_MEM_ADDR(ADCL)),
        [adch] "n"(_SFR_MEM_ADDR(ADCH)), [raw] "i"(&fsw::pal::g_scan.raw), [left] "i"(&fsw::pal::g_scan.left),
        [pin] "i"(&fsw::pal::g_scan.pin), [stride] "i"(&fsw::pal::g_scan.stride), [a0] "M"(A0),
        [refs] "M"(_BV(REFS0)), [admux] "n"(_SFR_MEM_ADDR(ADMUX)), [adcsra] "n"(_SFR_MEM_ADDR(ADCSRA)),
        [start] "M"(_BV(ADIF) | _BV(ADIE) | _BV(ADSC)), [stop] "M"(0xFF & ~_BV(ADIE))
        : "memory");
}
#else
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
#endif

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

#if defined(__AVR__) && defined(SPDR)
// The SPI through its registers (datasheet 19): a device's chip select
// port and mask are looked up once, so a select is a few instructions.
namespace {
SpiDevice g_spi_default;
}  // namespace
void spi_bus_begin() {
    digitalWrite(SS, HIGH);
    pinMode(SS, OUTPUT);  // master mode holds only while SS is an output (or high)
    pinMode(MOSI, OUTPUT);
    pinMode(SCK, OUTPUT);
    if (!(SPCR & _BV(SPE))) SPCR = static_cast<uint8_t>(_BV(SPE) | _BV(MSTR));  // mode 0, F_CPU / 4 until a select
}
void spi_device(SpiDevice& d, uint8_t cs_pin, uint8_t mode, uint32_t max_hz) {
    d.cs_pin = cs_pin;
    d.cs_port = portOutputRegister(digitalPinToPort(cs_pin));
    d.cs_mask = digitalPinToBitMask(cs_pin);
    *d.cs_port |= d.cs_mask;  // high before it drives: the chip stays deselected
    pinMode(cs_pin, OUTPUT);
    // F_CPU / 2^k, k = 1..7: SPI2X for odd k, SPR1:0 = (k - 1) / 2 (k = 7: 11, /128).
    uint8_t k = 1;
    while (k < 7u && static_cast<uint32_t>(F_CPU) >> k > max_hz) ++k;
    const uint8_t spr = k == 7u ? 3u : static_cast<uint8_t>((k - 1u) / 2u);
    d.spcr = static_cast<uint8_t>(_BV(SPE) | _BV(MSTR) | (mode & 3u) << CPHA | spr);
    d.spsr = (k & 1u) != 0 && k != 7u ? static_cast<uint8_t>(_BV(SPI2X)) : static_cast<uint8_t>(0);
}
void spi_select(const SpiDevice& d, bool on) {
    if (on) {
        SPCR = d.spcr;  // the clock's idle level follows CPOL before the chip sees it
        SPSR = d.spsr;
        *d.cs_port &= static_cast<uint8_t>(~d.cs_mask);
    } else {
        *d.cs_port |= d.cs_mask;
    }
}
void spi_begin(uint8_t cs_pin) {
    spi_bus_begin();
    spi_device(g_spi_default, cs_pin, 0, static_cast<uint32_t>(F_CPU) / 2u);
    SPCR = g_spi_default.spcr;
    SPSR = g_spi_default.spsr;
}
void spi_select(bool on) { spi_select(g_spi_default, on); }
uint8_t spi_transfer(uint8_t out) {
    SPDR = out;
    while (!(SPSR & _BV(SPIF))) {
    }
    return SPDR;
}
#else
// Another MCU: no SPI through this layer (reads give 0xFF, as an absent chip).
void spi_bus_begin() {}
void spi_device(SpiDevice& d, uint8_t cs_pin, uint8_t, uint32_t) {
    d.cs_port = 0;
    d.cs_pin = cs_pin;
    d.cs_mask = 0;
    d.spcr = d.spsr = 0;
}
void spi_select(const SpiDevice&, bool) {}
void spi_begin(uint8_t) {}
void spi_select(bool) {}
uint8_t spi_transfer(uint8_t) { return 0xFF; }
#endif

}  // namespace pal
}  // namespace fsw

#if FSW_SLEEP
// A sub-period of the cycle timer ended while nothing waited for it: the
// clock moves on, and a cycle start that passed is marked due, with why it
// was missed (the running cycle overran, or something else held the CPU).
ISR(TIMER1_COMPA_vect) {
    using fsw::pal::g_ct;
    SMCR = 0;  // cycle_wait() sleeps no more (its loop reads SE)
    if (fsw::pal::sub_period_ended()) {
        if (g_ct.due == 0) g_ct.why = g_ct.running ? fsw::pal::kCycleLateOverrun : fsw::pal::kCycleLateOther;
        if (g_ct.due != 0xFFu) ++g_ct.due;
    }
}
// The CPU wakes to wait out the last stretch before a cycle (cycle_wait()),
// told so by SE cleared: it sleeps no more. Naked: r24 is the only register
// it changes (ldi and out leave the status register alone), 10 bytes where
// the compiler's handler saves r0, r1 and SREG around the store.
ISR(TIMER1_COMPB_vect, ISR_NAKED) {
    __asm__ __volatile__(
        "push r24\n\t"
        "ldi r24, 0\n\t"
        "out %[smcr], r24\n\t"
        "pop r24\n\t"
        "reti\n\t" ::[smcr] "I"(_SFR_IO_ADDR(SMCR))
        : "memory");
}
#endif

#endif  // FSW_PLATFORM_ARDUINO
