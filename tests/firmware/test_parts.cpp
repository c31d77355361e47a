// Scenario: the digital sensor parts' data conversion (fsw_parts.h) against
// the datasheets' own worked examples to the last count, register bytes to
// raw counts, the parsers' refusals, the MS5611's second-order branches with
// cold inputs, and vectors that the Python mirror (host-tools/fswkit/sim/
// parts.py, an independent implementation of the same datasheet text)
// computed, so that the simulated AVR is held to the same numbers as the
// host. On AVR the suite also measures each routine's cycles (Timer1) and
// prints them (docs/sensors.md). Test names are short and tables live in
// flash: the ATmega328P's 2 KB of RAM hold Unity's strings.
#include "test_support.h"

#include "fsw_parts.h"

#if defined(__AVR__)
#include <avr/interrupt.h>
#include <avr/io.h>
#endif

using namespace fsw;

void setUp(void) {}
void tearDown(void) {}

// ---- BMP280 ------------------------------------------------------------------------

// The datasheet's worked example (inputs; 25.08 degC and, from its
// double-precision formula, 100653.27 Pa), as public BMP280 test suites
// carry it; the integer results below are what the formula text of 3.11.3
// and 8.2 gives (docs/sensors.md). The trimming values ...
static const Bmp280Calib kBmpExample = {27504, 26435, -1000, 36477, -10685, 3024, 2855, 140, -7, 15500, -14600, 6000};
// ... as the 24 bytes of 0x88..0x9F (little-endian words) ...
static const uint8_t kBmpCalibBytes[24] = {0x70, 0x6B, 0x43, 0x67, 0x18, 0xFC, 0x7D, 0x8E, 0x43, 0xD6, 0xD0, 0x0B,
                                           0x27, 0x0B, 0x8C, 0x00, 0xF9, 0xFF, 0x8C, 0x3C, 0xF8, 0xC6, 0x70, 0x17};
// ... and adc_P = 415148 (0x655AC), adc_T = 519888 (0x7EED0) as 0xF7..0xFC.
static const uint8_t kBmpDataBytes[6] = {0x65, 0x5A, 0xC0, 0x7E, 0xED, 0x00};

static void test_bmp280_parse(void) {
    Bmp280Calib c;
    TEST_ASSERT_EQUAL(kOk, bmp280_parse_calib(kBmpCalibBytes, c));
    TEST_ASSERT_EQUAL_MEMORY(&kBmpExample, &c, sizeof c);
    int32_t adc_P = 0, adc_T = 0;
    bmp280_parse_raw(kBmpDataBytes, adc_P, adc_T);
    TEST_ASSERT_EQUAL_INT32(415148L, adc_P);
    TEST_ASSERT_EQUAL_INT32(519888L, adc_T);
    // 20 bits at most; xlsb's low nibble is not data.
    const uint8_t ones[6] = {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
    bmp280_parse_raw(ones, adc_P, adc_T);
    TEST_ASSERT_EQUAL_INT32(0xFFFFFL, adc_P);
    TEST_ASSERT_EQUAL_INT32(0xFFFFFL, adc_T);
    const uint8_t skipped[6] = {0x80, 0x00, 0x00, 0x80, 0x00, 0x00};
    bmp280_parse_raw(skipped, adc_P, adc_T);
    TEST_ASSERT_EQUAL_INT32(kBmp280AdcSkipped, adc_P);
    TEST_ASSERT_EQUAL_INT32(kBmp280AdcSkipped, adc_T);
}

static void test_bmp280_parse_refusals(void) {
    uint8_t b[24];
    Bmp280Calib c;
    memset(b, 0, sizeof b);
    TEST_ASSERT_EQUAL(kErrFault, bmp280_parse_calib(b, c));  // a bus that reads zeros
    memset(b, 0xFF, sizeof b);
    TEST_ASSERT_EQUAL(kErrFault, bmp280_parse_calib(b, c));  // an open bus
    memcpy(b, kBmpCalibBytes, sizeof b);
    b[6] = b[7] = 0;  // dig_P1 = 0: the pressure formulas' divisor
    TEST_ASSERT_EQUAL(kErrFault, bmp280_parse_calib(b, c));
    memcpy(b, kBmpCalibBytes, sizeof b);
    b[0] = b[1] = 0;  // dig_T1 = 0
    TEST_ASSERT_EQUAL(kErrFault, bmp280_parse_calib(b, c));
}

static void test_bmp280_example_T(void) {
    int32_t t_fine = 0;
    // var1 = 128793, var2 = -371: t_fine = 128422, T = 2508 (25.08 degC).
    TEST_ASSERT_EQUAL_INT32(2508, bmp280_compensate_T(kBmpExample, 519888L, t_fine));
    TEST_ASSERT_EQUAL_INT32(128422L, t_fine);
}

static void test_bmp280_example_P64(void) {
    // Q24.8: 25767233 / 256 = 100653.25 Pa; the datasheet's double-precision
    // formula gives 100653.27 Pa for the same inputs.
    TEST_ASSERT_EQUAL_UINT32(25767233UL, bmp280_compensate_P64(kBmpExample, 415148L, 128422L));
}

static void test_bmp280_example_P32(void) {
    // Appendix 8.2's formula, its shifts as written: 100656 Pa (var1 =
    // 36471 after the sensitivity step; Bosch's BMP280 API, which divides
    // instead of shifting, gets 100654). 8.2: "typically 1 Pa (1-sigma)".
    TEST_ASSERT_EQUAL_UINT32(100656UL, bmp280_compensate_P32(kBmpExample, 415148L, 128422L));
}

static void test_bmp280_zero_divisor(void) {
    Bmp280Calib c = kBmpExample;
    c.dig_P1 = 0;
    TEST_ASSERT_EQUAL_UINT32(0, bmp280_compensate_P64(c, 415148L, 128422L));
    TEST_ASSERT_EQUAL_UINT32(0, bmp280_compensate_P32(c, 415148L, 128422L));
}

// Across the part's range (-40..85 degC, 300..1100 hPa): raw values the
// Python inverse helpers chose for the physical values in the comments and
// what parts.py's forward formulas give for them.
struct BmpVector {
    int32_t adc_T, adc_P, T, t_fine;
    uint32_t p64, p32;
};
static const BmpVector kBmpVectors[] FSW_FLASH = {
    {313696L, 813182L, -4000L, -204821L, 7680002UL, 29999UL},     // -40 degC, 300 hPa
    {440056L, 335719L, 0L, -13L, 28160006UL, 110003UL},           //   0 degC, 1100 hPa
    {712456L, 734397L, 8500L, 435175L, 12799983UL, 50000UL},      //  85 degC, 500 hPa
    {519872L, 415143L, 2508L, 128396L, 25767254UL, 100657UL},     //  25.08 degC, 100653.25 Pa
    {376728L, 564613L, -2000L, -102425L, 17920007UL, 70000UL},    // -20 degC, 700 hPa
};

static void test_bmp280_range_vectors(void) {
    for (size_t i = 0; i < sizeof kBmpVectors / sizeof kBmpVectors[0]; ++i) {
        BmpVector v;
        flash_read(&v, &kBmpVectors[i], sizeof v);
        int32_t t_fine = 0;
        TEST_ASSERT_EQUAL_INT32(v.T, bmp280_compensate_T(kBmpExample, v.adc_T, t_fine));
        TEST_ASSERT_EQUAL_INT32(v.t_fine, t_fine);
        TEST_ASSERT_EQUAL_UINT32(v.p64, bmp280_compensate_P64(kBmpExample, v.adc_P, t_fine));
        TEST_ASSERT_EQUAL_UINT32(v.p32, bmp280_compensate_P32(kBmpExample, v.adc_P, t_fine));
    }
}

// A calibration no part has, whose datasheet expressions overflow 32 bits:
// the results are the two's-complement ones parts.py also computes (and no
// undefined behaviour: the native suites run under UBSan).
static void test_bmp280_overflow_wraps(void) {
    const Bmp280Calib c = {1, 32767, -32768, 1, -32768, 32767, -32768, 32767, -32768, 32767, -32768, 32767};
    int32_t t_fine = 0;
    // ((0xFFFFF >> 3) - 2) * 32767 = 4294737923 and (0xFFFF - 1)^2 = 4294705156 overflow 32 bits.
    TEST_ASSERT_EQUAL_INT32(0, bmp280_compensate_T(c, 0xFFFFFL, t_fine));
    TEST_ASSERT_EQUAL_INT32(16, t_fine);
    TEST_ASSERT_EQUAL_UINT32(226985174UL, bmp280_compensate_P64(c, 0, t_fine));
    TEST_ASSERT_EQUAL_UINT32(1125507379UL, bmp280_compensate_P32(c, 0, t_fine));
}

// ---- MS5611-01BA03 ---------------------------------------------------------------------

// Datasheet example ("Example / Typical" column of the calculation table).
static const Ms5611Calib kMsExample = {40127, 36924, 23317, 23282, 33464, 28312};

static void test_ms5611_example(void) {
    Ms5611Result r;
    ms5611_compensate(kMsExample, 9085466UL, 8569150UL, false, r);
    TEST_ASSERT_EQUAL_INT32(2366, r.dT);
    TEST_ASSERT_EQUAL_INT32(2007, r.TEMP);  // 20.07 degC
    TEST_ASSERT_TRUE(r.OFF == 2420281617LL);
    TEST_ASSERT_TRUE(r.SENS == 1315097036LL);
    TEST_ASSERT_EQUAL_INT32(100009L, r.P);  // 1000.09 mbar
    // At or above 20 degC the second order changes nothing.
    Ms5611Result r2;
    ms5611_compensate(kMsExample, 9085466UL, 8569150UL, true, r2);
    TEST_ASSERT_EQUAL_MEMORY(&r, &r2, sizeof r);
    TEST_ASSERT_EQUAL_INT32(0, r2.T2);
}

// TE's MS5837-30BA datasheet example computes TEMP, OFF and SENS with the
// MS5611's formulas, with a negative dT: its TEMP 1981 and SENS 1145816755
// are the floor shifts' (truncating division would give 1982, 1145816756),
// which is why every /2^n here is an arithmetic shift.
static void test_ms5611_shifts_floor(void) {
    const Ms5611Calib c = {34982, 36352, 20328, 22354, 26646, 26146};
    Ms5611Result r;
    ms5611_compensate(c, 4958179UL, 6815414UL, false, r);
    TEST_ASSERT_EQUAL_INT32(-5962, r.dT);
    TEST_ASSERT_EQUAL_INT32(1981, r.TEMP);
    TEST_ASSERT_TRUE(r.SENS == 1145816755LL);
    TEST_ASSERT_TRUE(r.OFF == 2381323464LL);
}

// Second order, -15 < TEMP < 20 degC and TEMP < -15 degC, with the example
// PROM. The -30 degC case by hand (datasheet formulas, floor shifts):
//   D2 = 7304879: dT = 7304879 - 33464*256 = -1261905
//   TEMP = 2000 + (-1261905*28312 = -35727054360) >> 23 = 2000 - 4259 = -2259
//   OFF  = 36924*2^16 + (23282*dT = -29379672210) >> 7 = 2419851264 - 229528690 = 2190322574
//   SENS = 40127*2^15 + (23317*dT = -29423838885) >> 8 = 1314881536 - 114936871 = 1199944665
//   TEMP < 2000:  T2 = dT^2 (1592404229025) >> 31 = 741
//                 (TEMP-2000)^2 = 18139081: OFF2 = 5*18139081/2 = 45347702, SENS2 = 5*18139081/4 = 22673851
//   TEMP < -1500: (TEMP+1500)^2 = 576081: OFF2 += 7*576081 = 4032567 -> 49380269,
//                 SENS2 += 11*576081/2 = 3168445 -> 25842296
//   TEMP = -2259 - 741 = -3000; OFF = 2140942305; SENS = 1174102369
//   D1 = 6750566: P = ((6750566*1174102369) >> 21 = 3779342428) - 2140942305 = 1638400123, >> 15 = 50000
struct MsVector {
    uint32_t D1, D2;
    int32_t dT, TEMP1, P1;  // first order
    int32_t TEMP, P, T2;    // second order
    int64_t OFF, SENS, OFF2, SENS2;
};
static const MsVector kMsVectors[] FSW_FLASH = {
    // 5 degC, 900 mbar
    {8703192UL, 8146643UL, -420141L, 582, 90164L, 500, 90000L, 82, 2338404744LL, 1274100835LL, 5026810LL, 2513405LL},
    // -30 degC, 500 mbar (the case above)
    {6750566UL, 7304879UL, -1261905L, -2259, 51031L, -3000, 50000L, 741, 2140942305LL, 1174102369LL, 49380269LL,
     25842296LL},
    // -10 degC, 1100 mbar
    {9969102UL, 7766205UL, -800579L, -702, 110766L, -1000, 110000L, 298, 2255981439LL, 1232837169LL, 18252010LL,
     9126005LL},
    // 19.99 degC (just below the branch), 1013.25 mbar
    {9155145UL, 8566488UL, -296L, 1999, 101325L, 1999, 101325L, 0, 2419797422LL, 1314854574LL, 2LL, 1LL},
    // 60 degC, 300 mbar (no second order)
    {5333365UL, 9751951UL, 1185167L, 6000, 30000L, 6000, 30000L, 0, 2635422030LL, 1422828953LL, 0LL, 0LL},
};

static void test_ms5611_second_order_cold(void) {
    for (size_t i = 0; i < sizeof kMsVectors / sizeof kMsVectors[0]; ++i) {
        MsVector v;
        flash_read(&v, &kMsVectors[i], sizeof v);
        Ms5611Result r1, r2;
        ms5611_compensate(kMsExample, v.D1, v.D2, false, r1);
        ms5611_compensate(kMsExample, v.D1, v.D2, true, r2);
        TEST_ASSERT_EQUAL_INT32(v.dT, r1.dT);
        TEST_ASSERT_EQUAL_INT32(v.TEMP1, r1.TEMP);
        TEST_ASSERT_EQUAL_INT32(v.P1, r1.P);
        TEST_ASSERT_EQUAL_INT32(0, r1.T2);
        TEST_ASSERT_EQUAL_INT32(v.dT, r2.dT);
        TEST_ASSERT_EQUAL_INT32(v.TEMP, r2.TEMP);
        TEST_ASSERT_EQUAL_INT32(v.P, r2.P);
        TEST_ASSERT_EQUAL_INT32(v.T2, r2.T2);
        TEST_ASSERT_TRUE(r2.OFF == v.OFF);
        TEST_ASSERT_TRUE(r2.SENS == v.SENS);
        TEST_ASSERT_TRUE(r2.OFF2 == v.OFF2);
        TEST_ASSERT_TRUE(r2.SENS2 == v.SENS2);
    }
}

static void test_ms5611_extremes(void) {
    // The corners of 16-bit C and 24-bit D: no intermediate overflows
    // (UBSan watches the native runs); values from parts.py.
    const Ms5611Calib hi = {65535, 65535, 65535, 65535, 0, 65535};
    const Ms5611Calib lo = {65535, 65535, 65535, 65535, 65535, 65535};
    Ms5611Result r;
    ms5611_compensate(hi, 0xFFFFFFUL, 0xFFFFFFUL, true, r);
    TEST_ASSERT_EQUAL_INT32(16777215L, r.dT);
    TEST_ASSERT_EQUAL_INT32(133069L, r.TEMP);
    TEST_ASSERT_TRUE(r.OFF == 12884704768LL);
    TEST_ASSERT_TRUE(r.SENS == 6442352384LL);
    TEST_ASSERT_EQUAL_INT32(1179629L, r.P);
    ms5611_compensate(lo, 0xFFFFFFUL, 0, true, r);
    TEST_ASSERT_EQUAL_INT32(-16776960L, r.dT);
    TEST_ASSERT_EQUAL_INT32(-260137L, r.TEMP);
    TEST_ASSERT_EQUAL_INT32(131068L, r.T2);
    TEST_ASSERT_TRUE(r.OFF == -161159425919LL);
    TEST_ASSERT_TRUE(r.SENS == -113127412481LL);
    TEST_ASSERT_TRUE(r.OFF2 == 156864655229LL);
    TEST_ASSERT_TRUE(r.SENS2 == 110980027136LL);
    TEST_ASSERT_EQUAL_INT32(-22700801L, r.P);
    // Bits above the 24 are not data.
    Ms5611Result a, b;
    ms5611_compensate(kMsExample, 9085466UL | 0xFF000000UL, 8569150UL | 0x5A000000UL, true, a);
    ms5611_compensate(kMsExample, 9085466UL, 8569150UL, true, b);
    TEST_ASSERT_EQUAL_MEMORY(&b, &a, sizeof a);
}

static void test_ms5611_crc4_an520(void) {
    // AN520's test table: CRC 0xB.
    uint16_t w[8] = {0x3132, 0x3334, 0x3536, 0x3738, 0x3940, 0x4142, 0x4344, 0x4500};
    TEST_ASSERT_EQUAL_UINT8(0x0B, ms5611_crc4(w));
    w[7] = 0x450B;  // the CRC nibble (and the rest of the low byte) is not part of it
    TEST_ASSERT_EQUAL_UINT8(0x0B, ms5611_crc4(w));
    w[7] = 0x45FB;
    TEST_ASSERT_EQUAL_UINT8(0x0B, ms5611_crc4(w));
    TEST_ASSERT_EQUAL_HEX16(0x45FB, w[7]);  // the input is not modified
}

static void test_ms5611_parse_prom(void) {
    uint16_t w[8] = {0x3132, 0x3334, 0x3536, 0x3738, 0x3940, 0x4142, 0x4344, 0x450B};
    Ms5611Calib c = {1, 2, 3, 4, 5, 6};
    TEST_ASSERT_EQUAL(kOk, ms5611_parse_prom(w, c));
    TEST_ASSERT_EQUAL_HEX16(0x3334, c.C1);
    TEST_ASSERT_EQUAL_HEX16(0x4344, c.C6);
    w[7] = 0x4500;  // CRC 0 stored, 0xB computed
    const Ms5611Calib before = c;
    TEST_ASSERT_EQUAL(kErrFault, ms5611_parse_prom(w, c));
    TEST_ASSERT_EQUAL_MEMORY(&before, &c, sizeof c);
    w[7] = 0x450B;
    w[3] ^= 0x0100;  // one flipped bit in C3
    TEST_ASSERT_EQUAL(kErrFault, ms5611_parse_prom(w, c));
    uint16_t zeros[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    TEST_ASSERT_EQUAL_UINT8(0, ms5611_crc4(zeros));  // passes the CRC ...
    TEST_ASSERT_EQUAL(kErrFault, ms5611_parse_prom(zeros, c));  // ... refused anyway
    uint16_t ones[8];
    for (int i = 0; i < 8; ++i) ones[i] = 0xFFFF;
    TEST_ASSERT_EQUAL(kErrFault, ms5611_parse_prom(ones, c));
    // From the bytes of the eight reads, MSB first; the example PROM with its CRC (0x0).
    const uint8_t bytes[16] = {0x00, 0x00, 0x9C, 0xBF, 0x90, 0x3C, 0x5B, 0x15, 0x5A, 0xF2, 0x82, 0xB8, 0x6E, 0x98, 0x00, 0x00};
    TEST_ASSERT_EQUAL(kOk, ms5611_parse_prom_bytes(bytes, c));
    TEST_ASSERT_EQUAL_MEMORY(&kMsExample, &c, sizeof c);
    const uint8_t adc[3] = {0x8A, 0xA2, 0x1A};
    TEST_ASSERT_EQUAL_UINT32(9085466UL, ms5611_parse_adc(adc));
}

// ---- ADXL345 -----------------------------------------------------------------------------

static void test_adxl345_counts(void) {
    // Full resolution, +-16 g, right-justified: 13 bits, sign-extended.
    const uint8_t fr[6] = {0x00, 0x01, 0x00, 0xF0, 0xFF, 0x0F};  // 256, -4096, 4095
    int16_t xyz[3];
    const uint8_t f16 = kAdxl345FullRes | 3;
    TEST_ASSERT_EQUAL_UINT8(13, adxl345_bits(f16));
    adxl345_counts(fr, f16, xyz);
    TEST_ASSERT_EQUAL_INT16(256, xyz[0]);
    TEST_ASSERT_EQUAL_INT16(-4096, xyz[1]);
    TEST_ASSERT_EQUAL_INT16(4095, xyz[2]);
    // Left-justified: the same 13 bits in the top of the word.
    const uint8_t lj[6] = {0x00, 0x08, 0x00, 0x80, 0xF8, 0x7F};  // 256 << 3, -4096 << 3, 4095 << 3
    adxl345_counts(lj, f16 | kAdxl345Justify, xyz);
    TEST_ASSERT_EQUAL_INT16(256, xyz[0]);
    TEST_ASSERT_EQUAL_INT16(-4096, xyz[1]);
    TEST_ASSERT_EQUAL_INT16(4095, xyz[2]);
    // 10-bit mode at any range: 10 bits; left-justified shifts by 6.
    TEST_ASSERT_EQUAL_UINT8(10, adxl345_bits(3));
    TEST_ASSERT_EQUAL_UINT8(10, adxl345_bits(kAdxl345FullRes));
    const uint8_t ten[6] = {0x00, 0x40, 0x00, 0x80, 0xC0, 0x7F};  // 256 << 6, -512 << 6, 511 << 6
    adxl345_counts(ten, kAdxl345Justify | 1, xyz);
    TEST_ASSERT_EQUAL_INT16(256, xyz[0]);
    TEST_ASSERT_EQUAL_INT16(-512, xyz[1]);
    TEST_ASSERT_EQUAL_INT16(511, xyz[2]);
}

static void test_adxl345_scale(void) {
    // Full resolution: 2^-8 g at every range (3.9 mg/LSB typ.).
    for (uint8_t range = 0; range < 4; ++range) {
        TEST_ASSERT_EQUAL_HEX32(bits_of(0.00390625f), bits_of(adxl345_g_per_count(kAdxl345FullRes | range)));
    }
    TEST_ASSERT_EQUAL_HEX32(bits_of(1.0f), bits_of(adxl345_g(256, kAdxl345FullRes | 3)));
    TEST_ASSERT_EQUAL_HEX32(bits_of(-16.0f), bits_of(adxl345_g(-4096, kAdxl345FullRes | 3)));
    TEST_ASSERT_EQUAL_HEX32(bits_of(15.99609375f), bits_of(adxl345_g(4095, kAdxl345FullRes | 3)));
    // 10-bit mode: 256, 128, 64, 32 LSB/g.
    TEST_ASSERT_EQUAL_HEX32(bits_of(1.0f), bits_of(adxl345_g(256, 0)));
    TEST_ASSERT_EQUAL_HEX32(bits_of(1.0f), bits_of(adxl345_g(128, 1)));
    TEST_ASSERT_EQUAL_HEX32(bits_of(1.0f), bits_of(adxl345_g(64, 2)));
    TEST_ASSERT_EQUAL_HEX32(bits_of(1.0f), bits_of(adxl345_g(32, 3)));
    TEST_ASSERT_EQUAL_HEX32(bits_of(-16.0f), bits_of(adxl345_g(-512, 3)));
    TEST_ASSERT_EQUAL_HEX32(bits_of(-0.01171875f), bits_of(adxl345_g(-3, 0)));  // exact: -3/256
    // Bits the scale ignores (self test, SPI, INT_INVERT, justify).
    TEST_ASSERT_EQUAL_HEX32(bits_of(0.03125f), bits_of(adxl345_g_per_count(0xE7)));
}

// ---- MPU-6050 --------------------------------------------------------------------------------

static void test_mpu6050_accel(void) {
    const uint8_t b[6] = {0x40, 0x00, 0x80, 0x00, 0x7F, 0xFF};  // 16384, -32768, 32767 (big-endian)
    int16_t xyz[3];
    mpu6050_accel_counts(b, xyz);
    TEST_ASSERT_EQUAL_INT16(16384, xyz[0]);
    TEST_ASSERT_EQUAL_INT16(-32768, xyz[1]);
    TEST_ASSERT_EQUAL_INT16(32767, xyz[2]);
    TEST_ASSERT_EQUAL_UINT8(0, mpu6050_afs_sel(0x00));
    TEST_ASSERT_EQUAL_UINT8(3, mpu6050_afs_sel(0x18));
    TEST_ASSERT_EQUAL_UINT8(2, mpu6050_afs_sel(0xF7));  // self-test and HPF bits ignored
    TEST_ASSERT_EQUAL_HEX32(bits_of(1.0f), bits_of(mpu6050_accel_g(16384, 0)));
    TEST_ASSERT_EQUAL_HEX32(bits_of(1.0f), bits_of(mpu6050_accel_g(8192, 1)));
    TEST_ASSERT_EQUAL_HEX32(bits_of(1.0f), bits_of(mpu6050_accel_g(4096, 2)));
    TEST_ASSERT_EQUAL_HEX32(bits_of(1.0f), bits_of(mpu6050_accel_g(2048, 3)));
    TEST_ASSERT_EQUAL_HEX32(bits_of(-2.0f), bits_of(mpu6050_accel_g(-32768, 0)));
    TEST_ASSERT_EQUAL_HEX32(bits_of(-16.0f), bits_of(mpu6050_accel_g(-32768, 3)));
    TEST_ASSERT_EQUAL_HEX32(bits_of(15.99951171875f), bits_of(mpu6050_accel_g(32767, 3)));  // exact
    TEST_ASSERT_EQUAL_HEX32(bits_of(6.103515625e-05f), bits_of(mpu6050_g_per_count(4)));  // AFS_SEL masked to 2 bits
}

static void test_mpu6050_temp(void) {
    // TEMP_OUT / 340 + 36.53 in binary32 (quotient rounded, then the sum):
    // bit patterns from parts.py.
    struct Case {
        int16_t raw;
        uint32_t bits;
    };
    static const Case kCases[] FSW_FLASH = {
        {0, 0x42121EB8UL},       // 36.53
        {-521, 0x420BFD97UL},    // 34.997646
        {340, 0x42161EB8UL},     // 37.53
        {-12410, 0x3CF5C000UL},  // 0.0299988
        {32767, 0x4304E74EUL},   // 132.90353
        {-32768, 0xC26F62CAUL},  // -59.846474
        {1000, 0x421DE27CUL},    // 39.471176
    };
    for (size_t i = 0; i < sizeof kCases / sizeof kCases[0]; ++i) {
        Case k;
        flash_read(&k, &kCases[i], sizeof k);
        TEST_ASSERT_EQUAL_HEX32(k.bits, bits_of(mpu6050_temp_c(k.raw)));
    }
    const uint8_t t[2] = {0xFD, 0xF7};  // TEMP_OUT_H, TEMP_OUT_L = -521
    TEST_ASSERT_EQUAL_INT16(-521, mpu6050_be16(t));
}

// ---- AVR cycles -------------------------------------------------------------------------------

#if defined(__AVR__)
static Bmp280Calib g_bmp;
static Ms5611Calib g_ms;
static volatile int32_t v_adc_T = 519888L, v_adc_P = 415148L, v_t_fine = 128422L;
static volatile uint32_t v_D1 = 9085466UL, v_D2 = 8569150UL, v_D1c = 6750566UL, v_D2c = 7304879UL;
static volatile int16_t v_count = -521;
static volatile uint8_t v_format = kAdxl345FullRes | 3;
static volatile uint32_t sink;
static volatile float fsink;
static uint16_t g_prom[8] = {0x3132, 0x3334, 0x3536, 0x3738, 0x3940, 0x4142, 0x4344, 0x450B};

static void bench_empty() { sink = static_cast<uint32_t>(v_adc_T) + static_cast<uint32_t>(v_t_fine); }
static void bench_bmp_T() {
    int32_t tf;
    sink = static_cast<uint32_t>(bmp280_compensate_T(g_bmp, v_adc_T, tf));
}
static void bench_bmp_P64() { sink = bmp280_compensate_P64(g_bmp, v_adc_P, v_t_fine); }
static void bench_bmp_P32() { sink = bmp280_compensate_P32(g_bmp, v_adc_P, v_t_fine); }
static void bench_ms_first() {
    Ms5611Result r;
    ms5611_compensate(g_ms, v_D1, v_D2, false, r);
    sink = static_cast<uint32_t>(r.P);
}
static void bench_ms_second_warm() {
    Ms5611Result r;
    ms5611_compensate(g_ms, v_D1, v_D2, true, r);
    sink = static_cast<uint32_t>(r.P);
}
static void bench_ms_second_cold() {
    Ms5611Result r;
    ms5611_compensate(g_ms, v_D1c, v_D2c, true, r);
    sink = static_cast<uint32_t>(r.P);
}
static void bench_ms_crc() { sink = ms5611_crc4(g_prom); }
static void bench_adxl() { fsink = adxl345_g(v_count, v_format); }
static void bench_mpu_g() { fsink = mpu6050_accel_g(v_count, 3); }
static void bench_mpu_temp() { fsink = mpu6050_temp_c(v_count); }

// Cycles of one call of fn with interrupts off: Timer1 at F_CPU/8 (coarse,
// reaches 524288 cycles) and at F_CPU (exact modulo 65536), combined.
static uint32_t cycles_of(void (*fn)()) {
    const uint8_t sreg = SREG;
    cli();
    const uint8_t a = TCCR1A, b = TCCR1B;
    TCCR1A = 0;
    uint16_t ticks[2];
    for (uint8_t pass = 0; pass < 2; ++pass) {
        TCCR1B = pass == 0 ? _BV(CS11) : _BV(CS10);
        TCNT1 = 0;
        const uint16_t t0 = TCNT1;
        fn();
        const uint16_t t1 = TCNT1;
        ticks[pass] = static_cast<uint16_t>(t1 - t0);
    }
    const uint16_t z0 = TCNT1;
    const uint16_t z1 = TCNT1;  // the two reads' own cost at F_CPU
    TCCR1B = b;
    TCCR1A = a;
    SREG = sreg;
    const uint32_t coarse = static_cast<uint32_t>(ticks[0]) * 8u;
    const uint16_t fine = static_cast<uint16_t>(ticks[1] - static_cast<uint16_t>(z1 - z0));
    const uint32_t k = (coarse + 32768u - fine) >> 16;
    return fine + (k << 16);
}

// `name` in flash.
static void print_cycles(const char* name, uint32_t c) {
    UnityPrint("cycles ");
    for (char ch; (ch = static_cast<char>(pgm_read_byte(name))) != 0; ++name) UNITY_OUTPUT_CHAR(ch);
    UNITY_OUTPUT_CHAR(' ');
    UnityPrintNumberUnsigned(c);
    UNITY_PRINT_EOL();
}

static void test_avr_cycles(void) {
    g_bmp = kBmpExample;
    g_ms = kMsExample;
    const uint32_t base = cycles_of(bench_empty);
    static const char n0[] PROGMEM = "bmp280_compensate_T";
    static const char n1[] PROGMEM = "bmp280_compensate_P64";
    static const char n2[] PROGMEM = "bmp280_compensate_P32";
    static const char n3[] PROGMEM = "ms5611_compensate(first order)";
    static const char n4[] PROGMEM = "ms5611_compensate(second order, 20.07 degC)";
    static const char n5[] PROGMEM = "ms5611_compensate(second order, -30 degC)";
    static const char n6[] PROGMEM = "ms5611_crc4";
    static const char n7[] PROGMEM = "adxl345_g";
    static const char n8[] PROGMEM = "mpu6050_accel_g";
    static const char n9[] PROGMEM = "mpu6050_temp_c";
    struct Bench {
        const char* name;
        void (*fn)();
    };
    const Bench kBench[] = {
        {n0, bench_bmp_T},
        {n1, bench_bmp_P64},
        {n2, bench_bmp_P32},
        {n3, bench_ms_first},
        {n4, bench_ms_second_warm},
        {n5, bench_ms_second_cold},
        {n6, bench_ms_crc},
        {n7, bench_adxl},
        {n8, bench_mpu_g},
        {n9, bench_mpu_temp},
    };
    for (size_t i = 0; i < sizeof kBench / sizeof kBench[0]; ++i) {
        const uint32_t c = cycles_of(kBench[i].fn);
        const uint32_t again = cycles_of(kBench[i].fn);
        TEST_ASSERT_EQUAL_UINT32(c, again);  // deterministic: same inputs, same path
        TEST_ASSERT_TRUE(c > base && c < 200000UL);
        print_cycles(kBench[i].name, c - base);
    }
    TEST_ASSERT_EQUAL_UINT32(25767233UL, sink = bmp280_compensate_P64(g_bmp, v_adc_P, v_t_fine));
    // The longest over the range vectors (division and multiplication
    // routines take data-dependent time).
    uint32_t worst[4] = {0, 0, 0, 0};
    for (size_t i = 0; i < sizeof kBmpVectors / sizeof kBmpVectors[0]; ++i) {
        BmpVector v;
        flash_read(&v, &kBmpVectors[i], sizeof v);
        v_adc_T = v.adc_T;
        v_adc_P = v.adc_P;
        v_t_fine = v.t_fine;
        const uint32_t c[3] = {cycles_of(bench_bmp_T), cycles_of(bench_bmp_P64), cycles_of(bench_bmp_P32)};
        for (uint8_t k = 0; k < 3; ++k) worst[k] = c[k] > worst[k] ? c[k] : worst[k];
    }
    for (size_t i = 0; i < sizeof kMsVectors / sizeof kMsVectors[0]; ++i) {
        MsVector v;
        flash_read(&v, &kMsVectors[i], sizeof v);
        v_D1c = v.D1;
        v_D2c = v.D2;
        const uint32_t c = cycles_of(bench_ms_second_cold);
        worst[3] = c > worst[3] ? c : worst[3];
    }
    static const char w0[] PROGMEM = "bmp280_compensate_T(worst of the range vectors)";
    static const char w1[] PROGMEM = "bmp280_compensate_P64(worst of the range vectors)";
    static const char w2[] PROGMEM = "bmp280_compensate_P32(worst of the range vectors)";
    static const char w3[] PROGMEM = "ms5611_compensate(second order, worst of the vectors)";
    const char* const wn[4] = {w0, w1, w2, w3};
    for (uint8_t k = 0; k < 4; ++k) print_cycles(wn[k], worst[k] - base);
}
#endif

static void run(void) {
    UNITY_BEGIN();
    RUN_TEST(test_bmp280_parse);
    RUN_TEST(test_bmp280_parse_refusals);
    RUN_TEST(test_bmp280_example_T);
    RUN_TEST(test_bmp280_example_P64);
    RUN_TEST(test_bmp280_example_P32);
    RUN_TEST(test_bmp280_zero_divisor);
    RUN_TEST(test_bmp280_range_vectors);
    RUN_TEST(test_bmp280_overflow_wraps);
    RUN_TEST(test_ms5611_example);
    RUN_TEST(test_ms5611_shifts_floor);
    RUN_TEST(test_ms5611_second_order_cold);
    RUN_TEST(test_ms5611_extremes);
    RUN_TEST(test_ms5611_crc4_an520);
    RUN_TEST(test_ms5611_parse_prom);
    RUN_TEST(test_adxl345_counts);
    RUN_TEST(test_adxl345_scale);
    RUN_TEST(test_mpu6050_accel);
    RUN_TEST(test_mpu6050_temp);
#if defined(__AVR__)
    RUN_TEST(test_avr_cycles);
#endif
    (void)UNITY_END();
}

FSW_TEST_MAIN(run)
