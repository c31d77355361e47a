// Scenario: the barometer drivers (fsw_baro.h) over the interrupt-driven TWI
// (fsw_twi.h) on the simulated ATmega328P, against the harness's simulated
// parts: a BMP280 at 0x76 and an MS5611 at 0x77 (mk/firmware.mk passes
// `-I bmp280@0x76 -I ms5611@0x77` to this suite only). The parts default to
// the datasheets' worked examples, so the drivers must report the
// datasheets' compensated values. Steps are paced by the sleeping
// executor's cycle timer at 1 kHz (pal::cycle_wait), as an application's
// task would be, and each step's duration is measured (micros32, 1 us =
// 16 cycles) and printed: the worst step is the non-blocking guarantee.
// On the host the same tests run against a scripted responder on the
// native bus (psl_native.h: twi_set_responder), below: small register
// models of the two parts with the same datasheet defaults, conversions
// ending at once, and failure switches the native-only tests flip mid-run
// (nack, stuck, ok). On the AVR those mid-run failures are
// tests/sim/test_baro_faults.py: the Unity runner has no host control of
// the harness's parts.
#include "test_support.h"

#include "fsw_baro.h"
#include "fsw_twi.h"

#if !defined(__AVR__)
#include "psl_native.h"
#endif

using namespace fsw;

#include "part_suite.inc"

#if !defined(__AVR__)
// ---- the host's parts: BMP280 at 0x76, MS5611 at 0x77 ---------------------------
static const uint8_t kBmpCalibBytes[24] = {0x70, 0x6B, 0x43, 0x67, 0x18, 0xFC, 0x7D, 0x8E, 0x43, 0xD6, 0xD0, 0x0B,
                                           0x27, 0x0B, 0x8C, 0x00, 0xF9, 0xFF, 0x8C, 0x3C, 0xF8, 0xC6, 0x70, 0x17};
static struct {
    uint8_t fail, reg;
    int32_t adc_P, adc_T;   // what the next measurement latches
    uint8_t data[6];        // F7..FC
} g_bmp = {kModelOk, 0, 415148L, 519888L, {0x80, 0, 0, 0x80, 0, 0}};
static struct {
    uint8_t fail, prom_word, adc_sel, have;
    uint32_t D1, D2, result;
    uint16_t prom[8];
} g_ms = {kModelOk, 0, 0, 0, 9085466UL, 8569150UL, 0, {0, 40127, 36924, 23317, 23282, 33464, 28312, 0}};

static uint8_t bmp_model(const uint8_t* w, uint8_t nw, uint8_t* r, uint8_t nr) {
    if (nw >= 1) g_bmp.reg = w[0];
    for (uint8_t i = 0; i + 1 < nw; i = static_cast<uint8_t>(i + 2)) {
        if (w[i] == 0xF4 && (w[i + 1] & 3u) != 0 && g_bmp.fail != kModelStuck) {  // a measurement, at once
            const int32_t p = g_bmp.adc_P, t = g_bmp.adc_T;
            const uint8_t d[6] = {static_cast<uint8_t>(p >> 12), static_cast<uint8_t>(p >> 4), static_cast<uint8_t>(p << 4),
                                  static_cast<uint8_t>(t >> 12), static_cast<uint8_t>(t >> 4), static_cast<uint8_t>(t << 4)};
            memcpy(g_bmp.data, d, 6);
        }
    }
    for (uint8_t i = 0; i < nr; ++i) {
        const uint8_t a = static_cast<uint8_t>(g_bmp.reg + i);
        uint8_t v = 0;
        if (a == 0xD0) v = 0x58;
        else if (a >= 0x88 && a < 0x88 + 24) v = kBmpCalibBytes[a - 0x88];
        else if (a >= 0xF7 && a <= 0xFC) v = g_bmp.data[a - 0xF7];
        r[i] = v;
    }
    return kTwiOk;
}

static uint8_t ms_model(const uint8_t* w, uint8_t nw, uint8_t* r, uint8_t nr) {
    if (nw == 1) {
        const uint8_t c = w[0];
        if (c >= 0xA0 && c <= 0xAE) { g_ms.prom_word = static_cast<uint8_t>((c - 0xA0) / 2); g_ms.adc_sel = 0; }
        else if (c == 0x00) g_ms.adc_sel = 1;
        else if ((c & 0xF0) == 0x40 || (c & 0xF0) == 0x50) {  // a conversion, at once
            if (g_ms.fail != kModelStuck || !g_ms.have) g_ms.result = (c & 0xF0) == 0x40 ? g_ms.D1 : g_ms.D2;
            g_ms.have = 1;
        }
    }
    if (nr == 2 && !g_ms.adc_sel) {
        r[0] = static_cast<uint8_t>(g_ms.prom[g_ms.prom_word] >> 8);
        r[1] = static_cast<uint8_t>(g_ms.prom[g_ms.prom_word]);
    } else if (nr == 3) {
        const uint32_t v = g_ms.have ? g_ms.result : 0;
        r[0] = static_cast<uint8_t>(v >> 16); r[1] = static_cast<uint8_t>(v >> 8); r[2] = static_cast<uint8_t>(v);
        if (g_ms.fail != kModelStuck) g_ms.have = 0;  // read once (stuck: the same again)
    } else {
        for (uint8_t i = 0; i < nr; ++i) r[i] = 0;
    }
    return kTwiOk;
}

static uint8_t responder(uint8_t addr7, const uint8_t* w, uint8_t nw, uint8_t* r, uint8_t nr) {
    if (addr7 == 0x76 && g_bmp.fail != kModelNack) return bmp_model(w, nw, r, nr);
    if (addr7 == 0x77 && g_ms.fail != kModelNack) return ms_model(w, nw, r, nr);
    return kTwiNackAddr;
}

static void models_begin(void) {
    g_ms.prom[7] = 0;
    g_ms.prom[7] = ms5611_crc4(g_ms.prom);
    native::twi_set_responder(responder);
}
#endif

static uint32_t g_worst_us, g_worst_bmp_us, g_worst_ms_us;

// Runs `cycles` executor cycles of 1 ms, stepping the drivers given (either
// may be null) once each per cycle; returns the worst step (us).
static uint32_t run_cycles(Bmp280* b, Ms5611* m, uint16_t cycles) {
    uint32_t worst = 0;
    for (uint16_t k = 0; k < cycles; ++k) {
        cycle_start();
        uint32_t t0 = pal::micros32();
        if (b != 0) b->step();
        uint32_t t1 = pal::micros32();
        if (t1 - t0 > worst) worst = t1 - t0;
        if (b != 0 && t1 - t0 > g_worst_bmp_us) g_worst_bmp_us = t1 - t0;
        if (m != 0) m->step();
        t0 = pal::micros32();
        if (t0 - t1 > worst) worst = t0 - t1;
        if (m != 0 && t0 - t1 > g_worst_ms_us) g_worst_ms_us = t0 - t1;
        cycle_done();
    }
    if (worst > g_worst_us) g_worst_us = worst;
    wait_bus();  // the drivers (a test's locals) outlive their last transactions
    return worst;
}

static void test_bmp280_datasheet(void) {
    Bmp280 b(0x76, 1, 1, 0);
    TEST_ASSERT_EQUAL_UINT32(6425UL, b.measure_us());
    run_cycles(&b, 0, 40);  // reset 2 ms, ID, calibration, config, one 6.4 ms measurement
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, b.health());
    TEST_ASSERT_EQUAL_UINT16(0, b.faults());
    TEST_ASSERT_TRUE(b.readings() >= 1);
    TEST_ASSERT_EQUAL_UINT16(27504, b.calib().dig_T1);
    TEST_ASSERT_EQUAL_INT16(-7, b.calib().dig_P6);
    TEST_ASSERT_EQUAL_INT32(415148L, b.adc_P());
    TEST_ASSERT_EQUAL_INT32(519888L, b.adc_T());
    TEST_ASSERT_EQUAL_INT32(2508, b.temp_centi());         // 25.08 degC
    TEST_ASSERT_EQUAL_UINT32(25767233UL, b.pressure_q24_8()); // 100653.25 Pa
    TEST_ASSERT_EQUAL_UINT32(bits_of(100653.25f), bits_of(b.pressure_pa()));
    TEST_ASSERT_EQUAL_UINT32(bits_of(25.08f), bits_of(b.temp_c()));
    const uint16_t n = b.readings();
    run_cycles(&b, 0, 100);  // ~7.4 ms a reading: 13 or so more
    TEST_ASSERT_TRUE(b.readings() >= n + 10);
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, b.health());
}

static void test_ms5611_datasheet(void) {
    Ms5611 m(0x77, 4, 0);
    TEST_ASSERT_EQUAL_UINT32(9040UL, m.conversion_us());
    run_cycles(0, &m, 60);  // reset 3 ms, 16 PROM transactions, D2 and D1 at 9.04 ms
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, m.health());
    TEST_ASSERT_EQUAL_UINT16(0, m.faults());
    TEST_ASSERT_TRUE(m.readings() >= 1);
    TEST_ASSERT_EQUAL_UINT16(40127, m.calib().C1);
    TEST_ASSERT_EQUAL_UINT16(28312, m.calib().C6);
    TEST_ASSERT_EQUAL_UINT32(9085466UL, m.d1());
    TEST_ASSERT_EQUAL_UINT32(8569150UL, m.d2());
    TEST_ASSERT_EQUAL_INT32(2007, m.temp_centi());     // 20.07 degC
    TEST_ASSERT_EQUAL_INT32(100009L, m.pressure_int()); // 1000.09 mbar
    TEST_ASSERT_EQUAL_UINT32(bits_of(100009.0f), bits_of(m.pressure_pa()));
    TEST_ASSERT_EQUAL_UINT32(bits_of(20.07f), bits_of(m.temp_c()));
}

// Both on the bus at once, stepped in the same cycles: they take turns.
static void test_both_share_the_bus(void) {
    Bmp280 b(0x76, 1, 1, 0);
    Ms5611 m(0x77, 2, 0);  // OSR 1024: 2.28 ms
    run_cycles(&b, &m, 200);
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, b.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, m.health());
    TEST_ASSERT_EQUAL_UINT16(0, b.faults() + m.faults());
    TEST_ASSERT_TRUE(b.readings() >= 15);
    print_u32("200 cycles shared: BMP280 readings ", b.readings());
    print_u32("200 cycles shared: MS5611 readings ", m.readings());
    TEST_ASSERT_TRUE(m.readings() >= 10);
    TEST_ASSERT_EQUAL_INT32(2508, b.temp_centi());
    TEST_ASSERT_EQUAL_INT32(100009L, m.pressure_int());
}

// Nobody at the address: reported at the step after the first transaction.
static void test_no_answer(void) {
    Bmp280 b(0x50);
    Ms5611 m(0x51);
    run_cycles(&b, &m, 2);
    TEST_ASSERT_EQUAL_UINT8(kSensorNoAnswer, b.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorNoAnswer, m.health());
    TEST_ASSERT_EQUAL_UINT16(1, b.faults());
    TEST_ASSERT_EQUAL_UINT16(1, m.faults());
    run_cycles(&b, &m, 100);  // retries every 20 ms
    TEST_ASSERT_TRUE(b.faults() >= 4);
    TEST_ASSERT_EQUAL_UINT16(0, b.readings());
    TEST_ASSERT_TRUE(twi_counters().nack_addr >= 8);
}

// The wrong part at the address: a BMP280 driver on the MS5611 reads no
// 0x58; an MS5611 driver on the BMP280 reads a PROM that fails its CRC.
static void test_wrong_part(void) {
    Bmp280 b(0x77);
    Ms5611 m(0x76);
    run_cycles(&b, &m, 30);
    TEST_ASSERT_EQUAL_UINT8(kSensorBadId, b.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorBadCalib, m.health());
    TEST_ASSERT_EQUAL_UINT16(0, b.readings() + m.readings());
}

// The simulated parts' raw counts stay at the datasheet examples, so a
// driver asked to flag 3 unchanged conversions in a row says stuck (one fault).
static void test_stuck(void) {
    Bmp280 b(0x76, 1, 1, 3);
    Ms5611 m(0x77, 0, 3);  // OSR 256: 0.6 ms
    run_cycles(&b, &m, 100);
    TEST_ASSERT_EQUAL_UINT8(kSensorStuck, b.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorStuck, m.health());
    TEST_ASSERT_EQUAL_UINT16(1, b.faults());
    TEST_ASSERT_EQUAL_UINT16(1, m.faults());
    TEST_ASSERT_EQUAL_INT32(2508, b.temp_centi());  // the values are still there
}

// The queue and the abort path a driver takes when its transaction
// outlives timeout_steps (the simulated parts always answer, so it is
// called directly here): a transaction started while another runs waits
// behind it; abandoning one (by its status byte) touches only that one,
// queued or on the bus; then the bus works on.
static void test_queue_and_abort(void) {
    wait_bus();  // the earlier tests' drivers may have left a transaction
    uint8_t cal[24], id1[1] = {0}, id2[1] = {0}, ms[2] = {0, 0};
    volatile uint8_t s_cal = kTwiIdle, s_id1 = kTwiIdle, s_id2 = kTwiIdle, s_ms = kTwiIdle;
    const uint8_t reg = 0x88, id = 0xD0, prom = 0xA2;
    TEST_ASSERT_TRUE(twi_start(0x76, &reg, 1, cal, 24, &s_cal));
    TEST_ASSERT_TRUE(twi_start(0x76, &id, 1, id1, 1, &s_id1));   // queued behind it
    TEST_ASSERT_TRUE(twi_start(0x77, &prom, 1, 0, 0, &s_ms));    // and this
    TEST_ASSERT_EQUAL_UINT8(kTwiBusy, s_id1);
    TEST_ASSERT_EQUAL_UINT8(kTwiBusy, s_ms);
    twi_abort(&s_id1);  // still queued: it leaves the queue, nothing else is touched
    TEST_ASSERT_EQUAL_UINT8(kTwiTimeout, s_id1);
    TEST_ASSERT_EQUAL_UINT8(kTwiBusy, s_ms);
    TEST_ASSERT_EQUAL_UINT8(kTwiBusy, s_cal);  // (the host's bus runs them at the first twi_busy poll)
    TEST_ASSERT_TRUE(twi_start(0x76, &id, 1, id2, 1, &s_id2));
    twi_abort(&s_cal);  // on the bus: abandoned, and the next in line starts
    TEST_ASSERT_EQUAL_UINT8(kTwiTimeout, s_cal);
    wait_bus();
    TEST_ASSERT_EQUAL_UINT8(kTwiOk, s_ms);
    TEST_ASSERT_EQUAL_UINT8(kTwiOk, s_id2);
    TEST_ASSERT_EQUAL_HEX8(0x58, id2[0]);
    TEST_ASSERT_EQUAL_HEX8(0x00, id1[0]);  // the abandoned read stored nothing
    // The MS5611's PROM word 1 (the command above selected it) reads C1.
    TEST_ASSERT_TRUE(twi_start(0x77, 0, 0, ms, 2, &s_ms));
    wait_bus();
    TEST_ASSERT_EQUAL_UINT8(kTwiOk, s_ms);
    TEST_ASSERT_EQUAL_UINT16(40127, static_cast<uint16_t>(ms[0] << 8 | ms[1]));
    // One on the bus and kTwiQueueLen waiting: the next start is refused.
    volatile uint8_t st[kTwiQueueLen + 2];
    uint8_t n = 0;
    while (n < kTwiQueueLen + 2 && twi_start(0x76, &reg, 1, cal, 24, &st[n])) ++n;
    TEST_ASSERT_EQUAL_UINT8(kTwiQueueLen + 1, n);
    wait_bus();
    for (uint8_t i = 0; i < n; ++i) TEST_ASSERT_EQUAL_UINT8(kTwiOk, st[i]);
    // The legacy form: no status byte: the transaction on the bus, whoever's.
    TEST_ASSERT_TRUE(twi_start(0x76, &reg, 1, cal, 24));
    twi_abort();
    TEST_ASSERT_FALSE(twi_busy());
    TEST_ASSERT_EQUAL_UINT8(kTwiTimeout, twi_result());
}

#if !defined(__AVR__)
// Host only: the parts fail and come back mid-run.
static void test_native_nack_then_ok(void) {
    Bmp280 b(0x76, 1, 1, 0);
    Ms5611 m(0x77, 2, 0);
    run_cycles(&b, &m, 50);
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, b.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, m.health());
    g_bmp.fail = kModelNack;
    // The BMP280's next transaction comes within a measurement (6.4 ms) and
    // a cycle; its failure is seen at the step after it.
    uint16_t k = 0;
    while (b.health() == kSensorOk && k < 20) { run_cycles(&b, &m, 1); ++k; }
    TEST_ASSERT_EQUAL_UINT8(kSensorNoAnswer, b.health());
    TEST_ASSERT_TRUE(k <= 9);
    run_cycles(&b, &m, 60);
    TEST_ASSERT_EQUAL_UINT8(kSensorNoAnswer, b.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, m.health());  // the other goes on
    TEST_ASSERT_EQUAL_UINT16(0, m.faults());
    g_bmp.fail = kModelOk;
    g_ms.fail = kModelNack;
    run_cycles(&b, &m, 60);
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, b.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorNoAnswer, m.health());
    g_ms.fail = kModelOk;
    run_cycles(&b, &m, 60);
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, m.health());
    TEST_ASSERT_EQUAL_INT32(100009L, m.pressure_int());
    TEST_ASSERT_EQUAL_INT32(2508, b.temp_centi());
}

// `n` cycles with the parts' raw pressure counts changing every cycle (noise).
static void run_changing(Bmp280* b, Ms5611* m, uint16_t n) {
    for (uint16_t k = 0; k < n; ++k) {
        g_bmp.adc_P = 415148L + k;
        g_ms.D1 = 9085466UL + k;
        run_cycles(b, m, 1);
    }
}

// Changing counts (noise) are never stuck; `stuck` is seen after stuck_n
// unchanged conversions and clears with the next changed one.
static void test_native_stuck_then_ok(void) {
    Bmp280 b(0x76, 1, 1, 4);
    Ms5611 m(0x77, 0, 4);
    run_changing(&b, &m, 200);
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, b.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, m.health());
    g_bmp.fail = kModelStuck;
    g_ms.fail = kModelStuck;
    run_changing(&b, &m, 100);
    TEST_ASSERT_EQUAL_UINT8(kSensorStuck, b.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorStuck, m.health());
    TEST_ASSERT_EQUAL_UINT16(1, b.faults());
    TEST_ASSERT_EQUAL_UINT16(1, m.faults());
    g_bmp.fail = kModelOk;
    g_ms.fail = kModelOk;
    run_changing(&b, &m, 50);
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, b.health());
    TEST_ASSERT_EQUAL_UINT8(kSensorOk, m.health());
    g_bmp.adc_P = 415148L;
    g_ms.D1 = 9085466UL;
}
#endif

static void test_report(void) {
    print_u32("worst step (us, x16 = cycles): ", g_worst_us);
    print_u32("worst Bmp280::step (us): ", g_worst_bmp_us);
    print_u32("worst Ms5611::step (us): ", g_worst_ms_us);
    print_u32("sizeof(Bmp280) B: ", sizeof(Bmp280));
    print_u32("sizeof(Ms5611) B: ", sizeof(Ms5611));
#if defined(__AVR__)
    TEST_ASSERT_TRUE(g_worst_us < 1000UL);
#endif
}

static void run(void) {
    parts_suite_begin();
    twi_begin(400000UL);
    UNITY_BEGIN();
    RUN_TEST(test_bmp280_datasheet);
    RUN_TEST(test_ms5611_datasheet);
    RUN_TEST(test_both_share_the_bus);
    RUN_TEST(test_no_answer);
    RUN_TEST(test_wrong_part);
    RUN_TEST(test_stuck);
    RUN_TEST(test_queue_and_abort);
#if !defined(__AVR__)
    RUN_TEST(test_native_nack_then_ok);
    RUN_TEST(test_native_stuck_then_ok);
#endif
    RUN_TEST(test_report);
    (void)UNITY_END();
}

FSW_TEST_MAIN(run)
