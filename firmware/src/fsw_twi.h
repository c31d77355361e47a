// Interrupt-driven TWI (I2C) master: one transaction on the bus at a time,
// started with twi_start() and carried on by the TWI interrupt, so nobody
// waits for the bus; a transaction started while another runs waits in a
// small queue and the interrupt starts it as soon as the bus is free. A transaction writes nw bytes to a 7-bit address, then (nr > 0) a
// repeated START reads nr bytes (ACK on every byte but the last). nw = 0 and
// nr > 0 is a plain read; nw > 0 and nr = 0 a plain write; both 0 an address
// probe. docs/sensors.md, "Bus and drivers".
//
// On an AVR: the TWI at 400 kHz (TWBR from F_CPU, prescaler 1), TWI_vect
// (so not together with the Wire library, which owns the same vector).
// On the host (native builds): a scripted responder installed with
// fsw::native::twi_set_responder() (psl_native.h) answers each transaction
// whole, in order with the ones queued behind it, on the first twi_busy()
// poll after its start; without one every address is NACKed.
#ifndef FSW_TWI_H
#define FSW_TWI_H

#include "fsw_types.h"

namespace fsw {

enum TwiStatus : uint8_t {
    kTwiOk = 0,         // every byte ACKed, the reads done, STOP sent
    kTwiBusy = 1,       // the transaction is still on the bus
    kTwiNackAddr = 2,   // SLA+W or SLA+R got no ACK (nobody at the address)
    kTwiNackData = 3,   // a written byte got no ACK
    kTwiBusError = 4,   // an illegal START/STOP, lost arbitration, or an unexpected status
    kTwiTimeout = 5,    // abandoned by twi_abort() (the caller's bound passed)
    kTwiIdle = 6        // no transaction since twi_begin()
};

// Bytes a transaction may write (copied at twi_start) and read.
static const uint8_t kTwiMaxWrite = 4;
static const uint8_t kTwiMaxRead = 32;
// Transactions that may wait behind the one on the bus.
static const uint8_t kTwiQueueLen = 4;

// Sets the TWI up as master at `hz` (400000 by default; AVR: TWBR =
// (F_CPU / hz - 16) / 2, prescaler 1) and enables its interrupt. A
// transaction on the bus or waiting is dropped, its status byte not written.
void twi_begin(uint32_t hz = 400000UL);

// Starts a transaction, or queues it behind the one on the bus (the
// interrupt starts it, a STOP then a START, when that one ends), and
// returns at once: false (nothing started) with kTwiQueueLen transactions
// already waiting, or with nw > kTwiMaxWrite or nr > kTwiMaxRead.
// The write bytes are copied; `r` (nr bytes) must stay valid until the
// transaction ends: the interrupt stores into it. `status`, if given, is the
// caller's own copy of this transaction's status: kTwiBusy now (queued or
// on the bus), its final status when it ends. Drivers sharing the bus use
// it, since twi_result() is the last transaction's, which may already be
// another driver's; it also names the transaction to twi_abort().
bool twi_start(uint8_t addr7, const uint8_t* w, uint8_t nw, uint8_t* r, uint8_t nr,
               volatile uint8_t* status = 0);

// Whether a transaction is on the bus or waiting (a STOP in progress included).
bool twi_busy();

// The status of the transaction on the bus, or of the last one to end
// (kTwiBusy while one runs).
uint8_t twi_result();

// Abandons the caller's transaction, the one whose status byte is
// `status`: still waiting, it leaves the queue (the bus is not touched);
// on the bus, the TWI is disabled and re-enabled, which releases SDA and
// SCL, and the next waiting transaction starts. Its status (and
// twi_result(), if it was on the bus) becomes kTwiTimeout. Another's
// transaction is never touched. `status` 0: the transaction on the bus,
// whoever's. The caller decides when (it counts its own cycles).
void twi_abort(volatile uint8_t* status = 0);

// Transactions ended with each failure status since twi_begin (saturating).
struct TwiCounters {
    uint16_t transactions, nack_addr, nack_data, bus_error, timeout;
};
TwiCounters twi_counters();

}  // namespace fsw

#endif  // FSW_TWI_H
