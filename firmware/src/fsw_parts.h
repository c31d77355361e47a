// Digital sensor parts: each part's data conversion exactly as its datasheet
// gives it (register bytes -> raw counts -> physical value), with the
// datasheet's own integer arithmetic, shifts and intermediate widths.
// No bus access here: callers hand in the bytes a bus driver read.
// docs/sensors.md lists the sources (datasheet names and sections), the
// units, the widths and the measured AVR cycles and flash of each routine.
//
// Integer rules common to every routine below:
// - `x >> n` on a signed value is an arithmetic shift (floor division by
//   2^n), as the datasheets' C code does with GCC and as TE's own worked
//   examples for the MS56xx family require (docs/sensors.md).
// - Where a datasheet's C left-shifts a signed value or multiplies signed
//   values, the operation is done here in two's-complement arithmetic of the
//   width the datasheet names (through the unsigned type of that width):
//   the same bits as the datasheet's expression whenever that expression is
//   defined, and a defined result (not undefined behaviour) when a corrupt
//   calibration would make it overflow. host-tools/fswkit/sim/parts.py
//   mirrors every step, wrap included.
#ifndef FSW_PARTS_H
#define FSW_PARTS_H

#include "fsw_types.h"

namespace fsw {

// ---- Bosch BMP280 (BST-BMP280-DS001) -------------------------------------------

// Trimming parameters, datasheet 3.11.2, Table 17: 16-bit words,
// little-endian (LSB at the lower address), registers 0x88..0x9F.
struct Bmp280Calib {
    uint16_t dig_T1;
    int16_t dig_T2, dig_T3;
    uint16_t dig_P1;
    int16_t dig_P2, dig_P3, dig_P4, dig_P5, dig_P6, dig_P7, dig_P8, dig_P9;
};

static const uint8_t kBmp280RegCalib = 0x88;  // calib00..calib23: 24 bytes
static const uint8_t kBmp280CalibLen = 24;
static const uint8_t kBmp280RegData = 0xF7;   // press_msb..temp_xlsb: 6 bytes (burst read, 3.9)
static const uint8_t kBmp280DataLen = 6;
static const uint8_t kBmp280RegId = 0xD0;
static const uint8_t kBmp280ChipId = 0x58;
// The value of adc_P / adc_T when the measurement is skipped (oversampling
// x0): datasheet 3.3.2/3.3.3 and 4.3.6/4.3.7 reset state.
static const int32_t kBmp280AdcSkipped = 0x80000L;

// The 24 bytes of 0x88..0x9F into `c`. kErrFault (c still filled) when the
// words cannot be a part's: dig_T1 or dig_P1 zero (the pressure formula would
// divide by zero; a bus reading all zeros) or all 24 bytes 0xFF (an open bus).
FSW_MUST_CHECK Result bmp280_parse_calib(const uint8_t* bytes24, Bmp280Calib& c);

// The 20-bit raw values from the 6 bytes of 0xF7..0xFC (datasheet 3.9,
// 4.3.6, 4.3.7): adc = msb << 12 | lsb << 4 | xlsb >> 4; each 0..0xFFFFF.
void bmp280_parse_raw(const uint8_t* bytes6, int32_t& adc_P, int32_t& adc_T);

// Temperature in 0.01 degC (2508 = 25.08 degC), datasheet 3.11.3
// bmp280_compensate_T_int32 (32-bit signed throughout); `t_fine` receives
// the fine temperature the pressure formulas take.
int32_t bmp280_compensate_T(const Bmp280Calib& c, int32_t adc_T, int32_t& t_fine);

// Pressure in Pa as unsigned Q24.8 (25767233 = 100653.25 Pa), datasheet
// 3.11.3 bmp280_compensate_P_int64 (64-bit signed intermediates); 0 where the
// datasheet's divisor is 0. The most accurate; slow on an 8-bit MCU
// (64-bit division in software, docs/sensors.md).
uint32_t bmp280_compensate_P64(const Bmp280Calib& c, int32_t adc_P, int32_t t_fine);

// Pressure in whole Pa (100653), datasheet 8.2 bmp280_compensate_P_int32
// (32-bit intermediates; typically 1 Pa 1-sigma from the 64-bit result, per
// 8.2); 0 where the datasheet's divisor is 0.
uint32_t bmp280_compensate_P32(const Bmp280Calib& c, int32_t adc_P, int32_t t_fine);

// ---- TE Connectivity MS5611-01BA03 (datasheet, "Pressure and temperature
// calculation"; PROM CRC: application note AN520) -------------------------------

// C1..C6: PROM words 1..6 (16-bit unsigned, read big-endian with commands
// 0xA2..0xAC). Word 0 is the factory's, word 7's low 4 bits the CRC.
struct Ms5611Calib {
    uint16_t C1, C2, C3, C4, C5, C6;
};

static const uint8_t kMs5611CmdReset = 0x1E;
static const uint8_t kMs5611CmdD1 = 0x40;      // + 2 * OSR index (0..4: OSR 256..4096)
static const uint8_t kMs5611CmdD2 = 0x50;      // + 2 * OSR index
static const uint8_t kMs5611CmdAdcRead = 0x00; // 24 bits, MSB first
static const uint8_t kMs5611CmdProm = 0xA0;    // + 2 * word (0..7)

// CRC-4 of the 8 PROM words as AN520 computes it (polynomial 0x3000 on a
// 16-bit remainder, the low byte of word 7 taken as zero): 0..15.
uint8_t ms5611_crc4(const uint16_t* words8);

// Checks the PROM (8 words as read: word 0 .. word 7) and takes C1..C6.
// kErrFault (c left unchanged) on a CRC mismatch, or when all 8 words are
// 0x0000 or all 0xFFFF (a dead bus; an all-zero PROM passes AN520's CRC).
FSW_MUST_CHECK Result ms5611_parse_prom(const uint16_t* words8, Ms5611Calib& c);
// The same from the 16 bytes of the 8 PROM reads (each word MSB first).
FSW_MUST_CHECK Result ms5611_parse_prom_bytes(const uint8_t* bytes16, Ms5611Calib& c);

// D1 or D2 from the 3 bytes of an ADC read (MSB first): 0..0xFFFFFF.
uint32_t ms5611_parse_adc(const uint8_t* bytes3);

// Every intermediate of the datasheet's flow, with its recommended type.
struct Ms5611Result {
    int32_t dT;     // D2 - C5 * 2^8                                 (signed int 32)
    int32_t TEMP;   // 0.01 degC: 2000 + dT * C6 / 2^23 (- T2)       (signed int 32)
    int64_t OFF;    // C2 * 2^16 + (C4 * dT) / 2^7 (- OFF2)          (signed int 64)
    int64_t SENS;   // C1 * 2^15 + (C3 * dT) / 2^8 (- SENS2)         (signed int 64)
    int32_t P;      // 0.01 mbar: (D1 * SENS / 2^21 - OFF) / 2^15    (signed int 32)
    int32_t T2;     // second order (0 at or above 20 degC, or when not applied)
    int64_t OFF2, SENS2;
};

// First-order compensation (`second_order` false), or with the datasheet's
// second-order temperature compensation (TEMP < 20 degC, < -15 degC) applied
// to TEMP, OFF and SENS before P. D1 and D2 are 24-bit (higher bits ignored).
// For any C1..C6 and 24-bit D1, D2 no intermediate overflows its type.
void ms5611_compensate(const Ms5611Calib& c, uint32_t D1, uint32_t D2, bool second_order, Ms5611Result& r);

// ---- Analog Devices ADXL345 (data sheet Rev. G) ---------------------------------

static const uint8_t kAdxl345RegDevId = 0x00;
static const uint8_t kAdxl345DevId = 0xE5;
static const uint8_t kAdxl345RegDataFormat = 0x31;
static const uint8_t kAdxl345RegData = 0x32;  // DATAX0, DATAX1, DATAY0, DATAY1, DATAZ0, DATAZ1
// DATA_FORMAT (0x31) bits.
static const uint8_t kAdxl345SelfTest = 0x80;
static const uint8_t kAdxl345Spi3Wire = 0x40;
static const uint8_t kAdxl345IntInvert = 0x20;
static const uint8_t kAdxl345FullRes = 0x08;
static const uint8_t kAdxl345Justify = 0x04;  // 1: left-justified (MSB) mode
static const uint8_t kAdxl345RangeMask = 0x03;  // 0: +-2 g, 1: +-4 g, 2: +-8 g, 3: +-16 g

// Output bits for a DATA_FORMAT value: 10 in 10-bit mode, 10 + range in full
// resolution (13 at +-16 g).
uint8_t adxl345_bits(uint8_t data_format);
// Counts (sign-extended, right-justified) of X, Y, Z from DATAX0..DATAZ1
// (little-endian two's complement), whichever justification DATA_FORMAT sets.
void adxl345_counts(const uint8_t* bytes6, uint8_t data_format, int16_t* xyz);
// g per count as binary32, a power of two: the data sheet's typical scale
// factor 3.9 mg/LSB = 1/256 g at +-2 g (Table 1: 256 LSB/g typ.), which full
// resolution keeps at every range, and 2^range / 256 g in 10-bit mode (128,
// 64, 32 LSB/g). The register description's "4 mg/LSB" is the nominal
// rounding of the same value. Exact: count * scale rounds nothing.
float adxl345_g_per_count(uint8_t data_format);
float adxl345_g(int16_t count, uint8_t data_format);

// ---- InvenSense MPU-6000/MPU-6050 (Register Map and Descriptions RM-MPU-6000A) ----

static const uint8_t kMpu6050RegAccelConfig = 0x1C;  // AFS_SEL in bits 4:3
static const uint8_t kMpu6050RegAccel = 0x3B;        // ACCEL_XOUT_H .. ACCEL_ZOUT_L
static const uint8_t kMpu6050RegTemp = 0x41;         // TEMP_OUT_H, TEMP_OUT_L
static const uint8_t kMpu6050RegWhoAmI = 0x75;
static const uint8_t kMpu6050WhoAmI = 0x68;

// AFS_SEL (0..3) from an ACCEL_CONFIG value.
inline uint8_t mpu6050_afs_sel(uint8_t accel_config) { return static_cast<uint8_t>((accel_config >> 3) & 3u); }
// A big-endian 16-bit two's complement register pair (H at the lower address).
inline int16_t mpu6050_be16(const uint8_t* b) {
    return static_cast<int16_t>(static_cast<uint16_t>(static_cast<uint16_t>(b[0]) << 8 | b[1]));
}
// Counts of X, Y, Z from ACCEL_XOUT_H..ACCEL_ZOUT_L (6 bytes).
void mpu6050_accel_counts(const uint8_t* bytes6, int16_t* xyz);
// g per count: 1/16384, 1/8192, 1/4096, 1/2048 for AFS_SEL 0..3 (register
// map 4.17): powers of two, so the conversion is exact in binary32.
float mpu6050_g_per_count(uint8_t afs_sel);
float mpu6050_accel_g(int16_t count, uint8_t afs_sel);
// degC = TEMP_OUT / 340 + 36.53 (register map 4.18), in binary32 in this
// order: the quotient rounded, then the sum rounded.
float mpu6050_temp_c(int16_t temp_out);

}  // namespace fsw

#endif  // FSW_PARTS_H
