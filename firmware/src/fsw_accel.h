// Accelerometer drivers: Analog Devices ADXL345 (on the TWI or on the SPI)
// and InvenSense MPU-6050 (TWI), small state machines stepped once per
// executor cycle, as the barometers (fsw_sensor.h: the shared core, the
// health codes and the step; docs/sensors.md, "Bus and drivers").
//
// Both parts sample on their own at their output data rate. Once set up,
// each step reads the part's interrupt status and data registers in one
// burst: a new sample (the status's data-ready bit) is a reading, converted
// with fsw_parts.h; no new sample is no reading. The burst is the heartbeat
// too: a part that stops answering is seen at the next step.
//
// On the SPI (ADXL345 only) a transaction is a few bytes shifted within the
// step (mode 3, F_CPU / 4); an absent part reads 0x00 or 0xFF, so the ID
// read and, in every burst, DATA_FORMAT read back are the answer check.
#ifndef FSW_ACCEL_H
#define FSW_ACCEL_H

#include "fsw_pal.h"
#include "fsw_parts.h"
#include "fsw_sensor.h"
#include "fsw_types.h"

namespace fsw {

// What the accelerometers share besides the core: the last reading.
class AccelDriver : public SensorDriver {
public:
    // g (binary32) and raw counts (sign-extended) of the last reading.
    float x_g() const { return g_[0]; }
    float y_g() const { return g_[1]; }
    float z_g() const { return g_[2]; }
    int16_t counts(uint8_t axis) const { return raw_[axis < 3 ? axis : 2]; }

protected:
    AccelDriver() : g_(), raw_() {}
    // A new sample's counts: stuck check (all three unchanged), stored.
    void sample(const int16_t* xyz);
    float g_[3];
    int16_t raw_[3];
};

class Adxl345 : public AccelDriver {
public:
    // `where`: the 7-bit I2C address (0x53 or 0x1D) or, with `spi` 1, the
    // chip select's board pin. `range_code` 0..3: +-2..+-16 g, full
    // resolution; `rate_code`: BW_RATE's rate bits (0x0..0xF; 0xC = 400 Hz).
    explicit Adxl345(uint8_t where = 0x53, uint8_t spi = 0, uint8_t range_code = 3, uint8_t rate_code = 0xC,
                     uint8_t stuck_n = 0, uint8_t timeout_steps = 3);
    void step();
    uint8_t data_format() const { return fmt_; }
    // Output data rate period (3200 Hz / 2^(15 - rate)), us.
    uint32_t period_us() const;

private:
    template <class Driver> friend void sensor_step(Driver& d);
    void issue(uint32_t now);
    void done(uint8_t status, uint32_t now);
    // SPI: one register write or burst read, shifted now.
    void spi_xfer(uint8_t reg, const uint8_t* w, uint8_t nw, uint8_t* r, uint8_t nr);
    uint8_t cs_;             // SPI: the chip select's board pin (0: on the TWI)
    uint8_t fmt_;            // DATA_FORMAT: FULL_RES | range
    uint8_t rate_;           // BW_RATE
    uint8_t spi_ready_;      // SPI: dev_ described
    pal::SpiDevice dev_;
    uint8_t buf_[8];         // INT_SOURCE, DATA_FORMAT, DATAX0..DATAZ1; the ID read's 1
};

class Mpu6050 : public AccelDriver {
public:
    // `afs_sel` 0..3: +-2..+-16 g (ACCEL_CONFIG); `dlpf_cfg` 0..6 (CONFIG).
    // Clock: PLL with the X gyro's reference (PWR_MGMT_1 = 1).
    explicit Mpu6050(uint8_t addr7 = 0x68, uint8_t afs_sel = 3, uint8_t dlpf_cfg = 3, uint8_t stuck_n = 0,
                     uint8_t timeout_steps = 3);
    void step();
    float temp_c() const { return temp_c_; }
    int16_t temp_counts() const { return temp_raw_; }

private:
    template <class Driver> friend void sensor_step(Driver& d);
    void issue(uint32_t now);
    void done(uint8_t status, uint32_t now);
    uint8_t afs_, dlpf_;
    int16_t temp_raw_;
    float temp_c_;
    uint8_t buf_[9];         // INT_STATUS, ACCEL_XOUT_H..ACCEL_ZOUT_L, TEMP_OUT_H, TEMP_OUT_L
};

}  // namespace fsw

#endif  // FSW_ACCEL_H
