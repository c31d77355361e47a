// ADXL345 and MPU-6050 drivers (fsw_accel.h): state machines over fsw_twi
// (and the pal SPI for the ADXL345 on SPI).
#include "fsw_accel.h"

namespace fsw {

void AccelDriver::sample(const int16_t* xyz) {
    sensor_reading(c_, xyz[0] == raw_[0] && xyz[1] == raw_[1] && xyz[2] == raw_[2]);
    for (uint8_t i = 0; i < 3; ++i) raw_[i] = xyz[i];
}

// ---- ADXL345 -----------------------------------------------------------------

namespace {
enum : uint8_t { kAStart = 0, kAId, kAStandby, kAFormat, kARate, kAMeasure, kARead };
const uint8_t kAdxlRegBwRate = 0x2C;
const uint8_t kAdxlRegPowerCtl = 0x2D;
const uint8_t kAdxlMeasure = 0x08;
const uint8_t kAdxlRegIntSource = 0x30;  // INT_SOURCE, DATA_FORMAT, DATAX0..DATAZ1: a burst of 8
const uint8_t kAdxlDataReady = 0x80;
const uint8_t kAdxlSpiRead = 0x80, kAdxlSpiMulti = 0x40;
const uint32_t kAdxlSpiHz = 5000000UL;  // datasheet: SCLK at most 5 MHz; CPOL = CPHA = 1
}  // namespace

Adxl345::Adxl345(uint8_t where, uint8_t spi, uint8_t range_code, uint8_t rate_code, uint8_t stuck_n,
                 uint8_t timeout_steps)
    : cs_(spi ? where : 0),
      fmt_(static_cast<uint8_t>(kAdxl345FullRes | (range_code & kAdxl345RangeMask))),
      rate_(static_cast<uint8_t>(rate_code & 0x0Fu)), spi_ready_(0), dev_(), buf_() {
    sensor_init(c_, spi ? 0 : where, stuck_n, timeout_steps);
}

uint32_t Adxl345::period_us() const { return static_cast<uint32_t>((625UL << (15u - rate_)) / 2u); }  // 312.5 us x 2^(15 - rate)

void Adxl345::step() { sensor_step(*this); }

void Adxl345::spi_xfer(uint8_t reg, const uint8_t* w, uint8_t nw, uint8_t* r, uint8_t nr) {
    pal::spi_select(dev_, true);
    (void)pal::spi_transfer(static_cast<uint8_t>(reg | (nr != 0 ? kAdxlSpiRead : 0u) |
                                                 (nr > 1 || nw > 1 ? kAdxlSpiMulti : 0u)));
    for (uint8_t i = 0; i < nw; ++i) (void)pal::spi_transfer(w[i]);
    for (uint8_t i = 0; i < nr; ++i) r[i] = pal::spi_transfer(0x00);
    pal::spi_select(dev_, false);
}

void Adxl345::issue(uint32_t now) {
    uint8_t reg, val = 0, nr = 0;
    switch (c_.state) {
        case kAStart:  // nothing to say to the part: its registers are set below
            if (cs_ != 0 && !spi_ready_) {
                pal::spi_bus_begin();
                pal::spi_device(dev_, cs_, 3, kAdxlSpiHz);
                spi_ready_ = 1;
            }
            c_.state = kAId;
            // fall through
        case kAId: reg = kAdxl345RegDevId; nr = 1; break;
        case kAStandby: reg = kAdxlRegPowerCtl; val = 0; break;
        case kAFormat: reg = kAdxl345RegDataFormat; val = fmt_; break;
        case kARate: reg = kAdxlRegBwRate; val = rate_; break;
        case kAMeasure: reg = kAdxlRegPowerCtl; val = kAdxlMeasure; break;
        default: reg = kAdxlRegIntSource; nr = 8; break;
    }
    if (cs_ != 0) {
        spi_xfer(reg, &val, nr == 0 ? 1 : 0, buf_, nr);
        done(kTwiOk, now);
        return;
    }
    const uint8_t w[2] = {reg, val};
    (void)sensor_start(c_, w, nr == 0 ? 2 : 1, buf_, nr);
}

void Adxl345::done(uint8_t status, uint32_t now) {
    if (status != kTwiOk) {
        sensor_fault(c_, kSensorNoAnswer, now);
        return;
    }
    c_.due_us = now;  // the next transaction at the next step
    switch (c_.state) {
        case kAId:
            if (buf_[0] != kAdxl345DevId) {
                // On the SPI nobody drives MISO: 0xFF (pull-up) or 0x00 is no part.
                const bool none = cs_ != 0 && (buf_[0] == 0x00 || buf_[0] == 0xFF);
                sensor_fault(c_, none ? kSensorNoAnswer : kSensorBadId, now);
                break;
            }
            c_.state = kAStandby;
            break;
        case kAStandby: c_.state = kAFormat; break;
        case kAFormat: c_.state = kARate; break;
        case kARate: c_.state = kAMeasure; break;
        case kAMeasure: c_.state = kARead; break;
        default: {
            // DATA_FORMAT read back: another value is a part that lost its
            // settings (a reset) or, on the SPI, nobody answering.
            if (buf_[1] != fmt_) {
                sensor_fault(c_, kSensorNoAnswer, now);
                break;
            }
            if (!(buf_[0] & kAdxlDataReady)) break;  // no new sample since the last read
            int16_t xyz[3];
            adxl345_counts(buf_ + 2, fmt_, xyz);
            sample(xyz);
            for (uint8_t i = 0; i < 3; ++i) g_[i] = adxl345_g(xyz[i], fmt_);
            break;
        }
    }
}

// ---- MPU-6050 ----------------------------------------------------------------

namespace {
enum : uint8_t { kPReset = 0, kPId, kPWake, kPConfig, kPAccel, kPInt, kPRead };
const uint8_t kMpuRegConfig = 0x1A;
const uint8_t kMpuRegIntEnable = 0x38;
const uint8_t kMpuRegIntStatus = 0x3A;  // INT_STATUS, ACCEL_*OUT_H/L, TEMP_OUT_H/L: a burst of 9
const uint8_t kMpuRegPwrMgmt1 = 0x6B;
const uint8_t kMpuDeviceReset = 0x80;
const uint8_t kMpuClockPllX = 0x01;      // SLEEP clear, CLKSEL 1
const uint8_t kMpuDataRdy = 0x01;
const uint32_t kMpuResetUs = 100000UL;   // register map 4.28: 100 ms after DEVICE_RESET
}  // namespace

Mpu6050::Mpu6050(uint8_t addr7, uint8_t afs_sel, uint8_t dlpf_cfg, uint8_t stuck_n, uint8_t timeout_steps)
    : afs_(static_cast<uint8_t>(afs_sel & 3u)), dlpf_(static_cast<uint8_t>(dlpf_cfg > 6 ? 6 : dlpf_cfg)),
      temp_raw_(0), temp_c_(0.0f), buf_() {
    sensor_init(c_, addr7, stuck_n, timeout_steps);
}

void Mpu6050::step() { sensor_step(*this); }

void Mpu6050::issue(uint32_t now) {
    (void)now;
    uint8_t w[2];
    switch (c_.state) {
        case kPReset: w[0] = kMpuRegPwrMgmt1; w[1] = kMpuDeviceReset; (void)sensor_start(c_, w, 2, 0, 0); break;
        case kPId: w[0] = kMpu6050RegWhoAmI; (void)sensor_start(c_, w, 1, buf_, 1); break;
        case kPWake: w[0] = kMpuRegPwrMgmt1; w[1] = kMpuClockPllX; (void)sensor_start(c_, w, 2, 0, 0); break;
        case kPConfig: w[0] = kMpuRegConfig; w[1] = dlpf_; (void)sensor_start(c_, w, 2, 0, 0); break;
        case kPAccel:
            w[0] = kMpu6050RegAccelConfig;
            w[1] = static_cast<uint8_t>(afs_ << 3);
            (void)sensor_start(c_, w, 2, 0, 0);
            break;
        case kPInt: w[0] = kMpuRegIntEnable; w[1] = kMpuDataRdy; (void)sensor_start(c_, w, 2, 0, 0); break;
        default: w[0] = kMpuRegIntStatus; (void)sensor_start(c_, w, 1, buf_, 9); break;
    }
}

void Mpu6050::done(uint8_t status, uint32_t now) {
    if (status != kTwiOk) {
        sensor_fault(c_, kSensorNoAnswer, now);
        return;
    }
    c_.due_us = now;
    switch (c_.state) {
        case kPReset:
            c_.state = kPId;
            c_.due_us = now + kMpuResetUs;
            break;
        case kPId:
            // WHO_AM_I is 0x68 at either address (AD0 is not in it).
            if (buf_[0] != kMpu6050WhoAmI) { sensor_fault(c_, kSensorBadId, now); break; }
            c_.state = kPWake;
            break;
        case kPWake: c_.state = kPConfig; break;
        case kPConfig: c_.state = kPAccel; break;
        case kPAccel: c_.state = kPInt; break;
        case kPInt: c_.state = kPRead; break;
        default: {
            if (!(buf_[0] & kMpuDataRdy)) break;  // no new sample since the last read
            int16_t xyz[3];
            mpu6050_accel_counts(buf_ + 1, xyz);
            sample(xyz);
            for (uint8_t i = 0; i < 3; ++i) g_[i] = mpu6050_accel_g(xyz[i], afs_);
            temp_raw_ = mpu6050_be16(buf_ + 7);
            temp_c_ = mpu6050_temp_c(temp_raw_);
            break;
        }
    }
}

}  // namespace fsw
