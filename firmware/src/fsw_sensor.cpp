// The drivers' shared state machine helpers (fsw_sensor.h).
#include "fsw_sensor.h"

namespace fsw {

void sensors_begin(uint8_t i2c, uint8_t spi) {
    if (i2c != 0) twi_begin(400000UL);
    if (spi != 0) pal::spi_bus_begin();
}

void sensor_init(SensorCore& c, uint8_t addr, uint8_t stuck_n, uint8_t timeout_steps) {
    memset(&c, 0, sizeof c);  // state 0, kSensorInit, nothing pending, counters zero
    c.addr = addr;
    c.txn = kTwiIdle;
    c.timeout_steps = timeout_steps == 0 ? 1 : timeout_steps;
    c.stuck_n = stuck_n;
}

// Our own status byte, not twi_result(): another driver's transaction may
// have started and ended since ours did.
bool sensor_poll(SensorCore& c, uint8_t& st) {
    (void)twi_busy();  // the host's bus runs the transactions here; on an AVR a barrier
    st = c.txn;
    if (st == kTwiBusy) {
        c.waited = static_cast<uint8_t>(c.waited + 1u);
        if (c.waited <= c.timeout_steps) return false;
        twi_abort(&c.txn);  // ours only: still queued, or on the bus
        st = kTwiTimeout;
    }
    c.pending = 0;
    return true;
}

bool sensor_start(SensorCore& c, const uint8_t* w, uint8_t nw, uint8_t* r, uint8_t nr) {
    if (!twi_start(c.addr, w, nw, r, nr, &c.txn)) return false;
    c.pending = 1;
    c.waited = 0;
    return true;
}

bool sensor_probe(SensorCore& c) { return c.addr != 0 && sensor_start(c, 0, 0, 0, 0); }

void sensor_fault(SensorCore& c, uint8_t health, uint32_t now) {
    c.health = health;
    if (c.faults != 0xFFFFu) c.faults = static_cast<uint16_t>(c.faults + 1u);
    c.state = 0;  // every driver: state 0 starts the part afresh
    c.same = 0;
    c.due_us = now + kSensorRetryUs;
}

void sensor_reading(SensorCore& c, bool unchanged) {
    if (unchanged && c.readings != 0) {
        if (c.same != 0xFFu) c.same = static_cast<uint8_t>(c.same + 1u);
    } else {
        c.same = 0;
    }
    if (c.stuck_n != 0 && c.same >= c.stuck_n) {
        if (c.health != kSensorStuck && c.faults != 0xFFFFu) c.faults = static_cast<uint16_t>(c.faults + 1u);
        c.health = kSensorStuck;
    } else {
        c.health = kSensorOk;
    }
    c.readings = static_cast<uint16_t>(c.readings + 1u);
}

}  // namespace fsw
