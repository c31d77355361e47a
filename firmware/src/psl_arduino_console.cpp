// Arduino PSL, Console: the serial port. On AVR, a small interrupt-driven
// UART0 driver (two rings, two interrupts); elsewhere, or with
// FSW_CONSOLE_ARDUINO_SERIAL=1, the core's Serial. Its own file so that a
// build that never uses the console links neither.
#include "fsw_config.h"

#if FSW_PLATFORM_ARDUINO

#include <Arduino.h>

#include "fsw_pal.h"

#if FSW_CONSOLE_ARDUINO_SERIAL

namespace fsw {
namespace pal {

void console_begin(uint32_t baud) { Serial.begin(baud); }
void console_write(const uint8_t* data, uint16_t len) { Serial.write(data, len); }
int16_t console_read() { return static_cast<int16_t>(Serial.read()); }
uint16_t console_write_space() { return static_cast<uint16_t>(Serial.availableForWrite()); }

}  // namespace pal
}  // namespace fsw

#else  // the built-in UART0 driver (AVR)

#if defined(USART_RX_vect)  // ATmega328P (Uno, Nano)
#define FSW_UART_RX_VECT USART_RX_vect
#define FSW_UART_UDRE_VECT USART_UDRE_vect
#elif defined(USART0_RX_vect)  // ATmega2560 (Mega)
#define FSW_UART_RX_VECT USART0_RX_vect
#define FSW_UART_UDRE_VECT USART0_UDRE_vect
#else
#error "fswkit: no USART0 on this MCU: set FSW_CONSOLE_ARDUINO_SERIAL=1"
#endif

namespace {

const uint8_t kTxMask = FSW_CONSOLE_TX_SIZE - 1;
const uint8_t kRxMask = FSW_CONSOLE_RX_SIZE - 1;

// One free slot tells a full ring from an empty one. Each index has one
// writer: the heads belong to the writer of the ring, the tails to its reader.
uint8_t g_tx[FSW_CONSOLE_TX_SIZE];
uint8_t g_rx[FSW_CONSOLE_RX_SIZE];
volatile uint8_t g_rx_head, g_rx_tail;
#if defined(GPIOR1) && defined(GPIOR2)
// The transmit ring's indices in two of the MCU's general-purpose I/O
// registers (nothing else in the kit or the Arduino core uses them): the
// handler below reads and writes them with `in` and `out`, a cycle each
// where RAM takes two, 4 cycles a byte sent. console_begin zeroes them.
#define FSW_TX_HEAD GPIOR1
#define FSW_TX_TAIL GPIOR2
#define FSW_TX_IN "in"
#define FSW_TX_OUT "out"
#define FSW_TX_REG(r) "I"(_SFR_IO_ADDR(r))
#else
volatile uint8_t g_tx_head, g_tx_tail;
#define FSW_TX_HEAD g_tx_head
#define FSW_TX_TAIL g_tx_tail
#define FSW_TX_IN "lds"
#define FSW_TX_OUT "sts"
#define FSW_TX_REG(r) "i"(&(r))
#endif

}  // namespace

// A received byte into the ring; dropped when it is full (the uplink's CRC
// and COBS checks then refuse the frame it belonged to).
ISR(FSW_UART_RX_VECT) {
    const uint8_t b = UDR0;
    const uint8_t h = g_rx_head;
    const uint8_t next = static_cast<uint8_t>((h + 1u) & kRxMask);
    if (next != g_rx_tail) {
        g_rx[h] = b;
        g_rx_head = next;
    }
}

// The data register is free: the next byte, and the interrupt off once the
// ring is empty (console_write turns it back on). It runs once a byte sent
// (about 18 times a cycle on the demo flight): naked, it saves only the
// three registers and the status register it uses, 40 cycles a byte where
// the compiler's handler took 59 (44 with the ring's indices in RAM). In C:
//     uint8_t t = g_tx_tail;
//     if (t != g_tx_head) {
//         UDR0 = g_tx[t];
//         t = (t + 1) & kTxMask;
//         g_tx_tail = t;
//     }
//     if (t == g_tx_head) UCSR0B &= ~_BV(UDRIE0);
ISR(FSW_UART_UDRE_VECT, ISR_NAKED) {
    __asm__ __volatile__(
        "push r24\n\t"
        "in   r24, __SREG__\n\t"
        "push r24\n\t"
        "push r30\n\t"
        "push r31\n\t"
        FSW_TX_IN "  r30, %[tail]\n\t"
        FSW_TX_IN "  r24, %[head]\n\t"
        "cp   r30, r24\n\t"
        "breq 1f\n\t"
        "ldi  r31, 0\n\t"  // Z = g_tx + t
        "subi r30, lo8(-(%[ring]))\n\t"
        "sbci r31, hi8(-(%[ring]))\n\t"
        "ld   r24, Z+\n\t"
        "sts  %[udr], r24\n\t"
        "subi r30, lo8(%[ring])\n\t"  // t + 1 (the low byte is all the mask keeps)
        "andi r30, %[mask]\n\t"
        FSW_TX_OUT " %[tail], r30\n\t"
        FSW_TX_IN "  r24, %[head]\n\t"
        "cp   r30, r24\n\t"
        "brne 2f\n\t"
        "1:\n\t"
        "lds  r24, %[ucsrb]\n\t"
        "andi r24, %[no_udrie]\n\t"
        "sts  %[ucsrb], r24\n\t"
        "2:\n\t"
        "pop  r31\n\t"
        "pop  r30\n\t"
        "pop  r24\n\t"
        "out  __SREG__, r24\n\t"
        "pop  r24\n\t"
        "reti\n\t" ::[tail] FSW_TX_REG(FSW_TX_TAIL),
        [head] FSW_TX_REG(FSW_TX_HEAD), [ring] "i"(g_tx), [mask] "M"(kTxMask), [udr] "n"(_SFR_MEM_ADDR(UDR0)),
        [ucsrb] "n"(_SFR_MEM_ADDR(UCSR0B)), [no_udrie] "M"(0xFF & ~_BV(UDRIE0))
        : "memory");  // it reads the ring console_write fills
}

namespace fsw {
namespace pal {

// 8N1 with double speed, the divisor rounded as the Arduino core does
// (115200 baud at 16 MHz: UBRR 16, 117,647 baud, +2.1 %). Double speed is
// set before the divisor: silicon takes either order, but simavr fixes the
// bit rate when UBRR0 is written, and would run the line at half speed.
void console_begin(uint32_t baud) {
    const uint16_t ubrr = static_cast<uint16_t>((F_CPU / 4u / baud - 1u) / 2u);
    FSW_TX_HEAD = 0;  // an empty transmit ring (the registers' reset value too)
    FSW_TX_TAIL = 0;
    UCSR0A = _BV(U2X0);
    UBRR0 = ubrr;
    UCSR0C = static_cast<uint8_t>(_BV(UCSZ01) | _BV(UCSZ00));
    UCSR0B = static_cast<uint8_t>(_BV(RXEN0) | _BV(TXEN0) | _BV(RXCIE0));
}

// Never waits: bytes that do not fit are dropped (callers stay within
// console_write_space()). Copied in at most two runs (up to the ring's
// end, then from its start), not a byte at a time.
void console_write(const uint8_t* data, uint16_t len) {
    const uint8_t h = FSW_TX_HEAD;
    const uint8_t space = static_cast<uint8_t>((FSW_TX_TAIL - h - 1u) & kTxMask);
    if (len > space) len = space;
    if (len == 0) return;
    const uint8_t n = static_cast<uint8_t>(len);
    const uint8_t first = static_cast<uint8_t>(FSW_CONSOLE_TX_SIZE - h);  // 0: h is 0 in a ring of 256
    if (first == 0 || n <= first) {
        memcpy(g_tx + h, data, n);
    } else {
        memcpy(g_tx + h, data, first);
        memcpy(g_tx, data + first, static_cast<uint8_t>(n - first));
    }
    FSW_TX_HEAD = static_cast<uint8_t>((h + n) & kTxMask);
    // Read-modify-write against the interrupt clearing UDRIE0: at worst it
    // fires once more on an empty ring and turns itself off.
    UCSR0B = static_cast<uint8_t>(UCSR0B | _BV(UDRIE0));
}

int16_t console_read() {
    const uint8_t t = g_rx_tail;
    if (t == g_rx_head) return -1;
    const uint8_t b = g_rx[t];
    g_rx_tail = static_cast<uint8_t>((t + 1u) & kRxMask);
    return b;
}

uint16_t console_write_space() { return static_cast<uint8_t>((FSW_TX_TAIL - FSW_TX_HEAD - 1u) & kTxMask); }

}  // namespace pal
}  // namespace fsw

#endif  // FSW_CONSOLE_ARDUINO_SERIAL

#endif  // FSW_PLATFORM_ARDUINO
