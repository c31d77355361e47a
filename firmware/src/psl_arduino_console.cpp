// Arduino PSL, Console: the serial port. On AVR, a small interrupt-driven
// UART0 driver (a receive ring; bytes sent where the caller keeps them;
// two interrupts); elsewhere, or with
// FSW_CONSOLE_ARDUINO_SERIAL=1, the core's Serial. Its own file so that a
// build that never uses the console links neither.
#include "fsw_config.h"

#if FSW_PLATFORM_ARDUINO

#include <Arduino.h>

#include "fsw_pal.h"

// The receive ring and its size less one (a power of two, 4..256): the
// application's own, sized by its generated code for what its ground keeps
// in flight (docs/runtime.md, "The console"), else psl_arduino_console_rx.cpp's
// (FSW_CONSOLE_RX_SIZE), which the linker takes out of the runtime's archive
// only for a program that does not define them. (The UART0 handler reads the
// mask where it lies, a byte of RAM: a constant of another object is no
// immediate operand where the runtime is compiled without LTO.)
extern "C" uint8_t fsw_console_rx[];
extern "C" const uint8_t fsw_console_rx_mask;

namespace fsw {
namespace pal {
namespace {

void reverse(uint8_t* a, uint8_t* b) {  // [a, b)
    while (a < --b) {
        const uint8_t x = *a;
        *a++ = *b;
        *b = x;
    }
}

// The receive ring's bytes turned so that the one at `t` is at its front
// (a command read in place that wraps round the ring's end: console_run):
// three reversals, about 17 cycles a byte of the ring (540 for a ring of
// 32). Its indices are the caller's to move.
inline void turn_bytes(uint8_t t) {
    uint8_t* const ring = fsw_console_rx;
    uint8_t* const end = ring + fsw_console_rx_mask + 1;
    reverse(ring, ring + t);
    reverse(ring + t, end);
    reverse(ring, end);
}

}  // namespace
}  // namespace pal
}  // namespace fsw

#if FSW_CONSOLE_ARDUINO_SERIAL

namespace fsw {
namespace pal {

void console_begin(uint32_t baud) { Serial.begin(baud); }
void console_write(const uint8_t* data, uint16_t len) { Serial.write(data, len); }
uint16_t console_write_space() { return static_cast<uint16_t>(Serial.availableForWrite()); }

// The received bytes read in place (fsw_pal.h): Serial's bytes are taken
// into the application's receive ring (fsw_console_rx, which the kit's
// UART driver fills on other builds) as far as the reader looks; the ring
// has no other writer here.
namespace {
uint8_t g_rx_head, g_rx_tail;
inline uint8_t rx_waiting() { return static_cast<uint8_t>((g_rx_head - g_rx_tail) & fsw_console_rx_mask); }
}  // namespace

int16_t console_read() {
    if (g_rx_head != g_rx_tail) {  // a byte the ring took already
        const uint8_t b = fsw_console_rx[g_rx_tail];
        g_rx_tail = static_cast<uint8_t>((g_rx_tail + 1u) & fsw_console_rx_mask);
        return b;
    }
    return static_cast<int16_t>(Serial.read());
}

int16_t console_peek(uint8_t i) {
    while (i >= rx_waiting()) {
        if (rx_waiting() == fsw_console_rx_mask) return -1;  // the ring is full
        const int c = Serial.read();
        if (c < 0) return -1;
        fsw_console_rx[g_rx_head] = static_cast<uint8_t>(c);
        g_rx_head = static_cast<uint8_t>((g_rx_head + 1u) & fsw_console_rx_mask);
    }
    return fsw_console_rx[(g_rx_tail + i) & fsw_console_rx_mask];
}

uint8_t* console_run(uint8_t n) {
    const uint8_t t = g_rx_tail;
    const uint16_t size = static_cast<uint16_t>(fsw_console_rx_mask + 1u);
    if (t + n <= size) return fsw_console_rx + t;
    turn_bytes(t);  // wrapped round the ring's end: turned, its tail at the front
    g_rx_head = static_cast<uint8_t>((g_rx_head - t) & fsw_console_rx_mask);
    g_rx_tail = 0;
    return fsw_console_rx;
}

void console_drop(uint8_t n) {
    g_rx_tail = static_cast<uint8_t>((g_rx_tail + n) & fsw_console_rx_mask);
    if (g_rx_tail == g_rx_head) g_rx_tail = g_rx_head = 0;  // empty: the next bytes go from the front
}

// The runs handed (console_send), fed to Serial as its buffer takes them
// whenever the caller asks where the sending is (console_needs_poll).
namespace {
const uint8_t* g_at;    // the next byte to hand to Serial (0: none)
const uint8_t* g_end;   // the end of its run
const uint8_t* g_next;  // the run after it (0: none)
const uint8_t* g_next_end;
}  // namespace

void console_send(const uint8_t* data, uint16_t len) {
    if (len == 0) return;
    if (g_at == 0) {
        g_at = data;
        g_end = data + len;
    } else if (data == g_end) {
        g_end = data + len;
    } else if (g_next == 0) {
        g_next = data;
        g_next_end = data + len;
    } else if (data == g_next_end) {
        g_next_end = data + len;
    }
}

const uint8_t* console_sending() {
    while (g_at != 0) {
        uint16_t n = static_cast<uint16_t>(g_end - g_at);
        const uint16_t room = static_cast<uint16_t>(Serial.availableForWrite());
        if (n > room) n = room;
        if (n == 0) break;
        Serial.write(g_at, n);
        g_at += n;
        if (g_at != g_end) break;
        g_at = g_next;
        g_end = g_next_end;
        g_next = 0;
    }
    return g_at;
}

bool console_needs_poll() { return true; }

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

// UCSR0B as the driver runs it (receiver, transmitter, receive interrupt),
// without and with the data-register-empty interrupt.
#define FSW_UCSRB_IDLE (_BV(RXEN0) | _BV(TXEN0) | _BV(RXCIE0))
const uint8_t kUcsrbIdle = FSW_UCSRB_IDLE;
const uint8_t kUcsrbSending = FSW_UCSRB_IDLE | _BV(UDRIE0);

// One free slot tells a full receive ring from an empty one. Each index has
// one writer: the head belongs to the handler, the tail to console_read.
volatile uint8_t g_rx_head, g_rx_tail;

// Transmit: no ring. The handler below sends the runs console_send handed,
// where the caller keeps them (the link's transmit buffer, which frames are
// built in): the place of the next byte (the tail; its high byte 0 when
// every byte handed went out: RAM starts at 0x100), the end of its run, and
// a second run to go on with at that end (its place's high byte 0: none).
// The handler takes a byte, moves the tail on and compares it with the end
// with instructions that leave the status register alone (ld Z+, cpse, in,
// out, lds, sts, ldi), so it saves no SREG.
#if defined(GPIOR0) && defined(GPIOR1) && defined(GPIOR2)
// The tail and the end's low byte in the MCU's three general-purpose I/O
// registers (nothing else in the kit or the Arduino core uses them): the
// handler reads and writes them with `in` and `out`, a cycle each where RAM
// takes two. console_begin sets them.
#define FSW_TX_END_LO GPIOR0
#define FSW_TX_TAIL_LO GPIOR1
#define FSW_TX_TAIL_HI GPIOR2
#define FSW_TX_IN "in"
#define FSW_TX_OUT "out"
#define FSW_TX_REG(r) "I"(_SFR_IO_ADDR(r))
#else
volatile uint8_t g_tx_end_lo, g_tx_tail_lo, g_tx_tail_hi;
#define FSW_TX_END_LO g_tx_end_lo
#define FSW_TX_TAIL_LO g_tx_tail_lo
#define FSW_TX_TAIL_HI g_tx_tail_hi
#define FSW_TX_IN "lds"
#define FSW_TX_OUT "sts"
#define FSW_TX_REG(r) "i"(&(r))
#endif
volatile uint8_t g_tx_end_hi;
volatile uint8_t g_tx_next[4];  // the second run: its place, then its end (little-endian)

}  // namespace

// A received byte into the ring; dropped when it is full (the uplink's CRC
// and COBS checks then refuse the frame it belonged to). Naked: it saves
// the four registers and the status register it uses, where the compiler's
// handler also saved r0, r1 and r18 (64 bytes of flash where it took 74;
// the mask read where it lies, a byte of RAM: see fsw_console_rx_mask).
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
        "lds  r31, %[mask]\n\t"
        "and  r24, r31\n\t"
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
        [mask] "i"(&fsw_console_rx_mask)
        : "memory");  // it fills the ring console_read empties
}

// The data register is free: the next byte, and at its run's end the
// second run, or the interrupt off when there is none (console_send turns
// it back on). It runs once a byte sent (about 18 times a cycle on the demo
// flight): naked, and with no instruction that changes the status
// register, it saves only the three registers it uses: 37 cycles a byte
// with the vector's jump and the return (the handler of the ring it
// replaced took 39; the compiler's, 59). The UART's control bits are the
// driver's own, so the interrupt goes off with a store of them, not a
// read-modify-write. In C:
//     uint8_t* t = tail;
//     UDR0 = *t++;
//     if (t == end) {
//         t = next; end = next_end; next = 0;
//         if (t == 0) UCSR0B = kUcsrbIdle;
//     }
//     tail = t;
// (the interrupt is on only while a byte handed waits).
ISR(FSW_UART_UDRE_VECT, ISR_NAKED) {
    __asm__ __volatile__(
        "push r24\n\t"
        "push r30\n\t"
        "push r31\n\t"
        FSW_TX_IN "  r30, %[tail_lo]\n\t"
        FSW_TX_IN "  r31, %[tail_hi]\n\t"
        "ld   r24, Z+\n\t"
        "sts  %[udr], r24\n\t"
        FSW_TX_IN "  r24, %[end_lo]\n\t"
        "cpse r30, r24\n\t"
        "rjmp 2f\n\t"  // not the run's end (the low bytes differ)
        "lds  r24, %[end_hi]\n\t"
        "cpse r31, r24\n\t"
        "rjmp 2f\n\t"
        "lds  r30, %[next]\n\t"  // the run's end: the second run's place and end
        "lds  r31, %[next] + 1\n\t"
        "lds  r24, %[next] + 2\n\t"
        FSW_TX_OUT " %[end_lo], r24\n\t"
        "lds  r24, %[next] + 3\n\t"
        "sts  %[end_hi], r24\n\t"
        "ldi  r24, 0\n\t"
        "sts  %[next] + 1, r24\n\t"  // no second run now
        "cpse r31, r24\n\t"
        "rjmp 2f\n\t"
        "ldi  r24, %[idle]\n\t"  // none: every byte handed went out, the interrupt off
        "sts  %[ucsrb], r24\n\t"
        "2:\n\t"
        FSW_TX_OUT " %[tail_lo], r30\n\t"
        FSW_TX_OUT " %[tail_hi], r31\n\t"
        "pop  r31\n\t"
        "pop  r30\n\t"
        "pop  r24\n\t"
        "reti\n\t" ::[tail_lo] FSW_TX_REG(FSW_TX_TAIL_LO),
        [tail_hi] FSW_TX_REG(FSW_TX_TAIL_HI), [end_lo] FSW_TX_REG(FSW_TX_END_LO), [end_hi] "i"(&g_tx_end_hi),
        [next] "i"(g_tx_next), [udr] "n"(_SFR_MEM_ADDR(UDR0)), [ucsrb] "n"(_SFR_MEM_ADDR(UCSR0B)),
        [idle] "M"(FSW_UCSRB_IDLE)
        : "memory");  // it reads the runs console_send hands
}

namespace fsw {
namespace pal {

// 8N1 with double speed, the divisor rounded as the Arduino core does
// (115200 baud at 16 MHz: UBRR 16, 117,647 baud, +2.1 %). Double speed is
// set before the divisor: silicon takes either order, but simavr fixes the
// bit rate when UBRR0 is written, and would run the line at half speed.
void console_begin(uint32_t baud) {
    const uint16_t ubrr = static_cast<uint16_t>((F_CPU / 4u / baud - 1u) / 2u);
    UCSR0B = 0;  // the interrupts off while nothing is being sent
    FSW_TX_TAIL_HI = 0;
    g_tx_next[1] = 0;
    UCSR0A = _BV(U2X0);
    UBRR0 = ubrr;
    UCSR0C = static_cast<uint8_t>(_BV(UCSZ01) | _BV(UCSZ00));
    UCSR0B = kUcsrbIdle;
}

// The handler reads what this writes: with interrupts off. A run that
// starts where the one going out (or the second) ends lengthens it; one
// that starts elsewhere becomes the second; a third is not the contract
// (fsw_pal.h) and is dropped.
void console_send(const uint8_t* data, uint16_t len) {
    if (len == 0) return;
    const uintptr_t at = reinterpret_cast<uintptr_t>(data), end = at + len;
    const uint8_t sreg = SREG;
    cli();
    if (FSW_TX_TAIL_HI == 0) {  // idle: this run goes out now
        FSW_TX_TAIL_LO = static_cast<uint8_t>(at);
        FSW_TX_TAIL_HI = static_cast<uint8_t>(at >> 8);
        FSW_TX_END_LO = static_cast<uint8_t>(end);
        g_tx_end_hi = static_cast<uint8_t>(end >> 8);
        // A store, not a read-modify-write: the interrupt is on only while a
        // byte handed waits, and here one does.
        UCSR0B = kUcsrbSending;
    } else if (at == (FSW_TX_END_LO | static_cast<uintptr_t>(g_tx_end_hi) << 8)) {
        FSW_TX_END_LO = static_cast<uint8_t>(end);
        g_tx_end_hi = static_cast<uint8_t>(end >> 8);
    } else if (g_tx_next[1] == 0) {
        g_tx_next[0] = static_cast<uint8_t>(at);
        g_tx_next[2] = static_cast<uint8_t>(end);
        g_tx_next[3] = static_cast<uint8_t>(end >> 8);
        g_tx_next[1] = static_cast<uint8_t>(at >> 8);
    } else if (at == (g_tx_next[2] | static_cast<uintptr_t>(g_tx_next[3]) << 8)) {
        g_tx_next[2] = static_cast<uint8_t>(end);
        g_tx_next[3] = static_cast<uint8_t>(end >> 8);
    }
    SREG = sreg;
}

const uint8_t* console_sending() {
    const uint8_t sreg = SREG;
    cli();
    const uintptr_t t = FSW_TX_TAIL_LO | static_cast<uintptr_t>(FSW_TX_TAIL_HI) << 8;
    SREG = sreg;
    return (t >> 8) != 0 ? reinterpret_cast<const uint8_t*>(t) : 0;
}

bool console_needs_poll() { return false; }

int16_t console_read() {
    const uint8_t t = g_rx_tail;
    if (t == g_rx_head) return -1;
    const uint8_t b = fsw_console_rx[t];
    g_rx_tail = static_cast<uint8_t>((t + 1u) & fsw_console_rx_mask);
    return b;
}

// The ring read in place (fsw_pal.h). The handler writes only at the head,
// into the bytes between it and the tail, so the bytes waiting are the
// reader's until it moves the tail past them.
int16_t console_peek(uint8_t i) {
    const uint8_t t = g_rx_tail, mask = fsw_console_rx_mask;
    if (i >= static_cast<uint8_t>((g_rx_head - t) & mask)) return -1;
    return fsw_console_rx[(t + i) & mask];
}

namespace {

// The ring turned so that the tail, `t`, is at its front (turn_bytes),
// interrupts off (the handler's head moves with it). Out of line: its
// registers are not saved on the reader's every path.
FSW_NOINLINE void turn(uint8_t t) {
    const uint8_t sreg = SREG;
    cli();
    turn_bytes(t);
    g_rx_head = static_cast<uint8_t>((g_rx_head - t) & fsw_console_rx_mask);
    g_rx_tail = 0;
    SREG = sreg;
}

}  // namespace

uint8_t* console_run(uint8_t n) {
    const uint8_t t = g_rx_tail;
    if (t + n <= fsw_console_rx_mask + 1) return fsw_console_rx + t;
    // They wrap round the ring's end. A ring that was emptied starts again
    // from its front (console_drop), so only bytes that came while others
    // waited (a ground that sends a command before the one before is
    // answered) get here.
    turn(t);
    return fsw_console_rx;
}

void console_drop(uint8_t n) {
    const uint8_t sreg = SREG;
    cli();
    uint8_t t = static_cast<uint8_t>((g_rx_tail + n) & fsw_console_rx_mask);
    if (t == g_rx_head) {  // empty: the next bytes go from the front
        t = 0;
        g_rx_head = 0;
    }
    g_rx_tail = t;
    SREG = sreg;
}

}  // namespace pal
}  // namespace fsw

#endif  // FSW_CONSOLE_ARDUINO_SERIAL

#endif  // FSW_PLATFORM_ARDUINO
