/* twi_probe: an I2C (TWI) and SPI master for the simulated board's sensor
   parts (harness -I; tests/sim/test_twi_parts.py), bare ATmega328P at 16 MHz,
   no Arduino core. The TWI is driven through its registers, blocking.

   TWI on PC4 SDA, PC5 SCL (simavr does not model the wires); SPI on PB3
   MOSI, PB4 MISO, PB5 SCK, mode 3, an SPI part's chip select on PB1 (the
   Uno's D9); UART0 at 2 Mbaud (U2X, UBRR 0). At reset it prints `ready`;
   then each line the host sends is a script, comma-separated steps run with
   nothing sent on the UART in between, and it prints one line of results,
   one per step, in order:

     Waa<hex>       START, SLA+W to address aa, the bytes, STOP. `Wss`: ss is
                    the last TWI status (28 every byte ACKed, 18 no bytes,
                    20 address NACKed, 30 a byte NACKed). Its STOP starts the
                    clock of P, Z and T.
     Raann          START, SLA+R, nn bytes (ACK but the last), STOP.
                    `Rss<hex>` (58 when read, 48 address NACKed: no bytes)
     Xaarrnn        START, SLA+W, register rr, repeated START, SLA+R, nn
                    bytes, STOP: a register read. `Xss<hex>`, ss the status
                    that ended it (58, or 20 / 30 / 48 on a NACK)
     Paarrmmvv      X-reads register rr until (value & mm) == vv: `Ptttttttt`,
                    the clock at the read that saw it (Timer1 ticks, 0.5 us,
                    hex), or `P!ss` when a read fails
     Ztttttttt      waits until the clock reads tttttttt: `Ztttttttt`, when
     M / T          restarts the clock / `Ttttttttt`, the clock
     S<hex>         one SPI transaction on CS PB1: `S<hex>`, the bytes shifted in */
#include <avr/interrupt.h>
#include <avr/io.h>

#include "../probe_ticks.h"
#include <string.h>

#define CS (1 << PB1)

static char line[600];
static char out[1200];
static uint16_t o;
static uint32_t t_mark;


static uint8_t twi_wait(void) {
    while (!(TWCR & (1 << TWINT))) {}
    return TWSR & 0xF8;
}

/* START (or repeated START) and an address byte: the status after it. */
static uint8_t twi_start(uint8_t sla) {
    TWCR = (1 << TWINT) | (1 << TWSTA) | (1 << TWEN);
    const uint8_t st = twi_wait();
    if (st != 0x08 && st != 0x10) return st;
    TWDR = sla;
    TWCR = (1 << TWINT) | (1 << TWEN);
    return twi_wait();
}

static uint8_t twi_write(uint8_t v) {
    TWDR = v;
    TWCR = (1 << TWINT) | (1 << TWEN);
    return twi_wait();
}

static uint8_t twi_read(uint8_t ack, uint8_t* v) {
    TWCR = (1 << TWINT) | (1 << TWEN) | (ack ? (1 << TWEA) : 0);
    const uint8_t st = twi_wait();
    *v = TWDR;
    return st;
}

static void twi_stop(void) {
    TWCR = (1 << TWINT) | (1 << TWSTO) | (1 << TWEN);
    while (TWCR & (1 << TWSTO)) {}
}

static uint8_t spi(uint8_t v) {
    SPDR = v;
    while (!(SPSR & (1 << SPIF))) {}
    return SPDR;
}

static int nibble(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

static int hexbyte(const char* p) {
    const int a = nibble(p[0]), b = a < 0 ? -1 : nibble(p[1]);
    return b < 0 ? -1 : a << 4 | b;
}

static void emit(char c) {
    if (o < sizeof out - 1) out[o++] = c;
}

/* The low `digits` (2 or 8) hex digits of v, a byte at a time: a 32-bit
   shift by a variable count is a loop on the AVR, slow enough to show in
   the times measured. */
static void emit_hex(uint32_t v, uint8_t digits) {
    static const char hex[] = "0123456789abcdef";
    const uint8_t b[4] = {(uint8_t)(v >> 24), (uint8_t)(v >> 16), (uint8_t)(v >> 8), (uint8_t)v};
    for (uint8_t i = (uint8_t)(4 - digits / 2); i < 4; i++) {
        emit(hex[b[i] >> 4]);
        emit(hex[b[i] & 15]);
    }
}

/* A register read of n bytes into out (when emit is set); the status that ended it. */
static uint8_t reg_read(uint8_t a, uint8_t r, uint8_t n, uint8_t* last, uint8_t show) {
    uint8_t st = twi_start((uint8_t)(a << 1));
    if (st == 0x18) st = twi_write(r);
    if (st == 0x28) st = twi_start((uint8_t)(a << 1 | 1));
    if (st != 0x40) {
        twi_stop();
        return st;
    }
    if (show) emit_hex(0x58, 2);
    for (uint8_t i = 0; i < n; i++) {
        st = twi_read(i + 1 < n, last);
        if (show) emit_hex(*last, 2);
    }
    twi_stop();
    return 0x58;
}

/* Runs one step at p; returns the character after it. */
static const char* step(const char* p) {
    const char c = *p++;
    emit(c);
    if (c == 'W') {
        const int a = hexbyte(p);
        p += 2;
        uint8_t st = twi_start((uint8_t)(a << 1));
        while (st == 0x18 || st == 0x28) {
            const int v = hexbyte(p);
            if (v < 0) break;
            p += 2;
            st = twi_write((uint8_t)v);
        }
        twi_stop();
        t_mark = ticks();
        emit_hex(st, 2);
    } else if (c == 'R') {
        const int a = hexbyte(p), n = hexbyte(p + 2);
        p += 4;
        uint8_t st = twi_start((uint8_t)(a << 1 | 1)), v;
        if (st == 0x40) {
            const uint16_t k = o;
            emit_hex(0, 2);
            for (int i = 0; i < n; i++) {
                st = twi_read(i + 1 < n, &v);
                emit_hex(v, 2);
            }
            o = k, emit_hex(st, 2), o = (uint16_t)(k + 2 + 2 * n);
        } else {
            emit_hex(st, 2);
        }
        twi_stop();
    } else if (c == 'X') {
        const int a = hexbyte(p), r = hexbyte(p + 2), n = hexbyte(p + 4);
        p += 6;
        uint8_t v;
        const uint8_t st = reg_read((uint8_t)a, (uint8_t)r, (uint8_t)n, &v, 1);
        if (st != 0x58) emit_hex(st, 2);
    } else if (c == 'P') {
        const int a = hexbyte(p), r = hexbyte(p + 2), m = hexbyte(p + 4), want = hexbyte(p + 6);
        p += 8;
        for (;;) {
            uint8_t v;
            const uint8_t st = reg_read((uint8_t)a, (uint8_t)r, 1, &v, 0);
            const uint32_t t = ticks() - t_mark;
            if (st != 0x58) {
                emit('!');
                emit_hex(st, 2);
                break;
            }
            if ((v & m) == want) {
                emit_hex(t, 8);
                break;
            }
        }
    } else if (c == 'Z') {
        uint32_t t = 0;
        for (uint8_t k = 0; k < 8 && nibble(*p) >= 0; k++) t = t << 4 | (uint8_t)nibble(*p++);
        uint32_t now;
        while ((now = ticks() - t_mark) < t) {}
        emit_hex(now, 8);
    } else if (c == 'M') {
        t_mark = ticks();
    } else if (c == 'T') {
        emit_hex(ticks() - t_mark, 8);
    } else if (c == 'S') {
        PORTB &= ~CS;
        for (int v; (v = hexbyte(p)) >= 0; p += 2) emit_hex(spi((uint8_t)v), 2);
        PORTB |= CS;
    }
    while (*p && *p != ',') p++; /* anything else in the step is skipped */
    return p;
}

static void put(char c) {
    while (!(UCSR0A & (1 << UDRE0))) {}
    UDR0 = c;
}

static void print(const char* s, uint16_t n) {
    for (uint16_t i = 0; i < n; i++) put(s[i]);
    put('\n');
}

int main(void) {
    PORTB = CS;                          /* deselected before it drives the pin */
    DDRB = CS | (1 << PB2) | (1 << PB3) | (1 << PB5); /* SS as an output keeps the SPI master */
    SPCR = (1 << SPE) | (1 << MSTR) | (1 << CPOL) | (1 << CPHA); /* mode 3, clk/4 */
    TWSR = 0;
    TWBR = 12; /* 400 kHz (simavr takes 9 us a byte whatever it says) */
    UBRR0 = 0;
    UCSR0A = 1 << U2X0;
    UCSR0B = (1 << TXEN0) | (1 << RXEN0);
    UCSR0C = 3 << UCSZ00;
    ticks_begin();
    sei();
    print("ready", 5);
    for (;;) {
        uint16_t n = 0;
        for (;;) {
            while (!(UCSR0A & (1 << RXC0))) {}
            const char c = UDR0;
            if (c == '\n') break;
            if (n < sizeof line - 1) line[n++] = c;
        }
        line[n] = 0;
        o = 0;
        for (const char* p = line; *p;) {
            if (*p == ',') {
                emit(',');
                p++;
                continue;
            }
            p = step(p);
        }
        print(out, o);
    }
}
