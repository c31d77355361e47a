// Interrupt-driven TWI master (fsw_twi.h). AVR: the TWI's status codes
// (ATmega328P datasheet 22.7, master transmitter / receiver tables) walked
// by TWI_vect. Host: a scripted responder (psl_native.h).
#include "fsw_twi.h"

#include "fsw_pal.h"

#if FSW_PLATFORM_NATIVE
#include "psl_native.h"
#endif

namespace fsw {

namespace {

struct TwiState {
    uint8_t addr;                 // 7-bit address
    uint8_t w[kTwiMaxWrite];
    uint8_t nw, nr;
    uint8_t* r;
    volatile uint8_t* owner;      // the caller's status byte, or null
    volatile uint8_t wi, ri;
    volatile uint8_t result;      // TwiStatus
    volatile bool busy;
};
TwiState g_twi = {0, {0, 0, 0, 0}, 0, 0, 0, 0, 0, 0, kTwiIdle, false};
volatile TwiCounters g_twi_count = {0, 0, 0, 0, 0};

#if (defined(__AVR__) && defined(TWCR)) || FSW_PLATFORM_NATIVE  // (the stub below queues nothing)
// Transactions waiting for the bus, oldest first (a ring).
struct TwiQueued {
    uint8_t addr;
    uint8_t w[kTwiMaxWrite];
    uint8_t nw, nr;
    uint8_t* r;
    volatile uint8_t* owner;
};
TwiQueued g_q[kTwiQueueLen];
volatile uint8_t g_q_head, g_q_n;
#endif

inline void bump(volatile uint16_t& c) {
    if (c != 0xFFFFu) c = static_cast<uint16_t>(c + 1u);
}

// Ends the transaction with `st` (called with interrupts off or from the ISR).
void finish(uint8_t st) {
    g_twi.result = st;
    if (g_twi.owner != 0) *g_twi.owner = st;
    g_twi.busy = false;
    switch (st) {
        case kTwiNackAddr: bump(g_twi_count.nack_addr); break;
        case kTwiNackData: bump(g_twi_count.nack_data); break;
        case kTwiBusError: bump(g_twi_count.bus_error); break;
        case kTwiTimeout: bump(g_twi_count.timeout); break;
        default: break;
    }
}

// A new transaction's description, and its owner told it runs (both
// platforms' twi_start, once they know the bus is theirs).
void load(uint8_t addr7, const uint8_t* w, uint8_t nw, uint8_t* r, uint8_t nr, volatile uint8_t* status) {
    for (uint8_t i = 0; i < nw; ++i) g_twi.w[i] = w[i];
    g_twi.addr = addr7;
    g_twi.wi = 0;
    g_twi.ri = 0;
    g_twi.nw = nw;
    g_twi.nr = nr;
    g_twi.r = r;
    g_twi.owner = status;
    if (status != 0) *status = kTwiBusy;
    g_twi.result = kTwiBusy;
    g_twi.busy = true;
}

#if (defined(__AVR__) && defined(TWCR)) || FSW_PLATFORM_NATIVE
void enqueue(uint8_t addr7, const uint8_t* w, uint8_t nw, uint8_t* r, uint8_t nr, volatile uint8_t* status) {
    uint8_t i = static_cast<uint8_t>(g_q_head + g_q_n);
    if (i >= kTwiQueueLen) i = static_cast<uint8_t>(i - kTwiQueueLen);
    TwiQueued& q = g_q[i];
    q.addr = addr7;
    for (uint8_t k = 0; k < nw; ++k) q.w[k] = w[k];
    q.nw = nw;
    q.nr = nr;
    q.r = r;
    q.owner = status;
    if (status != 0) *status = kTwiBusy;
    g_q_n = static_cast<uint8_t>(g_q_n + 1u);
}

// The oldest waiting transaction onto the bus's description (the caller
// knows one waits and the bus is free).
void dequeue() {
    const TwiQueued& q = g_q[g_q_head];
    load(q.addr, q.w, q.nw, q.r, q.nr, q.owner);
    g_q_head = static_cast<uint8_t>(g_q_head + 1u == kTwiQueueLen ? 0u : g_q_head + 1u);
    g_q_n = static_cast<uint8_t>(g_q_n - 1u);
}

// Removes the waiting transaction whose status byte is `status` (told
// kTwiTimeout); false when none waits.
bool unqueue(volatile uint8_t* status) {
    for (uint8_t k = 0; k < g_q_n; ++k) {
        uint8_t i = static_cast<uint8_t>(g_q_head + k);
        if (i >= kTwiQueueLen) i = static_cast<uint8_t>(i - kTwiQueueLen);
        if (g_q[i].owner != status) continue;
        for (uint8_t m = static_cast<uint8_t>(k + 1u); m < g_q_n; ++m) {  // close the gap
            uint8_t to = static_cast<uint8_t>(g_q_head + m - 1u), from = static_cast<uint8_t>(g_q_head + m);
            if (to >= kTwiQueueLen) to = static_cast<uint8_t>(to - kTwiQueueLen);
            if (from >= kTwiQueueLen) from = static_cast<uint8_t>(from - kTwiQueueLen);
            g_q[to] = g_q[from];
        }
        g_q_n = static_cast<uint8_t>(g_q_n - 1u);
        *status = kTwiTimeout;
        bump(g_twi_count.timeout);
        return true;
    }
    return false;
}
#endif

}  // namespace

TwiCounters twi_counters() {
    CriticalSection cs;
    TwiCounters c;
    c.transactions = g_twi_count.transactions;
    c.nack_addr = g_twi_count.nack_addr;
    c.nack_data = g_twi_count.nack_data;
    c.bus_error = g_twi_count.bus_error;
    c.timeout = g_twi_count.timeout;
    return c;
}

uint8_t twi_result() { return g_twi.result; }

#if defined(__AVR__) && defined(TWCR)

namespace {
const uint8_t kCtlOn = static_cast<uint8_t>(_BV(TWEN) | _BV(TWIE));
inline void twi_stop() {
    TWCR = static_cast<uint8_t>(_BV(TWINT) | _BV(TWEN) | _BV(TWSTO));  // interrupt off
}

// The transaction on the bus ended with `st` (from the ISR): the next
// waiting one follows at once, a STOP then a START in one TWCR write
// (datasheet 22.7: TWSTA and TWSTO both set), else a STOP alone.
void end(uint8_t st) {
    finish(st);
    if (g_q_n != 0) {
        dequeue();
        TWCR = static_cast<uint8_t>(_BV(TWINT) | _BV(TWSTO) | _BV(TWSTA) | kCtlOn);
    } else {
        twi_stop();
    }
}

// A STOP written by the ISR takes a bit time (2.5 us at 400 kHz) to go
// out; a START written meanwhile would be lost on a real part.
inline void wait_stop() {
    for (uint8_t n = 0; n < 255u && (TWCR & _BV(TWSTO)) != 0; ++n) {
    }
}
}  // namespace

void twi_begin(uint32_t hz) {
    if (hz == 0) hz = 400000UL;
    uint32_t br = (static_cast<uint32_t>(F_CPU) / hz);
    br = br > 16u ? (br - 16u) / 2u : 0u;
    if (br > 255u) br = 255u;
    CriticalSection cs;
    // The MCU's weak pull-ups on SDA and SCL (as the Wire library sets);
    // a 400 kHz bus needs the external ones sensor boards carry.
#if defined(__AVR_ATmega328P__) || defined(__AVR_ATmega328__) || defined(__AVR_ATmega168__)
    PORTC = static_cast<uint8_t>(PORTC | _BV(PC4) | _BV(PC5));
#elif defined(__AVR_ATmega2560__) || defined(__AVR_ATmega1280__)
    PORTD = static_cast<uint8_t>(PORTD | _BV(PD0) | _BV(PD1));
#endif
    TWSR = 0;  // prescaler 1
    TWBR = static_cast<uint8_t>(br);
    TWCR = 0;  // a transaction on the bus is dropped (SDA and SCL let go)
    TWCR = _BV(TWEN);
    g_twi.busy = false;
    g_q_n = 0;
}

bool twi_busy() {
    // A STOP in progress (TWSTO still set) counts as busy.
    const bool b = g_twi.busy || g_q_n != 0 || (TWCR & _BV(TWSTO)) != 0;
    __asm__ __volatile__("" ::: "memory");
    return b;
}

bool twi_start(uint8_t addr7, const uint8_t* w, uint8_t nw, uint8_t* r, uint8_t nr, volatile uint8_t* status) {
    if (nw > kTwiMaxWrite || nr > kTwiMaxRead) return false;
    CriticalSection cs;
    if (g_twi.busy) {
        if (g_q_n >= kTwiQueueLen) return false;
        enqueue(addr7, w, nw, r, nr, status);  // the ISR starts it when the bus is free
    } else {
        wait_stop();
        load(addr7, w, nw, r, nr, status);
        TWCR = static_cast<uint8_t>(_BV(TWINT) | _BV(TWSTA) | kCtlOn);
    }
    bump(g_twi_count.transactions);
    return true;
}

void twi_abort(volatile uint8_t* status) {
    CriticalSection cs;
    if (status != 0 && unqueue(status)) return;  // still waiting: the bus is not touched
    if (!g_twi.busy || (status != 0 && g_twi.owner != status)) return;
    TWCR = 0;         // the TWI lets go of SDA and SCL ...
    TWCR = _BV(TWEN); // ... and is ready again
    finish(kTwiTimeout);
    if (g_q_n != 0) {  // the next waiting one goes on
        dequeue();
        TWCR = static_cast<uint8_t>(_BV(TWINT) | _BV(TWSTA) | kCtlOn);
    }
}

ISR(TWI_vect) {
    const uint8_t st = static_cast<uint8_t>(TWSR & 0xF8u);
    switch (st) {
        case 0x08:  // START
        case 0x10:  // repeated START
            if (g_twi.wi < g_twi.nw || g_twi.nr == 0) {
                TWDR = static_cast<uint8_t>(g_twi.addr << 1);
            } else {
                TWDR = static_cast<uint8_t>(g_twi.addr << 1 | 1u);
            }
            TWCR = static_cast<uint8_t>(_BV(TWINT) | kCtlOn);
            break;
        case 0x18:  // SLA+W ACKed
        case 0x28:  // data byte ACKed
            if (g_twi.wi < g_twi.nw) {
                TWDR = g_twi.w[g_twi.wi];
                g_twi.wi = static_cast<uint8_t>(g_twi.wi + 1u);
                TWCR = static_cast<uint8_t>(_BV(TWINT) | kCtlOn);
            } else if (g_twi.nr != 0) {
                TWCR = static_cast<uint8_t>(_BV(TWINT) | _BV(TWSTA) | kCtlOn);  // repeated START
            } else {
                end(kTwiOk);
            }
            break;
        case 0x20:  // SLA+W NACKed
        case 0x48:  // SLA+R NACKed
            end(kTwiNackAddr);
            break;
        case 0x30:  // data byte NACKed
            end(kTwiNackData);
            break;
        case 0x40:  // SLA+R ACKed: ACK the bytes before the last
            TWCR = static_cast<uint8_t>(_BV(TWINT) | kCtlOn | (g_twi.nr > 1 ? _BV(TWEA) : 0));
            break;
        case 0x50:  // byte received, ACK returned
        case 0x58: {  // byte received, NACK returned (the last)
            const uint8_t i = g_twi.ri;
            if (i < g_twi.nr) g_twi.r[i] = TWDR;
            g_twi.ri = static_cast<uint8_t>(i + 1u);
            if (st == 0x58 || g_twi.ri >= g_twi.nr) {
                end(kTwiOk);
            } else {
                const bool more = static_cast<uint8_t>(g_twi.ri + 1u) < g_twi.nr;
                TWCR = static_cast<uint8_t>(_BV(TWINT) | kCtlOn | (more ? _BV(TWEA) : 0));
            }
            break;
        }
        case 0x38:  // arbitration lost: the bus is another master's; START again when it is free
            finish(kTwiBusError);
            if (g_q_n != 0) {
                dequeue();
                TWCR = static_cast<uint8_t>(_BV(TWINT) | _BV(TWSTA) | kCtlOn);
            } else {
                TWCR = static_cast<uint8_t>(_BV(TWINT) | _BV(TWEN));
            }
            break;
        default:  // 0x00 bus error, or a status a master never expects
            end(kTwiBusError);
            break;
    }
}

#elif FSW_PLATFORM_NATIVE  // host: the scripted responder

void twi_begin(uint32_t hz) {
    (void)hz;
    g_twi.busy = false;
    g_q_n = 0;
}

bool twi_busy() {
    // Every transaction started (or waiting) happens whole, in order, at
    // the first poll after its start.
    while (g_twi.busy) {
        uint8_t st = kTwiNackAddr;
        native::TwiResponder resp = native::twi_responder();
        if (resp != 0) st = resp(g_twi.addr, g_twi.w, g_twi.nw, g_twi.r, g_twi.nr);
        finish(st == kTwiBusy ? static_cast<uint8_t>(kTwiBusError) : st);
        if (g_q_n != 0) dequeue();
    }
    return false;
}

bool twi_start(uint8_t addr7, const uint8_t* w, uint8_t nw, uint8_t* r, uint8_t nr, volatile uint8_t* status) {
    if (nw > kTwiMaxWrite || nr > kTwiMaxRead) return false;
    if (g_twi.busy) {
        if (g_q_n >= kTwiQueueLen) return false;
        enqueue(addr7, w, nw, r, nr, status);
    } else {
        load(addr7, w, nw, r, nr, status);
    }
    bump(g_twi_count.transactions);
    return true;
}

void twi_abort(volatile uint8_t* status) {
    if (status != 0 && unqueue(status)) return;
    if (!g_twi.busy || (status != 0 && g_twi.owner != status)) return;
    finish(kTwiTimeout);
    if (g_q_n != 0) dequeue();
}

#else  // another MCU: no TWI driver yet; every transaction ends unanswered

void twi_begin(uint32_t hz) { (void)hz; }
bool twi_busy() { return false; }
bool twi_start(uint8_t addr7, const uint8_t* w, uint8_t nw, uint8_t* r, uint8_t nr, volatile uint8_t* status) {
    (void)addr7; (void)w; (void)r;
    if (nw > kTwiMaxWrite || nr > kTwiMaxRead) return false;
    g_twi.owner = status;
    bump(g_twi_count.transactions);
    finish(kTwiNackAddr);
    return true;
}
void twi_abort(volatile uint8_t* status) { (void)status; }

#endif

}  // namespace fsw
