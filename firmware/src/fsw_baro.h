// Barometer drivers on the TWI (fsw_twi.h): Bosch BMP280 and TE MS5611,
// each a small state machine stepped once per executor cycle. A step never
// waits: it looks at the transaction it started, starts at most the next
// one, and takes the datasheets' conversion times across cycles (micros32).
// The data conversions are fsw_parts.h's. docs/sensors.md, "Bus and drivers".
//
// Both drivers share the one TWI: a driver whose transaction cannot start
// (the bus is another's) tries again at its next step. A transaction still
// running after `timeout_steps` further steps is abandoned (twi_abort) and
// counts as no answer, so the step period must exceed the longest
// transaction (a 24-byte read: 0.7 ms at 400 kHz).
#ifndef FSW_BARO_H
#define FSW_BARO_H

#include "fsw_parts.h"
#include "fsw_types.h"

namespace fsw {

enum BaroHealth : uint8_t {
    kBaroInit = 0,       // not yet through its first initialisation
    kBaroOk = 1,         // the last conversion gave a new reading
    kBaroNoAnswer = 2,   // a transaction failed (NACK, bus error, timeout); re-initialising
    kBaroBadId = 3,      // BMP280: chip ID not 0x58; re-initialising
    kBaroBadCalib = 4,   // calibration / PROM refused by fsw_parts' parser; re-initialising
    kBaroStuck = 5       // the raw counts unchanged for stuck_n conversions in a row
};

// Time before a driver that saw a fault initialises again (reset, ID, calibration).
static const uint32_t kBaroRetryUs = 20000UL;

// The part of a driver common to both: the transaction in flight and the
// health bookkeeping. Not used on its own.
struct BaroCore {
    uint8_t addr;
    uint8_t state;
    uint8_t health;         // BaroHealth
    uint8_t pending;        // a transaction of ours was started
    volatile uint8_t txn;   // its status (TwiStatus; kTwiBusy while it runs)
    uint8_t waited;         // steps it has been running
    uint8_t timeout_steps;
    uint8_t stuck_n;        // 0: no stuck detection
    uint8_t started;        // the first step has set due_us (micros32 may be anywhere then)
    uint8_t same;           // conversions in a row with the raw counts unchanged
    uint16_t faults;        // fault events (saturating)
    uint16_t readings;      // new readings (wraps)
    uint32_t due_us;        // micros32() when the wait in progress ends
    float pressure_pa;
    float temp_c;
};

// What the two drivers share: the health, the counters and the last
// reading, and the step that polls a transaction and starts the next
// (step_driver in fsw_baro.cpp).
class BaroDriver {
public:
    uint8_t health() const { return c_.health; }
    uint16_t faults() const { return c_.faults; }
    uint16_t readings() const { return c_.readings; }
    float pressure_pa() const { return c_.pressure_pa; }
    float temp_c() const { return c_.temp_c; }

protected:
    BaroCore c_;
};

class Bmp280 : public BaroDriver {
public:
    // `osrs_t`, `osrs_p`: the oversampling codes of ctrl_meas (1..5: x1..x16);
    // forced mode, one measurement per trigger, IIR filter off.
    explicit Bmp280(uint8_t addr7 = 0x76, uint8_t osrs_t = 1, uint8_t osrs_p = 1, uint8_t stuck_n = 0,
                    uint8_t timeout_steps = 3);
    // One step of the state machine (once per executor cycle; never waits).
    void step();

    // The last reading (valid once readings() > 0): pressure_pa() from the
    // datasheet's 64-bit formula (Q24.8 / 256), temp_c() from the 0.01 degC
    // integer / 100.
    uint32_t pressure_q24_8() const { return p_q8_; }
    int32_t temp_centi() const { return t_centi_; }
    int32_t adc_P() const { return adc_P_; }
    int32_t adc_T() const { return adc_T_; }
    const Bmp280Calib& calib() const { return cal_; }
    // Measurement time for the oversampling (datasheet max, 3.8.1), us.
    uint32_t measure_us() const;

private:
    template <class Driver> friend void step_driver(Driver& d);
    void issue(uint32_t now);
    void done(uint8_t status, uint32_t now);
    void fault(uint8_t health, uint32_t now);
    uint8_t ctrl_;           // ctrl_meas value with mode 01 (forced)
    Bmp280Calib cal_;
    int32_t adc_P_, adc_T_;
    int32_t t_centi_;
    uint32_t p_q8_;
    uint8_t buf_[kBmp280CalibLen];
};

class Ms5611 : public BaroDriver {
public:
    // `osr`: 0..4 for OSR 256..4096 (conversion 0.60 .. 9.04 ms, datasheet max).
    explicit Ms5611(uint8_t addr7 = 0x77, uint8_t osr = 4, uint8_t stuck_n = 0, uint8_t timeout_steps = 3);
    void step();

    // pressure_pa(): the datasheet's P in 0.01 mbar, which is 1 Pa;
    // temp_c(): TEMP / 100; second-order temperature compensation applied.
    int32_t pressure_int() const { return p_; }
    int32_t temp_centi() const { return t_centi_; }
    uint32_t d1() const { return d1_; }
    uint32_t d2() const { return d2_; }
    const Ms5611Calib& calib() const { return cal_; }
    uint32_t conversion_us() const;

private:
    template <class Driver> friend void step_driver(Driver& d);
    void issue(uint32_t now);
    void done(uint8_t status, uint32_t now);
    void fault(uint8_t health, uint32_t now);
    uint8_t osr_;
    uint8_t word_;           // PROM word being read (0..7)
    Ms5611Calib cal_;
    uint32_t d1_, d2_, last_d1_, last_d2_;
    int32_t t_centi_, p_;
    uint8_t buf_[16];        // the PROM's 16 bytes; an ADC read's 3
};

}  // namespace fsw

#endif  // FSW_BARO_H
