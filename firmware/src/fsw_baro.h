// Barometer drivers on the TWI (fsw_twi.h): Bosch BMP280 and TE MS5611,
// each a small state machine stepped once per executor cycle
// (fsw_sensor.h: the shared core, the health codes and the step). A step
// never waits: it looks at the transaction it started, starts at most the
// next one, and takes the datasheets' conversion times across cycles
// (micros32). The data conversions are fsw_parts.h's. docs/sensors.md,
// "Bus and drivers".
//
// While a conversion runs the BMP280 driver reads the part's status
// register each step (0xF3, `measuring`) and reads the data as soon as the
// measurement is over; the MS5611 driver probes its address. Either way a
// part that stops answering is seen at the next step.
#ifndef FSW_BARO_H
#define FSW_BARO_H

#include "fsw_parts.h"
#include "fsw_sensor.h"
#include "fsw_types.h"

namespace fsw {

// What the two barometers share besides the core: the last reading.
class BaroDriver : public SensorDriver {
public:
    float pressure_pa() const { return pressure_pa_; }
    float temp_c() const { return temp_c_; }

protected:
    BaroDriver() : pressure_pa_(0.0f), temp_c_(0.0f) {}
    float pressure_pa_;
    float temp_c_;
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
    template <class Driver> friend void sensor_step(Driver& d);
    void issue(uint32_t now);
    void done(uint8_t status, uint32_t now);
    // While a measurement runs: the status register read, `measuring` seen.
    bool waiting() const;
    bool heartbeat(uint32_t now);
    void beat_done(uint8_t status, uint32_t now);
    uint8_t ctrl_;
    uint8_t status_;         // the last status register read (0xF3)           // ctrl_meas value with mode 01 (forced)
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
    template <class Driver> friend void sensor_step(Driver& d);
    void issue(uint32_t now);
    void done(uint8_t status, uint32_t now);
    bool waiting() const;    // a conversion runs: the heartbeat probes the address
    uint8_t osr_;
    uint8_t word_;           // PROM word being read (0..7)
    Ms5611Calib cal_;
    uint32_t d1_, d2_, last_d1_, last_d2_;
    int32_t t_centi_, p_;
    uint8_t buf_[16];        // the PROM's 16 bytes; an ADC read's 3
};

}  // namespace fsw

#endif  // FSW_BARO_H
