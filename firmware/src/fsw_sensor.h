// The part every digital sensor driver shares (fsw_baro.h, fsw_accel.h):
// the health codes, the core a driver's state machine keeps (the
// transaction in flight, the steps it has waited, the timeout, the stuck
// count, the fault and reading counters), the base class with the
// accessors, and the step every driver takes once per executor cycle.
// docs/sensors.md, "Bus and drivers".
//
// A step never waits: it looks at the transaction it started (fsw_twi.h's
// own status byte), handles its outcome, then starts at most one more: the
// next one the part needs when its wait (a reset, a conversion) is over,
// else, while it waits out a conversion, a heartbeat (an address probe, a
// zero-length write, or a status read), so a part that stops answering is
// seen within one step. A transaction still running after `timeout_steps`
// further steps is abandoned (twi_abort of our own) and counts as no answer.
#ifndef FSW_SENSOR_H
#define FSW_SENSOR_H

#include "fsw_pal.h"
#include "fsw_twi.h"
#include "fsw_types.h"

namespace fsw {

enum SensorHealth : uint8_t {
    kSensorInit = 0,       // not yet through its first initialisation
    kSensorOk = 1,         // the last conversion gave a new reading
    kSensorNoAnswer = 2,   // a transaction failed (NACK, bus error, timeout; SPI: the ID or a
                           // check byte read wrong); re-initialising
    kSensorBadId = 3,      // the chip ID is not the part's; re-initialising
    kSensorBadCalib = 4,   // calibration / PROM refused by fsw_parts' parser; re-initialising
    kSensorStuck = 5       // the raw counts unchanged for stuck_n readings in a row
};

// Time before a driver that saw a fault initialises again (reset, ID, calibration).
static const uint32_t kSensorRetryUs = 20000UL;

// What a driver's state machine keeps besides its part's own bytes.
struct SensorCore {
    uint8_t addr;           // 7-bit I2C address (0 on SPI)
    uint8_t state;          // the driver's; 0 starts the part afresh
    uint8_t health;         // SensorHealth
    uint8_t pending;        // a transaction of ours was started ...
    uint8_t beat;           // ... and it is a heartbeat
    volatile uint8_t txn;   // its status (TwiStatus; kTwiBusy while it waits or runs)
    uint8_t waited;         // steps it has been running
    uint8_t timeout_steps;
    uint8_t stuck_n;        // 0: no stuck detection
    uint8_t started;        // the first step has set due_us (micros32 may be anywhere then)
    uint8_t same;           // readings in a row with the raw counts unchanged
    uint16_t faults;        // fault events (saturating)
    uint16_t readings;      // new readings (wraps)
    uint32_t due_us;        // micros32() when the wait in progress ends
};

// Starts the buses a generated application's sensors use: the TWI at
// 400 kHz (i2c != 0), the SPI bus as master (spi != 0; each SPI driver
// describes its own device at its first step).
void sensors_begin(uint8_t i2c, uint8_t spi);

// Helpers of the drivers' state machines (fsw_sensor.cpp).
void sensor_init(SensorCore& c, uint8_t addr, uint8_t stuck_n, uint8_t timeout_steps);
// Whether our transaction ended (its status in `st`); abandons it once it
// has run for more than timeout_steps steps.
bool sensor_poll(SensorCore& c, uint8_t& st);
// Starts (or queues) a TWI transaction of ours: false when it could not
// (the queue is full): the driver tries again at its next step.
bool sensor_start(SensorCore& c, const uint8_t* w, uint8_t nw, uint8_t* r, uint8_t nr);
// The heartbeat's address probe: address + STOP (a zero-length write).
bool sensor_probe(SensorCore& c);
// A fault: health set, counted, the part started afresh after kSensorRetryUs.
void sensor_fault(SensorCore& c, uint8_t health, uint32_t now);
// A new reading, its raw counts `unchanged` or not: Ok, or Stuck (one
// fault) after stuck_n unchanged readings in a row.
void sensor_reading(SensorCore& c, bool unchanged);
inline bool sensor_due(uint32_t now, uint32_t t) { return static_cast<int32_t>(now - t) >= 0; }

// What every driver offers: its health, fault events and readings.
// Drivers are static objects stepped once per executor cycle (no virtuals).
class SensorDriver {
public:
    uint8_t health() const { return c_.health; }
    uint16_t faults() const { return c_.faults; }
    uint16_t readings() const { return c_.readings; }

protected:
    SensorDriver() : c_() {}
    // The defaults a driver may hide: whether it waits out a conversion
    // now (then a heartbeat probes the part), the heartbeat, and its outcome.
    bool waiting() const { return false; }
    bool heartbeat(uint32_t now) {
        (void)now;
        return sensor_probe(c_);
    }
    void beat_done(uint8_t status, uint32_t now) {
        if (status != kTwiOk) sensor_fault(c_, kSensorNoAnswer, now);
    }
    SensorCore c_;
};

// One step of a driver: the transaction in flight polled and its outcome
// handled (d.done, or d.beat_done for a heartbeat), then the next one
// started when its wait is over (d.issue), else a heartbeat while the
// driver waits out a conversion (d.waiting, d.heartbeat).
template <class Driver>
void sensor_step(Driver& d) {
    SensorCore& c = d.c_;
    const uint32_t now = pal::micros32();
    if (!c.started) {
        c.started = 1;
        c.due_us = now;
    }
    if (c.pending) {
        uint8_t st;
        if (!sensor_poll(c, st)) return;
        if (c.beat) {
            c.beat = 0;
            d.beat_done(st, now);
        } else {
            d.done(st, now);
        }
    }
    if (c.pending) return;
    if (sensor_due(now, c.due_us)) {
        d.issue(now);
    } else if (d.waiting() && d.heartbeat(now)) {
        c.beat = 1;
    }
}

}  // namespace fsw

#endif  // FSW_SENSOR_H
