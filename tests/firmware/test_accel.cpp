// Scenario: the accelerometer drivers (fsw_accel.h), and every driver
// together on one bus (fsw_sensor.h's step over fsw_twi.h's queue).
//
// On the simulated ATmega328P (mk/firmware.mk passes this suite's parts:
// an ADXL345 at 0x53 and one on the SPI with its chip select on B1 = D9,
// an MPU-6050 at 0x68, a BMP280 at 0x76, an MS5611 at 0x77) against the
// harness's register models and their default counts (ADXL345 z = 256:
// 1 g; MPU-6050 az = 16384: 1 g at +-2 g, temp -3920: about 25 degC).
// Steps are paced by the sleeping executor's cycle timer at 1 kHz; each
// driver's worst step is measured in CPU cycles with Timer1 (the cycle
// timer's counter, clk/8) and printed. The part failing mid-run (nack, ok)
// on the AVR is tests/sim/test_baro_faults.py's (the host sets it).
//
// On the host the same drivers run against scripted models (the TWI
// responder, the SPI responder of psl_native.h) with failure switches the
// native-only tests flip mid-run (nack, stuck, ok).
#include "test_support.h"

#include "fsw_accel.h"
#include "fsw_baro.h"
#include "fsw_sensor.h"
#include "fsw_twi.h"

#if !defined(__AVR__)
#include "psl_native.h"
#endif

using namespace fsw;

#include "part_suite.inc"

static const uint8_t kAdxlCs = 9;  // Uno D9 = PB1

#if !defined(__AVR__)
// ---- the host's parts: ADXL345 at 0x53 and on SPI (D9), MPU-6050 at 0x68 ----------
struct RegPart {
    uint8_t fail, ptr, id_reg, id;
    int16_t raw[4];     // x, y, z (and the MPU-6050's temp): the next sample
    uint32_t t_us;      // the ADXL345: when its last sample came
    uint8_t reg[128];
};
static RegPart g_adxl, g_adxl_spi, g_mpu;

static void part_reset(RegPart& p, uint8_t id_reg, uint8_t id, int16_t z) {
    memset(&p, 0, sizeof p);
    p.id_reg = id_reg;
    p.id = id;
    p.raw[2] = z;
    p.reg[id_reg] = id;
}

// The ADXL345 samples at BW_RATE's output data rate (the MPU-6050 at
// 1 kHz: a sample at every read of a 1 kHz executor), latched into the
// data registers unless stuck.
static void adxl_sample(RegPart& p) {
    if (!(p.reg[0x2D] & 0x08)) return;  // standby
    const uint32_t period = static_cast<uint32_t>((625UL << (15u - (p.reg[0x2C] & 15u))) / 2u);
    const uint32_t now = pal::micros32();
    if (now - p.t_us < period) return;
    p.t_us = now - p.t_us < 2u * period ? p.t_us + period : now;
    p.reg[0x30] |= 0x80;
    if (p.fail == kModelStuck) return;
    for (uint8_t i = 0; i < 3; ++i) {
        p.reg[0x32 + 2 * i] = static_cast<uint8_t>(p.raw[i]);
        p.reg[0x33 + 2 * i] = static_cast<uint8_t>(static_cast<uint16_t>(p.raw[i]) >> 8);
    }
}
static uint8_t adxl_read(RegPart& p, uint8_t r) {
    if (r == 0x30) adxl_sample(p);
    const uint8_t v = p.reg[r & 0x7F];
    if (r >= 0x32 && r <= 0x37) p.reg[0x30] &= 0x7F;
    return v;
}
static void adxl_write(RegPart& p, uint8_t r, uint8_t v) {
    if (r != 0x00 && r != 0x30 && (r < 0x32 || r > 0x37)) p.reg[r & 0x7F] = v;
}

static void mpu_sample(RegPart& p) {
    if (p.reg[0x6B] & 0x40) return;  // asleep
    p.reg[0x3A] |= 0x01;
    if (p.fail == kModelStuck) return;
    for (uint8_t i = 0; i < 4; ++i) {
        p.reg[0x3B + 2 * i] = static_cast<uint8_t>(static_cast<uint16_t>(p.raw[i]) >> 8);
        p.reg[0x3C + 2 * i] = static_cast<uint8_t>(p.raw[i]);
    }
}
static uint8_t mpu_read(RegPart& p, uint8_t r) {
    if (r == 0x3A) mpu_sample(p);
    const uint8_t v = p.reg[r & 0x7F];
    if (r == 0x3A) p.reg[0x3A] = 0;
    return v;
}
static void mpu_write(RegPart& p, uint8_t r, uint8_t v) {
    if (r == 0x6B && (v & 0x80)) {  // DEVICE_RESET
        const int16_t z = p.raw[2], t = p.raw[3];
        const uint8_t fail = p.fail;
        part_reset(p, 0x75, 0x68, z);
        p.raw[3] = t;
        p.fail = fail;
        p.reg[0x6B] = 0x40;
        return;
    }
    if (r != 0x75 && (r < 0x3A || r > 0x48)) p.reg[r & 0x7F] = v;
}

static uint8_t responder(uint8_t addr7, const uint8_t* w, uint8_t nw, uint8_t* r, uint8_t nr) {
    RegPart* p = addr7 == 0x53 ? &g_adxl : addr7 == 0x68 ? &g_mpu : 0;
    if (p == 0 || p->fail == kModelNack) return kTwiNackAddr;
    const bool adxl = p == &g_adxl;
    if (nw >= 1) p->ptr = w[0];
    for (uint8_t i = 1; i < nw; ++i) {
        if (adxl) adxl_write(*p, p->ptr, w[i]);
        else mpu_write(*p, p->ptr, w[i]);
        ++p->ptr;
    }
    for (uint8_t i = 0; i < nr; ++i) {
        r[i] = adxl ? adxl_read(*p, p->ptr) : mpu_read(*p, p->ptr);
        ++p->ptr;
    }
    return kTwiOk;
}

// The ADXL345's SPI: byte 0 R/W (bit 7), MB (bit 6), register; then data.
// Nack: nobody drives MISO (0xFF).
static uint8_t g_spi_cmd;
static uint8_t spi_responder(uint8_t cs_pin, uint16_t index, uint8_t out) {
    if (cs_pin != kAdxlCs || g_adxl_spi.fail == kModelNack) return 0xFF;
    if (index == 0) {
        g_spi_cmd = out;
        g_adxl_spi.ptr = out & 0x3F;
        return 0xFF;
    }
    uint8_t v = 0xFF;
    if (g_spi_cmd & 0x80) v = adxl_read(g_adxl_spi, g_adxl_spi.ptr);
    else adxl_write(g_adxl_spi, g_adxl_spi.ptr, out);
    if (g_spi_cmd & 0x40) g_adxl_spi.ptr = static_cast<uint8_t>((g_adxl_spi.ptr + 1) & 0x3F);
    return v;
}

static void models_begin(void) {
    part_reset(g_adxl, 0x00, 0xE5, 256);
    part_reset(g_adxl_spi, 0x00, 0xE5, 256);
    part_reset(g_mpu, 0x75, 0x68, 16384);
    g_mpu.raw[3] = -3920;
    g_mpu.reg[0x6B] = 0x40;
    native::twi_set_responder(responder);
    native::spi_set_responder(spi_responder);
}
#endif

// The time stamp for a step's length: Timer1's count (clk/8) on the AVR.
#if defined(__AVR__)
static uint16_t stamp(void) { return TCNT1; }
static uint32_t cycles_between(uint16_t a, uint16_t b) {
    const uint16_t top = static_cast<uint16_t>(OCR1A + 1u);
    return 8UL * static_cast<uint16_t>(b >= a ? b - a : b + top - a);
}
#else
static uint16_t stamp(void) { return 0; }
static uint32_t cycles_between(uint16_t, uint16_t) { return 0; }
#endif

// Worst step of each driver kind, CPU cycles.
enum { kWBmp, kWMs, kWAdxl, kWAdxlSpi, kWMpu, kWN };
static uint32_t g_worst[kWN];

struct Drivers {
    Bmp280* bmp;
    Ms5611* ms;
    Adxl345* adxl;
    Adxl345* adxl_spi;
    Mpu6050* mpu;
};

template <class D>
static void timed_step(D* d, uint8_t which) {
    if (d == 0) return;
    const uint16_t t0 = stamp();
    d->step();
    const uint32_t c = cycles_between(t0, stamp());
    if (c > g_worst[which]) g_worst[which] = c;
}

// Runs `cycles` executor cycles of 1 ms, stepping every driver given once each.
// The MPU-6050 first: it samples at 1 kHz, the cycle's own rate, so its read
// must start at the same point of every cycle to find one new sample each
// time; after the others, its read would start later or earlier with their
// steps' lengths (the BMP280's compensation, 0.5 ms, on some cycles) and,
// were a sample due in that span, find none on one cycle and two on the next.
static void run_cycles(const Drivers& d, uint16_t cycles) {
    for (uint16_t k = 0; k < cycles; ++k) {
        cycle_start();
        timed_step(d.mpu, kWMpu);
        timed_step(d.bmp, kWBmp);
        timed_step(d.ms, kWMs);
        timed_step(d.adxl, kWAdxl);
        timed_step(d.adxl_spi, kWAdxlSpi);
        cycle_done();
    }
    wait_bus();  // the drivers (a test's locals) outlive their last transactions
}

// The three accelerometers at their parts' places: the ADXL345s at 0x53 and
// on the SPI (D9) at +-16 g full resolution, 400 Hz; the MPU-6050 at 0x68 at
// +-2 g, DLPF 3; each stuck after `stuck_n` unchanged readings (0: never).
struct Accels {
    Adxl345 i2c, spi;
    Mpu6050 mpu;
    explicit Accels(uint8_t stuck_n)
        : i2c(0x53, 0, 3, 0xC, stuck_n), spi(kAdxlCs, 1, 3, 0xC, stuck_n), mpu(0x68, 0, 3, stuck_n) {}
    Drivers drivers() {
        Drivers d = {0, 0, &i2c, &spi, &mpu};
        return d;
    }
};

// Each of the three's health code is `code` / fault count is `n`; a
// failure names the driver, at the caller's line.
#define ASSERT_HEALTH3(code, x)                                                   \
    do {                                                                          \
        TEST_ASSERT_EQUAL_UINT8_MESSAGE((code), (x).i2c.health(), "ADXL345 I2C"); \
        TEST_ASSERT_EQUAL_UINT8_MESSAGE((code), (x).spi.health(), "ADXL345 SPI"); \
        TEST_ASSERT_EQUAL_UINT8_MESSAGE((code), (x).mpu.health(), "MPU-6050");    \
    } while (0)
#define ASSERT_FAULTS3(n, x)                                                      \
    do {                                                                          \
        TEST_ASSERT_EQUAL_UINT16_MESSAGE((n), (x).i2c.faults(), "ADXL345 I2C");   \
        TEST_ASSERT_EQUAL_UINT16_MESSAGE((n), (x).spi.faults(), "ADXL345 SPI");   \
        TEST_ASSERT_EQUAL_UINT16_MESSAGE((n), (x).mpu.faults(), "MPU-6050");      \
    } while (0)

static Drivers only(Adxl345* a, Adxl345* s, Mpu6050* m) {
    Drivers d = {0, 0, a, s, m};
    return d;
}

static void test_adxl345_i2c(void) {
    Adxl345 a(0x53, 0, 3, 0xC, 0);  // +-16 g full resolution, 400 Hz
    TEST_ASSERT_EQUAL_HEX8(0x0B, a.data_format());
    TEST_ASSERT_EQUAL_UINT32(2500UL, a.period_us());
    run_cycles(only(&a, 0, 0), 10);  // ID, 4 writes, then a burst read each step
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, a.health());
    const uint16_t n = a.readings();
    TEST_ASSERT_TRUE(n >= 1);
    run_cycles(only(&a, 0, 0), 100);  // a new sample every 2.5 ms: about 40
    TEST_ASSERT_TRUE(a.readings() - n >= 35);
    TEST_ASSERT_TRUE(a.readings() - n <= 45);
    TEST_ASSERT_EQUAL_UINT16(0, a.faults());
    TEST_ASSERT_EQUAL_INT16(256, a.counts(2));
    TEST_ASSERT_EQUAL_UINT32(bits_of(1.0f), bits_of(a.z_g()));  // full resolution: 256 LSB/g at any range
    TEST_ASSERT_EQUAL_UINT32(bits_of(0.0f), bits_of(a.x_g()));
    TEST_ASSERT_EQUAL_UINT32(bits_of(0.0f), bits_of(a.y_g()));
}

static void test_adxl345_spi(void) {
    Adxl345 a(kAdxlCs, 1, 1, 0xA, 0);  // +-4 g, 100 Hz
    run_cycles(only(0, &a, 0), 20);  // the first sample 10 ms after measuring starts
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, a.health());
    const uint16_t n = a.readings();
    run_cycles(only(0, &a, 0), 100);  // a sample every 10 ms
    TEST_ASSERT_TRUE(a.readings() - n >= 9);
    TEST_ASSERT_TRUE(a.readings() - n <= 11);
    TEST_ASSERT_EQUAL_UINT16(0, a.faults());
    TEST_ASSERT_EQUAL_UINT32(bits_of(1.0f), bits_of(a.z_g()));
    TEST_ASSERT_EQUAL_HEX8(0x09, a.data_format());
#if defined(__AVR__)
    // Mode 3, F_CPU / 4 (4 MHz: the fastest at most 5 MHz) while it is selected last.
    TEST_ASSERT_EQUAL_HEX8(_BV(SPE) | _BV(MSTR) | _BV(CPOL) | _BV(CPHA), SPCR);
    TEST_ASSERT_EQUAL_HEX8(0, SPSR & _BV(SPI2X));
#endif
}

static void test_mpu6050(void) {
    Mpu6050 m(0x68, 0, 3, 0);  // +-2 g, DLPF 3 (1 kHz sampling)
    run_cycles(only(0, 0, &m), 100);  // DEVICE_RESET, then 100 ms
    TEST_ASSERT_EQUAL_UINT8(kSensorInit, m.health());
    TEST_ASSERT_EQUAL_UINT16(0, m.readings());
    run_cycles(only(0, 0, &m), 20);  // ID, wake, CONFIG, ACCEL_CONFIG, INT_ENABLE, reads
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, m.health());
    const uint16_t n = m.readings();
    run_cycles(only(0, 0, &m), 100);
    TEST_ASSERT_TRUE(m.readings() - n >= 90);  // a sample each ms: nearly one a step
    TEST_ASSERT_EQUAL_UINT16(0, m.faults());
    TEST_ASSERT_EQUAL_INT16(16384, m.counts(2));
    TEST_ASSERT_EQUAL_UINT32(bits_of(1.0f), bits_of(m.z_g()));
    TEST_ASSERT_EQUAL_INT16(-3920, m.temp_counts());
    TEST_ASSERT_EQUAL_UINT32(bits_of(mpu6050_temp_c(-3920)), bits_of(m.temp_c()));
    TEST_ASSERT_FLOAT_WITHIN(0.01f, 25.0f, m.temp_c());
}

// The wrong part, or none: an ADXL345 driver on the MPU-6050 and an
// MPU-6050 driver on the ADXL345 read IDs not theirs; an ADXL345 on an
// SPI chip select nobody answers reads 0xFF (no answer); nobody at an I2C
// address is a NACK.
static void test_bad_id_and_absent(void) {
    Adxl345 a(0x68, 0, 3, 0xC, 0);
    Adxl345 s(8, 1, 3, 0xC, 0);  // D8: no part there
    Mpu6050 m(0x53, 3, 3, 0);
    Mpu6050 none(0x69, 3, 3, 0);
    Drivers d = {0, 0, &a, &s, &m};
    run_cycles(d, 3);
    TEST_ASSERT_EQUAL_UINT8(kSensorBadId, a.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorNoAnswer, s.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorInit, m.health());  // still in its 100 ms after the reset
    run_cycles(d, 110);
    TEST_ASSERT_EQUAL_UINT8(kSensorBadId, m.health());
    TEST_ASSERT_EQUAL_UINT16(0, a.readings() + s.readings() + m.readings());
    TEST_ASSERT_TRUE(a.faults() >= 4);  // retried every 20 ms
    Drivers e = {0, 0, 0, 0, &none};
    run_cycles(e, 2);
    TEST_ASSERT_EQUAL_UINT8(kSensorNoAnswer, none.health());
    TEST_ASSERT_EQUAL_UINT16(1, none.faults());
}

// The parts' counts stay at their defaults: stuck after stuck_n unchanged readings.
static void test_stuck_on_constant_counts(void) {
    Accels x(3);
    run_cycles(x.drivers(), 140);
    ASSERT_HEALTH3(kSensorStuck, x);
    ASSERT_FAULTS3(1, x);
    TEST_ASSERT_EQUAL_UINT32(bits_of(1.0f), bits_of(x.i2c.z_g()));  // the values are still there
}

#if defined(__AVR__)
// Four drivers on the one TWI: with the queue each gets a transaction
// every cycle, so each reads at its own part's pace. (The ADXL345 on the
// SPI is left out here: simavr shifts an SPI byte in 100 us, so its
// 9-byte burst alone fills most of a 1 ms cycle in the simulation.)
static void test_all_on_one_bus(void) {
    Bmp280 b(0x76, 1, 1, 0);
    Ms5611 ms(0x77, 2, 0);  // OSR 1024: 2.28 ms
    Adxl345 a(0x53, 0, 3, 0xC, 0);
    Mpu6050 m(0x68, 3, 3, 0);
    Drivers d = {&b, &ms, &a, 0, &m};
    run_cycles(d, 150);
    const uint16_t nb = b.readings(), nms = ms.readings(), na = a.readings(), nm = m.readings();
    const TwiCounters c0 = twi_counters();
    const uint32_t t0 = pal::micros32();
    run_cycles(d, 200);
    print_u32("200 cycles, 4 drivers on the TWI: ms ", (pal::micros32() - t0) / 1000UL);
    print_u32("  BMP280 readings ", b.readings() - nb);
    print_u32("  MS5611 readings ", ms.readings() - nms);
    print_u32("  ADXL345 readings ", a.readings() - na);
    print_u32("  MPU-6050 readings ", m.readings() - nm);
    print_u32("  TWI transactions ", twi_counters().transactions - c0.transactions);
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, b.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, ms.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, a.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, m.health());
    TEST_ASSERT_EQUAL_UINT16(0, b.faults() + ms.faults() + a.faults() + m.faults());
    // Every driver had a transaction every cycle (a heartbeat while it waits).
    TEST_ASSERT_EQUAL_UINT16(800, twi_counters().transactions - c0.transactions);
    // BMP280: trigger, 6.4 ms measuring (status reads), data: 9 steps a
    // reading; MS5611: per channel command, 2.28 ms, ADC command, read:
    // about 12 a reading.
    TEST_ASSERT_TRUE(b.readings() - nb >= 20);
    TEST_ASSERT_TRUE(ms.readings() - nms >= 15);
    TEST_ASSERT_TRUE(a.readings() - na >= 75);   // 400 Hz: 80 samples in 200 ms
    TEST_ASSERT_TRUE(m.readings() - nm >= 180);  // 1 kHz: one every step, nearly
    TEST_ASSERT_EQUAL_UINT16(0, twi_counters().timeout - c0.timeout);
    TEST_ASSERT_EQUAL_INT32(2508, b.temp_centi());
    TEST_ASSERT_EQUAL_INT32(100009L, ms.pressure_int());
    TEST_ASSERT_EQUAL_UINT32(bits_of(8.0f), bits_of(m.z_g()));  // 16384 counts at +-16 g: 8 g
}
#else
// Host only: the parts fail and come back mid-run; each failure is seen
// at the step after it, the others go on.
static void test_native_nack_then_ok(void) {
    Accels x(0);
    const Drivers d = x.drivers();
    run_cycles(d, 130);
    ASSERT_HEALTH3(kSensorOk, x);
    g_adxl.fail = kModelNack;
    g_adxl_spi.fail = kModelNack;
    g_mpu.fail = kModelNack;
    run_cycles(d, 1);  // the step's transaction fails (SPI: in the step itself)
    TEST_ASSERT_EQUAL_UINT8(kSensorNoAnswer, x.spi.health());
    run_cycles(d, 1);  // the TWI's failures are seen at the next step
    TEST_ASSERT_EQUAL_UINT8(kSensorNoAnswer, x.i2c.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorNoAnswer, x.mpu.health());
    run_cycles(d, 50);
    TEST_ASSERT_EQUAL_UINT8(kSensorNoAnswer, x.i2c.health());
    TEST_ASSERT_TRUE(x.i2c.faults() >= 3);
    g_adxl.fail = kModelOk;
    g_adxl_spi.fail = kModelOk;
    g_mpu.fail = kModelOk;
    run_cycles(d, 30);
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, x.i2c.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, x.spi.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorNoAnswer, x.mpu.health());  // in its 100 ms after the reset
    run_cycles(d, 110);
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, x.mpu.health());
    TEST_ASSERT_EQUAL_UINT32(bits_of(1.0f), bits_of(x.mpu.z_g()));
}

// Changing counts are never stuck; stuck after stuck_n unchanged
// readings; Ok again with the next changed one.
static void test_native_stuck_then_ok(void) {
    Accels x(4);
    const Drivers d = x.drivers();
    for (uint16_t k = 0; k < 200; ++k) {
        g_adxl.raw[0] = g_adxl_spi.raw[0] = g_mpu.raw[0] = static_cast<int16_t>(k);
        run_cycles(d, 1);
    }
    ASSERT_HEALTH3(kSensorOk, x);
    g_adxl.fail = g_adxl_spi.fail = g_mpu.fail = kModelStuck;
    run_cycles(d, 3);
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, x.i2c.health());  // not yet: 4 unchanged readings after the last changed one
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, x.mpu.health());
    run_cycles(d, 12);  // 400 Hz: 5 samples; MPU-6050: 12
    ASSERT_HEALTH3(kSensorStuck, x);
    TEST_ASSERT_EQUAL_UINT16(1, x.i2c.faults());
    g_adxl.fail = g_adxl_spi.fail = g_mpu.fail = kModelOk;
    g_adxl.raw[0] = g_adxl_spi.raw[0] = g_mpu.raw[0] = 1000;
    run_cycles(d, 4);  // the next sample of each
    ASSERT_HEALTH3(kSensorOk, x);
    TEST_ASSERT_EQUAL_INT16(1000, x.i2c.counts(0));
    ASSERT_FAULTS3(1, x);
    g_adxl.raw[0] = g_adxl_spi.raw[0] = g_mpu.raw[0] = 0;
}
#endif

static void test_report(void) {
    print_u32("worst Bmp280::step (CPU cycles): ", g_worst[kWBmp]);
    print_u32("worst Ms5611::step (CPU cycles): ", g_worst[kWMs]);
    print_u32("worst Adxl345::step I2C (CPU cycles): ", g_worst[kWAdxl]);
    print_u32("worst Adxl345::step SPI (CPU cycles): ", g_worst[kWAdxlSpi]);
    print_u32("worst Mpu6050::step (CPU cycles): ", g_worst[kWMpu]);
    print_u32("sizeof(Adxl345) B: ", sizeof(Adxl345));
    print_u32("sizeof(Mpu6050) B: ", sizeof(Mpu6050));
#if defined(__AVR__)
    for (uint8_t i = 0; i < kWN; ++i) TEST_ASSERT_TRUE(g_worst[i] > 0 && g_worst[i] < 16000UL);
#endif
}

static void run(void) {
    parts_suite_begin();
    sensors_begin(1, 1);
    UNITY_BEGIN();
    RUN_TEST(test_adxl345_i2c);
    RUN_TEST(test_adxl345_spi);
    RUN_TEST(test_mpu6050);
    RUN_TEST(test_bad_id_and_absent);
    RUN_TEST(test_stuck_on_constant_counts);
#if defined(__AVR__)
    RUN_TEST(test_all_on_one_bus);
#else
    RUN_TEST(test_native_nack_then_ok);
    RUN_TEST(test_native_stuck_then_ok);
#endif
    RUN_TEST(test_report);
    (void)UNITY_END();
}

FSW_TEST_MAIN(run)
