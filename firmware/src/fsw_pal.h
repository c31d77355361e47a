// Platform abstraction layer: the free functions every PSL implements
// (clock, analog/digital I/O, console, critical section, watchdog). One PSL
// is compiled per build: psl_arduino.cpp or psl_native.cpp. No virtuals.
#ifndef FSW_PAL_H
#define FSW_PAL_H

#include "fsw_app.h"
#include "fsw_types.h"

#if defined(__AVR__)
#include <avr/interrupt.h>
#include <avr/io.h>
// The start and end of a naked interrupt handler (ISR_NAKED) that uses
// r24, r25 and Z and changes the status register: they are saved, the
// status register through r24, and put back before `reti` (the UART's receive handler).
#define FSW_ISR_SAVE_R24_R25_Z \
    "push r24\n\t"             \
    "in   r24, __SREG__\n\t"   \
    "push r24\n\t"             \
    "push r25\n\t"             \
    "push r30\n\t"             \
    "push r31\n\t"
#define FSW_ISR_RESTORE_R24_R25_Z_RETI \
    "pop  r31\n\t"                     \
    "pop  r30\n\t"                     \
    "pop  r25\n\t"                     \
    "pop  r24\n\t"                     \
    "out  __SREG__, r24\n\t"           \
    "pop  r24\n\t"                     \
    "reti\n\t"
#endif

namespace fsw {
namespace pal {

// ---- lifecycle --------------------------------------------------------------
// Starts the platform (called once by executor_begin; idempotent).
void begin();
#if defined(__AVR__) && FSW_SLEEP
// What of the Arduino core's init() a firmware that never uses the core's
// timers needs: the ADC on at 125 kHz (as analogRead and the background
// scan expect it), the UART's pins released, interrupts on. The generated
// main() calls it in place of the core's main() and init(), so Timer0's
// overflow interrupt and millis()'s state are not linked (docs/runtime.md).
void boot();
#endif

// ---- Clock ------------------------------------------------------------------
// 32-bit microseconds / milliseconds since boot (wrap every 71.6 min / 49.7 d).
uint32_t micros32();
uint32_t millis32();
// 64-bit monotonic time, extended from the 32-bit counters (fsw_clock.h).
// Each must be called at least once per wrap period of its 32-bit source;
// generated machine tasks call the one `G` is written from every cycle.
uint64_t micros64();
uint64_t millis64();

// ---- Cycle timer (FSW_SLEEP: the sleeping executor) ----------------------------
#if FSW_SLEEP
// What cycle_wait() found.
enum CycleWait : uint8_t {
    kCycleOnTime = 0,       // a cycle starts now, on the timer's count
    kCycleLateOverrun = 1,  // a cycle starts late: the previous cycle's tasks ran past its start
    kCycleLateOther = 2,    // a cycle starts late: something else held the CPU at its start
                            // (interrupts, the link's service between cycles)
    kCycleNotDue = 0xFF     // no cycle yet: another interrupt woke the CPU
};
// Starts the timer that paces cycles of `period_us` (1..1000000, a divisor
// of 1000000) and keeps the clock from then on; the first cycle is due at once.
void cycle_timer_begin(uint32_t period_us);
// Sleeps until the next cycle is due, or, when `background` (the main loop
// has work between cycles: the link's transmit buffer, an EEPROM writer),
// until any interrupt wakes the CPU (kCycleNotDue then). Without background
// work the CPU sleeps on through the other interrupts (the UART's transmit,
// the ADC's scan): each would otherwise run the main loop for nothing.
// A cycle that is due returns with interrupts on, marked as running until
// cycle_end(); `skipped` counts the cycles whose start passed unserved.
uint8_t cycle_wait(uint8_t& skipped, bool background = true);
// The cycle cycle_wait() started has ended.
void cycle_end();
#endif

// ---- AnalogIO ---------------------------------------------------------------
// Raw ADC reading of an analog pin (board pin number, e.g. A0 = 14 on an Uno).
uint16_t analog_read(uint8_t pin);
// PWM output, duty 0..255.
void analog_write(uint8_t pin, uint8_t duty);
// Conversions in the background (non-blocking analog inputs): converts `n`
// analog pins in turn, entry i's pin being the byte at pins + i * stride
// (FSW_FLASH), and stores each count into raw[i] as its conversion ends.
// On an MCU the converter's interrupt stores a count and starts the next
// conversion, so nobody waits (about 104 us each on an AVR at 16 MHz); the
// host converts them all at once. Returns false, starting nothing, while a
// scan is still running; adc_scan_busy() says whether one is.
bool adc_scan_start(const uint8_t* pins, uint8_t stride, uint8_t n, volatile uint16_t* raw);
bool adc_scan_busy();

// ---- DigitalIO --------------------------------------------------------------
enum PinMode : uint8_t { kInput = 0, kInputPullup = 1, kOutput = 2 };
void pin_mode(uint8_t pin, uint8_t mode);
bool digital_read(uint8_t pin);
void digital_write(uint8_t pin, bool high);

// ---- Console (the serial port) ----------------------------------------------
void console_begin(uint32_t baud);
// Next received byte, or -1 when none is waiting.
int16_t console_read();
// The received bytes read where they wait, for a link that decodes a
// command where the receive ring holds it (no buffer of its own: fsw_app.h
// kAppRxRing, docs/runtime.md "The console"). console_peek(i): the i-th
// byte waiting (0: the one console_read() returns next), or -1 when no more
// than i wait. console_run(n): the first n bytes waiting (n <= those
// waiting) in one run of memory, the ring turned when they wrap round its
// end (interrupts off meanwhile: on an AVR about 12 cycles a byte of the
// ring); valid until the next console_drop. console_drop(n): the first n
// bytes waiting taken off (n <= those waiting); a ring left empty starts
// again from its front, so that a command that arrives in an empty ring
// lies in one run.
int16_t console_peek(uint8_t i);
uint8_t* console_run(uint8_t n);
void console_drop(uint8_t n);
// console_write copies the bytes into the transmit buffer; console_write_space
// is the bytes it takes now without waiting. Not on AVR with the kit's
// UART0 driver, which has no transmit buffer: it sends what console_send
// hands it, where it lies.
void console_write(const uint8_t* data, uint16_t len);
uint16_t console_write_space();
// Sends the `len` bytes at `data` where they lie (no copy: the link's frames
// go out of its own transmit buffer), after the bytes handed before. `data`
// continues the run handed last (it starts where that one ends) or starts a
// second run, which goes out after the first; never a third while two are
// under way. The caller leaves the bytes as they are until
// console_sending() has passed them. Never waits.
void console_send(const uint8_t* data, uint16_t len);
// The next byte the UART takes, in a run console_send handed; 0 once it has
// taken every byte handed (the bytes may all be reused).
const uint8_t* console_sending();
// Whether the bytes handed go out only as the caller polls console_sending()
// (the core's Serial, which takes them as its own buffer drains); the kit's
// UART0 driver and the host send them by themselves.
bool console_needs_poll();

// ---- Critical section -------------------------------------------------------
// Interrupts off on an MCU (nests: the previous state is restored); a
// re-entrant process-wide lock on the host.
typedef uint8_t IrqState;
#if defined(__AVR__)
// Inline on AVR: three instructions, cheap enough to wrap every element access.
inline IrqState critical_enter() {
    const IrqState s = SREG;
    cli();  // also a compiler memory barrier
    return s;
}
inline void critical_exit(IrqState saved) {
    __asm__ __volatile__("" ::: "memory");
    SREG = saved;
}
#else
IrqState critical_enter();
void critical_exit(IrqState saved);
#endif

#if FSW_SLEEP
// ---- The sleeping executor's cycle timer (psl_arduino.cpp) ---------------------
// Its state, here so that the executor reads the clock around each task run
// with micros32()'s code inline (micros32_inline) rather than a call of it.
#if F_CPU == 16000000L
#define FSW_T1_TICKS_PER_US 2u  // clk/8: 0.5 us a tick
#elif F_CPU == 8000000L
#define FSW_T1_TICKS_PER_US 1u
#else
#error "fswkit: the sleeping executor's timer needs F_CPU of 8 or 16 MHz: set FSW_SLEEP=0"
#endif
#if !defined(TIMSK1) || !defined(OCIE1B) || !defined(WGM12)
#error "fswkit: the sleeping executor needs a 16-bit Timer1 with two compare units: set FSW_SLEEP=0"
#endif
// The timer's settings for a base period: a cycle of P us is n equal
// sub-periods of P / n us, n the smallest power of two with P / n <= 32000
// (P = 2^a 5^b, a divisor of 1000000: n <= 32), each ended by OCR1A.
struct CycleSettings {
    uint16_t sub_us;    // a sub-period, us; as whole ms + us:
    uint16_t sub_ms;
    uint16_t sub_frac;
    uint16_t top;       // OCR1A: sub_us in ticks, less one
    uint16_t early;     // OCR1B: the count where the CPU wakes to spin
    uint16_t quiet;     // the count after which the last sub-period starts no background work
    uint8_t last;       // n - 1
    uint8_t spin;       // period too short to sleep in: spin from mid-period
};
// How long before a cycle's start the CPU wakes (fsw_config.h FSW_WAKE_EARLY_US).
inline __attribute__((always_inline)) uint16_t wake_early_us() {
    return FSW_WAKE_EARLY_US != 0 ? FSW_WAKE_EARLY_US : app_has(kAppSensors) ? 24u : 16u;
}
// For the periods cycle_timer_begin takes (1..1000000 us, a divisor of
// 1000000: at most five halvings), without a loop (the halvings as a
// choice): folded whole for a constant.
inline __attribute__((always_inline)) CycleSettings cycle_settings(uint32_t period_us) {
    const uint32_t m = 32000u;  // the longest sub-period: x 2 ticks fits OCR1A; sums below fit 16 bits
    const uint8_t k = period_us > 16u * m ? 5u : period_us > 8u * m ? 4u : period_us > 4u * m ? 3u
                      : period_us > 2u * m ? 2u : period_us > m ? 1u : 0u;
    CycleSettings c;
    c.sub_us = static_cast<uint16_t>(period_us >> k);
    c.sub_ms = static_cast<uint16_t>(c.sub_us / 1000u);
    c.sub_frac = static_cast<uint16_t>(c.sub_us % 1000u);
    c.top = static_cast<uint16_t>(c.sub_us * FSW_T1_TICKS_PER_US - 1u);
    const uint16_t early_ticks = wake_early_us() * FSW_T1_TICKS_PER_US;
    c.spin = c.top < 4u * early_ticks;
    c.early = c.spin ? static_cast<uint16_t>(c.top / 2u + 1u) : static_cast<uint16_t>(c.top - early_ticks);
    const uint16_t guard_ticks = FSW_BACKGROUND_GUARD_US * FSW_T1_TICKS_PER_US;
    c.quiet = c.early > guard_ticks ? static_cast<uint16_t>(c.early - guard_ticks) : 0u;
    c.last = static_cast<uint8_t>((1u << k) - 1u);
    return c;
}
// The running period's settings: where the application's base period is a
// constant (fsw_app.h app_period_us) each is a constant LTO folds into its
// uses, and g_cs is dropped; else cycle_timer_begin keeps them in g_cs.
extern CycleSettings g_cs;
#define FSW_CYCLE_SETTING(field) (app_period_us != 0 ? cycle_settings(app_period_us).field : g_cs.field)
inline __attribute__((always_inline)) uint16_t ct_sub_us() { return FSW_CYCLE_SETTING(sub_us); }
inline __attribute__((always_inline)) uint16_t ct_sub_ms() { return FSW_CYCLE_SETTING(sub_ms); }
inline __attribute__((always_inline)) uint16_t ct_sub_frac() { return FSW_CYCLE_SETTING(sub_frac); }
inline __attribute__((always_inline)) uint16_t ct_top() { return FSW_CYCLE_SETTING(top); }
inline __attribute__((always_inline)) uint16_t ct_early() { return FSW_CYCLE_SETTING(early); }
inline __attribute__((always_inline)) uint16_t ct_quiet() { return FSW_CYCLE_SETTING(quiet); }
inline __attribute__((always_inline)) uint8_t ct_last() { return FSW_CYCLE_SETTING(last); }
inline __attribute__((always_inline)) uint8_t ct_spin() { return FSW_CYCLE_SETTING(spin); }
#undef FSW_CYCLE_SETTING

// (The microseconds past `ms` are a variable of their own, psl_arduino.cpp:
// a sub-period of whole milliseconds never reads it, and LTO drops it.)
struct CycleTimer {
    uint32_t base_us;   // the clock at the start of the running sub-period
    uint32_t ms;        // milliseconds at that start
    uint8_t sub;        // sub-periods ended in this cycle
    volatile uint8_t due;       // cycle starts passed, not yet served (saturates)
    volatile uint8_t why;       // why the first of them was missed (CycleWait)
    volatile uint8_t running;   // a cycle's tasks are running
};
extern CycleTimer g_ct;

// micros32(), inline: the executor's clock read for a task run past a
// sub-period's end (cycle_clock below for the others; a call of
// micros32() cost about 20 AVR cycles more each, on the rocket's seven
// tasks about 150 a cycle). Interrupts off: the timer's count (0.5 us
// ticks at 16 MHz) past the sub-period's start, and the start; a
// sub-period that ended but that the interrupt has not counted yet (the
// compare's flag set and the count wrapped past it) is added. The wrap is
// looked at only where the flag is set, the sum after the critical
// section: about 24 cycles (29 with the flag kept in a register for a test
// after the sum; millis32 reads the count alike).
inline __attribute__((always_inline)) uint32_t micros32_inline() {
    const IrqState saved = critical_enter();
    const uint16_t t = TCNT1;
    uint32_t base = g_ct.base_us;
    if ((TIFR1 & _BV(OCF1A)) != 0 && t < ct_early()) base += ct_sub_us();  // a sub-period ended, not yet counted
    critical_exit(saved);
    return base + static_cast<uint16_t>(t / FSW_T1_TICKS_PER_US);
}

// The clock's base for a running cycle's marks (fsw_executor.cpp), with
// the microseconds past it now in `us`: micros32_inline()'s parts, its
// sum left to the marks.
inline __attribute__((always_inline)) uint32_t cycle_base(uint16_t& us) {
    const IrqState saved = critical_enter();
    const uint16_t t = TCNT1;
    uint32_t base = g_ct.base_us;
    if ((TIFR1 & _BV(OCF1A)) != 0 && t < ct_early()) base += ct_sub_us();  // a sub-period ended, not yet counted
    critical_exit(saved);
    us = static_cast<uint16_t>(t / FSW_T1_TICKS_PER_US);
    return base;
}

// The executor's clock within a running cycle (fsw_executor.cpp): true,
// with the microseconds past the running sub-period's start in `us`, where
// no sub-period has ended since the cycle started: `due` and `sub` are
// still 0 (cycle_wait()'s, sub_period_ended()'s; neither goes back to 0
// within a cycle) and no end waits for its interrupt (the compare's flag).
// Then the clock's base is the one of the cycle's start, and
// micros32_inline() would return it plus `us`: two such reads differ by
// the difference of their `us`. No critical section: the count is read
// first, the flag then, the counts last; an end at the count's wrap either
// still waits (its flag is set) or its handler ran to the end before the
// counts are read (the vector clears the flag). No handler of the kit
// uses Timer1's 16-bit registers (their shared TEMP byte).
inline __attribute__((always_inline)) bool cycle_clock(uint16_t& us) {
    const uint16_t t = TCNT1;
    __asm__ __volatile__("" ::: "memory");
    const bool none = (TIFR1 & _BV(OCF1A)) == 0 && g_ct.due == 0 && (ct_last() == 0 || g_ct.sub == 0);
    us = static_cast<uint16_t>(t / FSW_T1_TICKS_PER_US);
    return none;
}
#endif

// ---- EEPROM -----------------------------------------------------------------
// Bytes of EEPROM (an ATmega328P's 1,024; the host's model has as many).
uint16_t eeprom_size();
// A byte; waits for a write in progress to end (at most one byte's write
// time: 3.4 ms on an AVR), so it is for boot and for a writer that is idle.
uint8_t eeprom_read(uint16_t addr);
// Whether a byte write may start now (the previous one has ended).
bool eeprom_ready();
// Starts writing one byte (only when eeprom_ready()); returns at once. On
// an AVR the write ends 3.4 ms later, and the EEPROM-ready interrupt wakes
// a sleeping CPU then, so a background writer goes on at the EEPROM's pace.
void eeprom_write(uint16_t addr, uint8_t value);

// ---- SPI (master) -----------------------------------------------------------
// The SPI bus as master, MSB first, shared by several devices, each with its
// own chip select (a board pin, active low) and its own mode and clock,
// applied as it is selected. Register level: no Arduino SPI library.
//
// A device: its chip select and the SPI's control bits for it (filled by
// spi_device; on the host only cs_pin is used).
struct SpiDevice {
    volatile uint8_t* cs_port;
    uint8_t cs_pin, cs_mask;
    uint8_t spcr, spsr;  // AVR: SPCR (mode, clock) and SPSR's SPI2X for it
};
// The bus alone: MOSI, SCK and (on an AVR) the bus's own SS pin made
// outputs (as master it must not be an input pulled low), master on.
// Idempotent; selects no device.
void spi_bus_begin();
// Describes the device on `cs_pin` (its chip select made an output, high:
// deselected) at SPI `mode` (0..3: CPOL << 1 | CPHA) and the fastest clock
// F_CPU / 2^k (k = 1..7) not above `max_hz`: ADXL345 mode 3, 5 MHz ->
// F_CPU / 4 = 4 MHz on a 16 MHz Uno.
void spi_device(SpiDevice& d, uint8_t cs_pin, uint8_t mode, uint32_t max_hz);
// Selects the device (its mode and clock set, then its chip select low),
// or deselects it (chip select high).
void spi_select(const SpiDevice& d, bool on);
// The bus (spi_bus_begin) and its default device on `cs_pin` at mode 0,
// the fastest clock (F_CPU / 2): the flight recorder's NOR flash.
void spi_begin(uint8_t cs_pin);
// Selects (true) or deselects the default device.
void spi_select(bool on);
// Shifts `out` out and returns the byte shifted in meanwhile; waits for the
// shift (16 CPU cycles on an AVR at F_CPU / 2, 32 at F_CPU / 4).
uint8_t spi_transfer(uint8_t out);

// ---- Watchdog ---------------------------------------------------------------
// Arms the watchdog (FSW_WATCHDOG_MS) when FSW_WATCHDOG is on.
void watchdog_begin();
void watchdog_kick();
// Reset cause captured at boot (AVR: MCUSR bits; native: settable by tests).
uint8_t reset_cause();

}  // namespace pal

// Scoped critical section.
class CriticalSection {
public:
    CriticalSection() : saved_(pal::critical_enter()) {}
    ~CriticalSection() { pal::critical_exit(saved_); }

private:
    CriticalSection(const CriticalSection&);
    CriticalSection& operator=(const CriticalSection&);
    pal::IrqState saved_;
};

}  // namespace fsw

#endif  // FSW_PAL_H
