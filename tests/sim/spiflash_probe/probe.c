/* spiflash_probe: an SPI master for the simulated board's flash chip
   (tests/sim/test_spi_flash.py), bare ATmega328P at 16 MHz, no Arduino core.

   SPI on PB3 MOSI, PB4 MISO, PB5 SCK, the chip's CS on PB2 (the Uno's D10);
   UART0 at 2 Mbaud (U2X, UBRR 0). A script is a line of comma-separated
   steps, run with nothing sent on the UART in between (so that steps follow
   each other closely: simavr 1.6 takes 100 us to shift an SPI byte, the
   UART's bytes would add more):

     HEX        one transaction: CS low, the bytes, CS high; each pair of
                hex digits is replaced by the byte shifted in meanwhile.
                The time CS rose starts the clock of W and S.
     Wxxxxxxxx  poll status register 1 (05h, one transaction a poll) until
                BUSY clears; the 8 digits become the time from that clock's
                start to the poll that saw BUSY clear, in Timer1 ticks
                (0.5 us), hex
     Sxxxxxxxx  wait until the clock reads xxxxxxxx ticks, then read status
                register 1 once: the digits become the status (2) and the
                time it was read (6: ticks, hex); the chip samples its state
                as the status byte ends, a few cycles before this clock

   At reset it runs its own script (JEDEC ID, write enable, a page program,
   BUSY seen and polled, read back, a sector erase, BUSY seen and polled,
   read back) and prints
   `boot ` and the result; then it runs each line the host sends and prints
   the result. */
#include <avr/interrupt.h>
#include <avr/io.h>

#include "../probe_ticks.h"
#include <avr/pgmspace.h>

#define CS (1 << PB2)

static const char boot_script[] PROGMEM =
    "9F000000,06,05FF,"
    "020001000123456789abcdeffedcba9876543210,S00000000,W00000000,05FF,"
    "0300010000000000000000000000000000000000,"
    "06,20000000,S00000000,W00000000,"
    "0300010000000000000000000000000000000000";

static char line[1400]; /* a full page program's hex fits */
static uint32_t t_cs; /* when CS last rose after a HEX step */


static uint8_t spi(uint8_t out) {
    SPDR = out;
    while (!(SPSR & (1 << SPIF))) {}
    return SPDR;
}

static void put(char c) {
    while (!(UCSR0A & (1 << UDRE0))) {}
    UDR0 = c;
}

static int nibble(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

static char hexdigit(uint8_t v) { return "0123456789abcdef"[v & 15]; }

/* Writes the low `digits` hex digits of v at p. */
static void put_hex(char* p, uint32_t v, uint8_t digits) {
    for (uint8_t k = 0; k < digits && p[k]; k++) p[k] = hexdigit((uint8_t)(v >> (4 * (digits - 1 - k))));
}

/* One status register 1 read; the time it was read, since t_cs, in *when. */
static uint8_t status(uint32_t* when) {
    PORTB &= ~CS;
    spi(0x05);
    const uint8_t st = spi(0xFF);
    *when = ticks() - t_cs;
    PORTB |= CS;
    return st;
}

/* Runs a script in place: the results overwrite the digits. */
static void run(char* p) {
    while (*p) {
        if (*p == 'W' || *p == 'S') {
            uint32_t arg = 0, when;
            for (uint8_t k = 1; k <= 8 && nibble(p[k]) >= 0; k++) arg = arg << 4 | (uint8_t)nibble(p[k]);
            if (*p == 'W') {
                while (status(&when) & 0x01) {}
                put_hex(p + 1, when, 8);
            } else {
                while (ticks() - t_cs < arg) {}
                const uint8_t st = status(&when);
                put_hex(p + 1, st, 2);
                put_hex(p + 3, when, 6);
            }
            p++;
            while (*p && *p != ',') p++;
        } else if (nibble(p[0]) >= 0 && nibble(p[1]) >= 0) {
            PORTB &= ~CS;
            while (nibble(p[0]) >= 0 && nibble(p[1]) >= 0) {
                const uint8_t in = spi((uint8_t)(nibble(p[0]) << 4 | nibble(p[1])));
                p[0] = hexdigit(in >> 4);
                p[1] = hexdigit(in);
                p += 2;
            }
            PORTB |= CS;
            t_cs = ticks();
        } else {
            p++;
        }
    }
}

static void print(const char* s) {
    for (; *s; s++) put(*s);
    put('\n');
}

int main(void) {
    PORTB = CS;                              /* deselected before it drives the pin */
    DDRB = CS | (1 << PB3) | (1 << PB5);     /* SS as an output keeps the SPI master */
    SPCR = (1 << SPE) | (1 << MSTR);         /* mode 0, clk/4 */
    UBRR0 = 0;
    UCSR0A = 1 << U2X0;
    UCSR0B = (1 << TXEN0) | (1 << RXEN0);
    UCSR0C = 3 << UCSZ00;
    ticks_begin();
    sei();

    strcpy_P(line, boot_script);
    run(line);
    put('b'), put('o'), put('o'), put('t'), put(' ');
    print(line);
    for (;;) {
        uint16_t n = 0;
        for (;;) {
            while (!(UCSR0A & (1 << RXC0))) {}
            char c = UDR0;
            if (c == '\n') break;
            if (n < sizeof line - 1) line[n++] = c;
        }
        line[n] = 0;
        run(line);
        print(line);
    }
}
