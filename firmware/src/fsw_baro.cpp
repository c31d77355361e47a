// BMP280 and MS5611 drivers (fsw_baro.h): state machines over fsw_twi.
#include "fsw_baro.h"

#include "fsw_convert.h"

#include "fsw_pal.h"
#include "fsw_twi.h"

namespace fsw {

// ---- BMP280 ------------------------------------------------------------------

namespace {
enum : uint8_t { kBReset = 0, kBId, kBCal, kBCfg, kBTrig, kBRead };
const uint8_t kBmp280RegReset = 0xE0;
const uint8_t kBmp280ResetWord = 0xB6;
const uint8_t kBmp280RegCtrlMeas = 0xF4;
const uint8_t kBmp280RegConfig = 0xF5;
const uint8_t kBmp280RegStatus = 0xF3;
const uint8_t kBmp280Measuring = 0x08;  // status bit 3: a conversion runs
const uint32_t kBmp280StartupUs = 2000u;  // datasheet 1.1: start-up time 2 ms

inline uint8_t os_code(uint8_t v) { return v > 5 ? 5 : v; }
inline uint32_t os_times(uint8_t code) { return code == 0 ? 0u : static_cast<uint32_t>(1u << (code - 1u)); }
}  // namespace

Bmp280::Bmp280(uint8_t addr7, uint8_t osrs_t, uint8_t osrs_p, uint8_t stuck_n, uint8_t timeout_steps)
    : ctrl_(static_cast<uint8_t>(os_code(osrs_t) << 5 | os_code(osrs_p) << 2 | 1u)), status_(0),
      cal_(), adc_P_(0), adc_T_(0), t_centi_(0), p_q8_(0), buf_() {
    sensor_init(c_, addr7, stuck_n, timeout_steps);
}

uint32_t Bmp280::measure_us() const {
    const uint8_t ot = static_cast<uint8_t>(ctrl_ >> 5 & 7u), op = static_cast<uint8_t>(ctrl_ >> 2 & 7u);
    // Datasheet 3.8.1 (max): 1.25 + 2.3 * osrs_t + (2.3 * osrs_p + 0.575) ms.
    const uint32_t t = 1250u + 2300u * os_times(ot);
    return op != 0 ? t + 2300u * os_times(op) + 575u : t;
}

void Bmp280::step() { sensor_step(*this); }

bool Bmp280::waiting() const { return c_.state == kBRead; }

bool Bmp280::heartbeat(uint32_t now) {
    (void)now;
    const uint8_t w = kBmp280RegStatus;
    return sensor_start(c_, &w, 1, &status_, 1);
}

// The status read while measuring: a failure is no answer; `measuring`
// clear (the measurement is over before its datasheet maximum) makes the
// data due now.
void Bmp280::beat_done(uint8_t status, uint32_t now) {
    if (status != kTwiOk) {
        sensor_fault(c_, kSensorNoAnswer, now);
        return;
    }
    if (!(status_ & kBmp280Measuring)) c_.due_us = now;
}

void Bmp280::issue(uint32_t now) {
    (void)now;
    uint8_t w[2];
    switch (c_.state) {
        case kBReset: w[0] = kBmp280RegReset; w[1] = kBmp280ResetWord; (void)sensor_start(c_, w, 2, 0, 0); break;
        case kBId: w[0] = kBmp280RegId; (void)sensor_start(c_, w, 1, buf_, 1); break;
        case kBCal: w[0] = kBmp280RegCalib; (void)sensor_start(c_, w, 1, buf_, kBmp280CalibLen); break;
        case kBCfg: w[0] = kBmp280RegConfig; w[1] = 0; (void)sensor_start(c_, w, 2, 0, 0); break;
        case kBTrig: w[0] = kBmp280RegCtrlMeas; w[1] = ctrl_; (void)sensor_start(c_, w, 2, 0, 0); break;
        default: w[0] = kBmp280RegData; (void)sensor_start(c_, w, 1, buf_, kBmp280DataLen); break;
    }
}

void Bmp280::done(uint8_t status, uint32_t now) {
    if (status != kTwiOk) {
        sensor_fault(c_, kSensorNoAnswer, now);
        return;
    }
    c_.due_us = now;
    switch (c_.state) {
        case kBReset:
            c_.state = kBId;
            c_.due_us = now + kBmp280StartupUs;
            break;
        case kBId:
            if (buf_[0] != kBmp280ChipId) { sensor_fault(c_, kSensorBadId, now); break; }
            c_.state = kBCal;
            break;
        case kBCal:
            if (bmp280_parse_calib(buf_, cal_) != kOk) { sensor_fault(c_, kSensorBadCalib, now); break; }
            c_.state = kBCfg;
            break;
        case kBCfg: c_.state = kBTrig; break;
        case kBTrig:
            c_.state = kBRead;
            c_.due_us = now + measure_us();
            break;
        default: {
            int32_t p, t, t_fine;
            bmp280_parse_raw(buf_, p, t);
            sensor_reading(c_, p == adc_P_ && t == adc_T_);
            adc_P_ = p;
            adc_T_ = t;
            t_centi_ = bmp280_compensate_T(cal_, t, t_fine);
            p_q8_ = bmp280_compensate_P64(cal_, p, t_fine);
            temp_c_ = f32_from_i32(t_centi_) / 100.0f;
            pressure_pa_ = f32_from_u32(p_q8_) / 256.0f;
            c_.state = kBTrig;
            break;
        }
    }
}

// ---- MS5611 ------------------------------------------------------------------

namespace {
enum : uint8_t { kMReset = 0, kMPromCmd, kMPromRead, kMConv, kMAdcCmd, kMAdcRead };
const uint32_t kMs5611ReloadUs = 3000u;  // datasheet: reset reloads the PROM, 2.8 ms
// Datasheet maximum conversion times for OSR 256..4096.
const uint16_t kMs5611ConvUs[5] = {600, 1170, 2280, 4540, 9040};
}  // namespace

Ms5611::Ms5611(uint8_t addr7, uint8_t osr, uint8_t stuck_n, uint8_t timeout_steps)
    : osr_(osr > 4 ? 4 : osr), word_(0), cal_(), d1_(0), d2_(0), last_d1_(0), last_d2_(0),
      t_centi_(0), p_(0), buf_() {
    sensor_init(c_, addr7, stuck_n, timeout_steps);
}

uint32_t Ms5611::conversion_us() const { return kMs5611ConvUs[osr_]; }

void Ms5611::step() { sensor_step(*this); }

bool Ms5611::waiting() const { return c_.state == kMAdcCmd; }

void Ms5611::issue(uint32_t now) {
    (void)now;
    uint8_t w;
    switch (c_.state) {
        case kMReset: w = kMs5611CmdReset; (void)sensor_start(c_, &w, 1, 0, 0); break;
        case kMPromCmd:
            w = static_cast<uint8_t>(kMs5611CmdProm + 2u * word_);
            (void)sensor_start(c_, &w, 1, 0, 0);
            break;
        case kMPromRead: (void)sensor_start(c_, 0, 0, buf_ + 2u * word_, 2); break;
        case kMConv:  // word_: 0 converts D2 (temperature), 1 D1 (pressure)
            w = static_cast<uint8_t>((word_ == 0 ? kMs5611CmdD2 : kMs5611CmdD1) + 2u * osr_);
            (void)sensor_start(c_, &w, 1, 0, 0);
            break;
        case kMAdcCmd: w = kMs5611CmdAdcRead; (void)sensor_start(c_, &w, 1, 0, 0); break;
        default: (void)sensor_start(c_, 0, 0, buf_, 3); break;
    }
}

void Ms5611::done(uint8_t status, uint32_t now) {
    if (status != kTwiOk) {
        sensor_fault(c_, kSensorNoAnswer, now);
        return;
    }
    c_.due_us = now;
    switch (c_.state) {
        case kMReset:
            c_.state = kMPromCmd;
            word_ = 0;
            c_.due_us = now + kMs5611ReloadUs;
            break;
        case kMPromCmd: c_.state = kMPromRead; break;
        case kMPromRead:
            if (++word_ < 8) { c_.state = kMPromCmd; break; }
            if (ms5611_parse_prom_bytes(buf_, cal_) != kOk) { sensor_fault(c_, kSensorBadCalib, now); break; }
            word_ = 0;
            c_.state = kMConv;
            break;
        case kMConv:
            c_.state = kMAdcCmd;
            c_.due_us = now + conversion_us();
            break;
        case kMAdcCmd: c_.state = kMAdcRead; break;
        default: {
            const uint32_t d = ms5611_parse_adc(buf_);
            if (d == 0) {  // read with no conversion done: the part lost it (reset?)
                sensor_fault(c_, kSensorNoAnswer, now);
                break;
            }
            if (word_ == 0) {
                d2_ = d;
                word_ = 1;
                c_.state = kMConv;
                break;
            }
            d1_ = d;
            word_ = 0;
            c_.state = kMConv;
            sensor_reading(c_, d1_ == last_d1_ && d2_ == last_d2_);
            last_d1_ = d1_;
            last_d2_ = d2_;
            Ms5611Result r;
            ms5611_compensate(cal_, d1_, d2_, true, r);
            t_centi_ = r.TEMP;
            p_ = r.P;
            temp_c_ = f32_from_i32(t_centi_) / 100.0f;
            pressure_pa_ = f32_from_i32(p_);
            break;
        }
    }
}

}  // namespace fsw
