/* reset_probe: what a firmware sees of a reset on the simulated board
   (tests/sim/test_reset_cause.py), bare ATmega328P at 16 MHz, no Arduino
   core.

   At boot, before the C runtime clears anything, .init3 keeps MCUSR and
   clears it, and turns the watchdog off (after a watchdog reset the part
   restarts it at 16 ms with WDRF set; fswkit's firmware does the same in
   psl_arduino.cpp). main() then prints one line on UART0 (2 Mbaud: U2X,
   UBRR 0):

     boot n=NN mcusr=MM kept=HHHHHHHHHHHHHHHH

   NN: the boots counted in .noinit (valid only when `kept` is the
   pattern), MM: MCUSR as read at boot, HH..: the 8 bytes of a .noinit
   pattern as found, before this boot writes it again. A reset that keeps
   SRAM shows the pattern; a power-on shows whatever RAM came up with.
   Then it writes the boot count into EEPROM byte 0 and waits. */
#include <avr/eeprom.h>
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/wdt.h>
#include <stdint.h>

static const uint8_t PATTERN[8] = {0xF5, 0x3C, 0xA7, 0x19, 0x6E, 0xD2, 0x84, 0x5B};

static uint8_t mcusr_at_boot __attribute__((section(".noinit")));
static uint8_t kept[8] __attribute__((section(".noinit")));
static uint8_t boots __attribute__((section(".noinit")));

void capture_mcusr(void) __attribute__((naked, used, section(".init3")));
void capture_mcusr(void) {
    mcusr_at_boot = MCUSR;
    MCUSR = 0;
#ifndef KEEP_WATCHDOG /* -DKEEP_WATCHDOG: a firmware that forgets, reset again and again */
    wdt_disable();
#endif
}

static void tx(char c) {
    while (!(UCSR0A & (1 << UDRE0))) {}
    UDR0 = (uint8_t)c;
}

static void hex(uint8_t b) {
    static const char digits[] = "0123456789abcdef";
    tx(digits[b >> 4]);
    tx(digits[b & 15]);
}

static void say(const char* s) {
    while (*s) tx(*s++);
}

int main(void) {
    UBRR0 = 0;
    UCSR0A = 1 << U2X0;
    UCSR0B = 1 << TXEN0;
    UCSR0C = 3 << UCSZ00;
    uint8_t valid = 1;
    for (uint8_t i = 0; i < 8; i++)
        if (kept[i] != PATTERN[i]) valid = 0;
    boots = valid ? (uint8_t)(boots + 1) : 1;
    say("boot n=");
    hex(boots);
    say(" mcusr=");
    hex(mcusr_at_boot);
    say(" kept=");
    for (uint8_t i = 0; i < 8; i++) hex(kept[i]);
    tx('\n');
    for (uint8_t i = 0; i < 8; i++) kept[i] = PATTERN[i];
    eeprom_write_byte((uint8_t*)0, boots); /* one EEPROM write a boot: where `eeprom cut 1` cuts the power */
    for (;;) {} /* wait for the next reset (asleep with interrupts off, simavr would call it done) */
}
