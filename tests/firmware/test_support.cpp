// Suite epilogue and, on AVR, the polled UART0 that carries Unity's output.
#include "test_support.h"

#if defined(__AVR__)
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <avr/wdt.h>
#else
#include <stdio.h>
#endif

static void put_str(const char* s) {
    while (*s) UNITY_OUTPUT_CHAR(*s++);
}

static void put_uint(unsigned long v) {
    char buf[12];
    int i = 0;
    do {
        buf[i++] = static_cast<char>('0' + v % 10u);
        v /= 10u;
    } while (v != 0);
    while (i > 0) UNITY_OUTPUT_CHAR(buf[--i]);
}

int fsw_test_finish(void) {
    const unsigned long total = Unity.NumberOfTests;
    const unsigned long failed = Unity.TestFailures;
    const unsigned long skipped = Unity.TestIgnores;
    put_uint(total - failed - skipped);
    put_str(" passed, ");
    put_uint(failed);
    put_str(" failed");
    if (skipped != 0) {
        put_str(", ");
        put_uint(skipped);
        put_str(" skipped");
    }
    UNITY_OUTPUT_CHAR('\n');
#if !defined(__AVR__)
    fflush(stdout);
#endif
    return failed == 0 && total != 0 ? 0 : 1;
}

#if defined(__AVR__)
// The Arduino core's init() clears UCSR0B; simavr then keeps UDRE0 clear
// until a byte is sent. The transmitter is idle after fsw_test_uart_begin(),
// so the first byte goes out without waiting (harmless on hardware too).
static bool uart_idle;

extern "C" void fsw_test_putc(int c) {
    if (!uart_idle) loop_until_bit_is_set(UCSR0A, UDRE0);
    uart_idle = false;
    UCSR0A |= _BV(TXC0);  // cleared by writing one: set again when sent
    UDR0 = static_cast<uint8_t>(c);
}

void fsw_test_uart_begin(void) {
    UBRR0 = 0;  // 2 Mbaud with U2X0 at 16 MHz: the simulation is not slowed
    UCSR0A = _BV(U2X0);
    UCSR0B = _BV(TXEN0);
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
    uart_idle = true;
}

void fsw_test_halt(void) {
    if (UCSR0B & _BV(TXEN0)) loop_until_bit_is_set(UCSR0A, TXC0);
    wdt_disable();
    cli();
    sleep_enable();
    sleep_cpu();
    for (;;) {}
}
#else
void fsw_test_uart_begin(void) {}
void fsw_test_halt(void) {}
#endif
