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

// The receive ring and its size less one (a power of two, 4..256): the
// application's own, sized by its generated code for what its ground keeps
// in flight (docs/runtime.md, "The console"), else psl_arduino_console_rx.cpp's
// (FSW_CONSOLE_RX_SIZE), which the linker takes out of the runtime's archive
// only for a program that does not define them. LTO folds the mask into the
// code below (an immediate operand of the handler's `andi`).
extern "C" uint8_t fsw_console_rx[];
extern "C" const uint8_t fsw_console_rx_mask;

namespace {

const uint8_t kTxMask = FSW_CONSOLE_TX_SIZE - 1;
// UCSR0B as the driver runs it (receiver, transmitter, receive interrupt),
// without and with the data-register-empty interrupt.
#define FSW_UCSRB_IDLE (_BV(RXEN0) | _BV(TXEN0) | _BV(RXCIE0))
const uint8_t kUcsrbIdle = FSW_UCSRB_IDLE;
const uint8_t kUcsrbSending = FSW_UCSRB_IDLE | _BV(UDRIE0);

// One free slot tells a full ring from an empty one. Each index has one
// writer: the heads belong to the writer of the ring, the tails to its reader.
// The transmit ring's tail is kept as a pointer into the ring (its place,
// not its index), its head as the low byte of one: the handler below then
// takes a byte, moves the tail on and wraps it with instructions that leave
// the status register alone (ld Z+, cpse, ldi, in/out), so it saves no
// SREG. Two pointers into a ring of at most 256 bytes differ in their low
// byte, so the low bytes are all a comparison needs.
uint8_t g_tx[FSW_CONSOLE_TX_SIZE];
volatile uint8_t g_rx_head, g_rx_tail;
#if defined(GPIOR0) && defined(GPIOR1) && defined(GPIOR2)
// The head (the low byte of its place, &g_tx[head]) and the tail's place
// in the MCU's three general-purpose I/O registers (nothing else in the kit
// or the Arduino core uses them): the handler reads and writes them with
// `in` and `out`, a cycle each where RAM takes two. console_begin sets them.
#define FSW_TX_HEAD GPIOR0
#define FSW_TX_TAIL_LO GPIOR1
#define FSW_TX_TAIL_HI GPIOR2
#define FSW_TX_IN "in"
#define FSW_TX_OUT "out"
#define FSW_TX_REG(r) "I"(_SFR_IO_ADDR(r))
#else
volatile uint8_t g_tx_head, g_tx_tail_lo, g_tx_tail_hi;
#define FSW_TX_HEAD g_tx_head
#define FSW_TX_TAIL_LO g_tx_tail_lo
#define FSW_TX_TAIL_HI g_tx_tail_hi
#define FSW_TX_IN "lds"
#define FSW_TX_OUT "sts"
#define FSW_TX_REG(r) "i"(&(r))
#endif

// A place's index in the transmit ring, from its low byte.
inline uint8_t tx_index(uint8_t lo) { return static_cast<uint8_t>((lo - reinterpret_cast<uintptr_t>(g_tx)) & kTxMask); }

}  // namespace

// A received byte into the ring; dropped when it is full (the uplink's CRC
// and COBS checks then refuse the frame it belonged to). Naked: it saves
// the four registers and the status register it uses, where the compiler's
// handler also saved r0, r1 and r18 (60 bytes of flash where it took 74).
// In C:
//     const uint8_t b = UDR0;
//     const uint8_t h = g_rx_head;
//     const uint8_t next = (h + 1) & fsw_console_rx_mask;
//     if (next != g_rx_tail) {
//         fsw_console_rx[h] = b;
//         g_rx_head = next;
//     }
ISR(FSW_UART_RX_VECT, ISR_NAKED) {
    __asm__ __volatile__(
        FSW_ISR_SAVE_R24_R25_Z
        "lds  r25, %[udr]\n\t"  // read whatever happens: it clears the interrupt's flag
        "lds  r30, %[head]\n\t"
        "mov  r24, r30\n\t"
        "subi r24, 0xFF\n\t"  // h + 1
        "andi r24, %[mask]\n\t"
        "lds  r31, %[tail]\n\t"
        "cp   r24, r31\n\t"
        "breq 1f\n\t"  // full: the byte is dropped
        "ldi  r31, 0\n\t"  // Z = fsw_console_rx + h
        "subi r30, lo8(-(%[ring]))\n\t"
        "sbci r31, hi8(-(%[ring]))\n\t"
        "st   Z, r25\n\t"
        "sts  %[head], r24\n\t"
        "1:\n\t"
        FSW_ISR_RESTORE_R24_R25_Z_RETI ::[udr] "n"(_SFR_MEM_ADDR(UDR0)),
        [head] "i"(&g_rx_head), [tail] "i"(&g_rx_tail), [ring] "i"(fsw_console_rx),
        [mask] "M"(fsw_console_rx_mask)
        : "memory");  // it fills the ring console_read empties
}

// The data register is free: the next byte, and the interrupt off once the
// ring is empty (console_write turns it back on). It runs once a byte sent
// (about 18 times a cycle on the demo flight): naked, and with no
// instruction that changes the status register, it saves only the three
// registers it uses: 39 cycles a byte with the vector's jump and the
// return, where the handler that kept indices and saved SREG took 47 (the
// compiler's, 59). The UART's control bits are the driver's own, so the
// interrupt goes off with a store of them, not a read-modify-write. In C:
//     uint8_t* t = tail;
//     UDR0 = *t++;
//     if (t == g_tx + FSW_CONSOLE_TX_SIZE) t = g_tx;
//     tail = t;
//     if (low byte of t == head) UCSR0B = kUcsrbIdle;
// (the interrupt is on only while the ring holds a byte).
ISR(FSW_UART_UDRE_VECT, ISR_NAKED) {
    __asm__ __volatile__(
        "push r24\n\t"
        "push r30\n\t"
        "push r31\n\t"
        FSW_TX_IN "  r30, %[tail_lo]\n\t"
        FSW_TX_IN "  r31, %[tail_hi]\n\t"
        "ld   r24, Z+\n\t"
        "sts  %[udr], r24\n\t"
        "ldi  r24, lo8(%[ring] + %[size])\n\t"
        "cpse r30, r24\n\t"
        "rjmp 1f\n\t"
        "ldi  r30, lo8(%[ring])\n\t"  // past the ring's end: its start
        "ldi  r31, hi8(%[ring])\n\t"
        "1:\n\t"
        FSW_TX_OUT " %[tail_lo], r30\n\t"
        FSW_TX_OUT " %[tail_hi], r31\n\t"
        FSW_TX_IN "  r24, %[head]\n\t"
        "cpse r30, r24\n\t"
        "rjmp 2f\n\t"
        "ldi  r24, %[idle]\n\t"  // the ring is empty: the interrupt off
        "sts  %[ucsrb], r24\n\t"
        "2:\n\t"
        "pop  r31\n\t"
        "pop  r30\n\t"
        "pop  r24\n\t"
        "reti\n\t" ::[tail_lo] FSW_TX_REG(FSW_TX_TAIL_LO),
        [tail_hi] FSW_TX_REG(FSW_TX_TAIL_HI), [head] FSW_TX_REG(FSW_TX_HEAD), [ring] "i"(g_tx),
        [size] "i"(FSW_CONSOLE_TX_SIZE), [udr] "n"(_SFR_MEM_ADDR(UDR0)), [ucsrb] "n"(_SFR_MEM_ADDR(UCSR0B)),
        [idle] "M"(FSW_UCSRB_IDLE)
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
    UCSR0B = 0;  // the interrupts off while the ring is set empty
    const uintptr_t ring = reinterpret_cast<uintptr_t>(g_tx);
    FSW_TX_TAIL_LO = static_cast<uint8_t>(ring);
    FSW_TX_TAIL_HI = static_cast<uint8_t>(ring >> 8);
    FSW_TX_HEAD = static_cast<uint8_t>(ring);
    UCSR0A = _BV(U2X0);
    UBRR0 = ubrr;
    UCSR0C = static_cast<uint8_t>(_BV(UCSZ01) | _BV(UCSZ00));
    UCSR0B = kUcsrbIdle;
}

uint16_t console_write_space() {
    return static_cast<uint8_t>((tx_index(FSW_TX_TAIL_LO) - tx_index(FSW_TX_HEAD) - 1u) & kTxMask);
}

// Never waits: bytes that do not fit are dropped (callers stay within
// console_write_space()). In two runs, to the ring's end and from its start,
// each a plain copy (7 cycles a byte; 10 when one loop tested every place
// for the ring's end), the place wrapped to the start when the first run
// ends at the ring's end (the handler compares low bytes of wrapped places).
void console_write(const uint8_t* data, uint16_t len) {
    uint8_t* p = g_tx + tx_index(FSW_TX_HEAD);
    uint8_t n = static_cast<uint8_t>(console_write_space());
    if (len < n) n = static_cast<uint8_t>(len);
    if (n == 0) return;
    // the first run: to the ring's end (0 for 256 bytes), or all of them
    uint8_t first = static_cast<uint8_t>(reinterpret_cast<uintptr_t>(g_tx + FSW_CONSOLE_TX_SIZE) -
                                         reinterpret_cast<uintptr_t>(p));
    if (static_cast<uint8_t>(first - 1u) >= n) first = n;
    uint8_t rest = static_cast<uint8_t>(n - first);
    __asm__ __volatile__(
        "1:  ld   __tmp_reg__, X+\n\t"
        "    st   Z+, __tmp_reg__\n\t"
        "    dec  %[first]\n\t"
        "    brne 1b\n\t"
        "    cpi  %A[p], lo8(%[ring] + %[size])\n\t"
        "    brne 2f\n\t"
        "    ldi  %A[p], lo8(%[ring])\n\t"  // at the ring's end: its start
        "    ldi  %B[p], hi8(%[ring])\n\t"
        "    mov  %[first], %[rest]\n\t"  // the second run, if any
        "    ldi  %[rest], 0\n\t"
        "    tst  %[first]\n\t"
        "    brne 1b\n\t"
        "2:\n\t"
        : [p] "+z"(p), [data] "+x"(data), [first] "+r"(first), [rest] "+d"(rest)
        : [ring] "i"(g_tx), [size] "i"(FSW_CONSOLE_TX_SIZE)
        : "memory");
    __asm__ __volatile__("" ::: "memory");  // the bytes in the ring before the head moves over them
    FSW_TX_HEAD = static_cast<uint8_t>(reinterpret_cast<uintptr_t>(p));
    // A store, not a read-modify-write. The interrupt is on only while the
    // ring holds a byte (its handler does not look before it takes one): it
    // turns itself off when it takes the last, and here the ring holds the
    // bytes just written. Should it run between the head's store and this
    // one, the ring held a byte before this write too (it was on), so it
    // takes that one and cannot have emptied the ring.
    UCSR0B = kUcsrbSending;
}

int16_t console_read() {
    const uint8_t t = g_rx_tail;
    if (t == g_rx_head) return -1;
    const uint8_t b = fsw_console_rx[t];
    g_rx_tail = static_cast<uint8_t>((t + 1u) & fsw_console_rx_mask);
    return b;
}

}  // namespace pal
}  // namespace fsw

#endif  // FSW_CONSOLE_ARDUINO_SERIAL

#endif  // FSW_PLATFORM_ARDUINO
