// Digital sensor parts' data conversion, written from each datasheet's text
// (fsw_parts.h; docs/sensors.md). Every expression below keeps the
// datasheet's order of operations, shifts and intermediate widths; comments
// cite the section. Signed multiplications and left shifts go through the
// unsigned type of the datasheet's width (two's complement wrap: the
// datasheet's bits wherever its C is defined, fsw_parts.h), signed right
// shifts are arithmetic (GCC, on every target the kit builds for).
#include "fsw_parts.h"

#include "fsw_convert.h"

namespace fsw {

namespace {

// 32-bit two's-complement operations (BMP280_S32_t arithmetic).
inline int32_t w32(uint32_t u) { return static_cast<int32_t>(u); }  // modulo 2^32 (GCC)
inline int32_t mul32(int32_t a, int32_t b) { return w32(static_cast<uint32_t>(a) * static_cast<uint32_t>(b)); }
inline int32_t add32(int32_t a, int32_t b) { return w32(static_cast<uint32_t>(a) + static_cast<uint32_t>(b)); }
inline int32_t sub32(int32_t a, int32_t b) { return w32(static_cast<uint32_t>(a) - static_cast<uint32_t>(b)); }
inline int32_t shl32(int32_t a, unsigned n) { return w32(static_cast<uint32_t>(a) << n); }

// 64-bit two's-complement operations (BMP280_S64_t arithmetic).
inline int64_t w64(uint64_t u) { return static_cast<int64_t>(u); }
inline int64_t mul64(int64_t a, int64_t b) { return w64(static_cast<uint64_t>(a) * static_cast<uint64_t>(b)); }
inline int64_t add64(int64_t a, int64_t b) { return w64(static_cast<uint64_t>(a) + static_cast<uint64_t>(b)); }
inline int64_t sub64(int64_t a, int64_t b) { return w64(static_cast<uint64_t>(a) - static_cast<uint64_t>(b)); }
inline int64_t shl64(int64_t a, unsigned n) { return w64(static_cast<uint64_t>(a) << n); }
// C's signed division (truncation toward zero); INT64_MIN / -1 wraps to
// INT64_MIN instead of trapping. The caller has excluded a zero divisor.
inline int64_t div64(int64_t n, int64_t d) {
    if (d == -1) return w64(0u - static_cast<uint64_t>(n));
    return n / d;
}

inline uint16_t le16(const uint8_t* b) { return static_cast<uint16_t>(b[0] | static_cast<uint16_t>(b[1]) << 8); }
inline int16_t le16s(const uint8_t* b) { return static_cast<int16_t>(le16(b)); }

}  // namespace

// ---- BMP280 ----------------------------------------------------------------------

// Datasheet 3.11.2, Table 17: 0x88/0x89 dig_T1 unsigned short, 0x8A dig_T2
// signed short, ... 0x8E dig_P1 unsigned short, 0x90..0x9E dig_P2..dig_P9
// signed short; LSB first.
Result bmp280_parse_calib(const uint8_t* b, Bmp280Calib& c) {
    c.dig_T1 = le16(b + 0);
    c.dig_T2 = le16s(b + 2);
    c.dig_T3 = le16s(b + 4);
    c.dig_P1 = le16(b + 6);
    c.dig_P2 = le16s(b + 8);
    c.dig_P3 = le16s(b + 10);
    c.dig_P4 = le16s(b + 12);
    c.dig_P5 = le16s(b + 14);
    c.dig_P6 = le16s(b + 16);
    c.dig_P7 = le16s(b + 18);
    c.dig_P8 = le16s(b + 20);
    c.dig_P9 = le16s(b + 22);
    uint8_t all = 0xFF;
    for (uint8_t i = 0; i < kBmp280CalibLen; ++i) all &= b[i];
    return (c.dig_T1 == 0 || c.dig_P1 == 0 || all == 0xFF) ? kErrFault : kOk;
}

// Datasheet 3.9 / 4.3.6 / 4.3.7: press_msb [19:12], press_lsb [11:4],
// press_xlsb [7:4] = bits [3:0]; the same for temp.
void bmp280_parse_raw(const uint8_t* b, int32_t& adc_P, int32_t& adc_T) {
    adc_P = static_cast<int32_t>(static_cast<uint32_t>(b[0]) << 12 | static_cast<uint32_t>(b[1]) << 4 | b[2] >> 4);
    adc_T = static_cast<int32_t>(static_cast<uint32_t>(b[3]) << 12 | static_cast<uint32_t>(b[4]) << 4 | b[5] >> 4);
}

// Datasheet 3.11.3, bmp280_compensate_T_int32 (rev. 1.1), all BMP280_S32_t:
//   var1 = ((((adc_T>>3) - ((S32)dig_T1<<1))) * ((S32)dig_T2)) >> 11;
//   var2 = (((((adc_T>>4) - ((S32)dig_T1)) * ((adc_T>>4) - ((S32)dig_T1))) >> 12) * ((S32)dig_T3)) >> 14;
//   t_fine = var1 + var2;
//   T = (t_fine * 5 + 128) >> 8;
int32_t bmp280_compensate_T(const Bmp280Calib& c, int32_t adc_T, int32_t& t_fine) {
    const int32_t T1 = c.dig_T1, T2 = c.dig_T2, T3 = c.dig_T3;
    const int32_t var1 = mul32(sub32(adc_T >> 3, shl32(T1, 1)), T2) >> 11;
    const int32_t d = sub32(adc_T >> 4, T1);
    const int32_t var2 = mul32(mul32(d, d) >> 12, T3) >> 14;
    t_fine = add32(var1, var2);
    return add32(mul32(t_fine, 5), 128) >> 8;
}

// Datasheet 3.11.3, bmp280_compensate_P_int64 (rev. 1.1), BMP280_S64_t:
//   var1 = ((S64)t_fine) - 128000;
//   var2 = var1 * var1 * (S64)dig_P6;
//   var2 = var2 + ((var1*(S64)dig_P5)<<17);
//   var2 = var2 + (((S64)dig_P4)<<35);
//   var1 = ((var1 * var1 * (S64)dig_P3)>>8) + ((var1 * (S64)dig_P2)<<12);
//   var1 = (((((S64)1)<<47)+var1))*((S64)dig_P1)>>33;
//   if (var1 == 0) return 0;
//   p = 1048576-adc_P;
//   p = (((p<<31)-var2)*3125)/var1;
//   var1 = (((S64)dig_P9) * (p>>13) * (p>>13)) >> 25;
//   var2 = (((S64)dig_P8) * p) >> 19;
//   p = ((p + var1 + var2) >> 8) + (((S64)dig_P7)<<4);
//   return (U32)p;
uint32_t bmp280_compensate_P64(const Bmp280Calib& c, int32_t adc_P, int32_t t_fine) {
    int64_t var1 = static_cast<int64_t>(t_fine) - 128000;
    int64_t var2 = mul64(mul64(var1, var1), c.dig_P6);
    var2 = add64(var2, shl64(mul64(var1, c.dig_P5), 17));
    var2 = add64(var2, shl64(c.dig_P4, 35));
    var1 = add64(mul64(mul64(var1, var1), c.dig_P3) >> 8, shl64(mul64(var1, c.dig_P2), 12));
    var1 = mul64(add64(static_cast<int64_t>(1) << 47, var1), static_cast<int64_t>(c.dig_P1)) >> 33;
    if (var1 == 0) return 0;  // the datasheet's guard against division by zero
    int64_t p = 1048576 - static_cast<int64_t>(adc_P);
    p = div64(mul64(sub64(shl64(p, 31), var2), 3125), var1);
    var1 = mul64(mul64(c.dig_P9, p >> 13), p >> 13) >> 25;
    var2 = mul64(c.dig_P8, p) >> 19;
    p = add64(add64(add64(p, var1), var2) >> 8, shl64(c.dig_P7, 4));
    return static_cast<uint32_t>(static_cast<uint64_t>(p));
}

// Datasheet 8.2, bmp280_compensate_P_int32 (BMP280_S32_t var1, var2;
// BMP280_U32_t p):
//   var1 = (((S32)t_fine)>>1) - (S32)64000;
//   var2 = (((var1>>2) * (var1>>2)) >> 11 ) * ((S32)dig_P6);
//   var2 = var2 + ((var1*((S32)dig_P5))<<1);
//   var2 = (var2>>2)+(((S32)dig_P4)<<16);
//   var1 = (((dig_P3 * (((var1>>2) * (var1>>2)) >> 13 )) >> 3) + ((((S32)dig_P2) * var1)>>1))>>18;
//   var1 =((((32768+var1))*((S32)dig_P1))>>15);
//   if (var1 == 0) return 0;
//   p = (((U32)(((S32)1048576)-adc_P)-(var2>>12)))*3125;
//   if (p < 0x80000000) p = (p << 1) / ((U32)var1);
//   else                p = (p / (U32)var1) * 2;
//   var1 = (((S32)dig_P9) * ((S32)(((p>>3) * (p>>3))>>13)))>>12;
//   var2 = (((S32)(p>>2)) * ((S32)dig_P8))>>13;
//   p = (U32)((S32)p + ((var1 + var2 + dig_P7) >> 4));
uint32_t bmp280_compensate_P32(const Bmp280Calib& c, int32_t adc_P, int32_t t_fine) {
    int32_t var1 = sub32(t_fine >> 1, 64000);
    const int32_t q = var1 >> 2;
    const int32_t qq = mul32(q, q);
    int32_t var2 = mul32(qq >> 11, c.dig_P6);
    var2 = add32(var2, shl32(mul32(var1, c.dig_P5), 1));
    var2 = add32(var2 >> 2, shl32(c.dig_P4, 16));
    var1 = add32(mul32(c.dig_P3, qq >> 13) >> 3, mul32(c.dig_P2, var1) >> 1) >> 18;
    var1 = mul32(add32(32768, var1), static_cast<int32_t>(c.dig_P1)) >> 15;
    if (var1 == 0) return 0;  // the datasheet's guard against division by zero
    uint32_t p = (static_cast<uint32_t>(sub32(1048576, adc_P)) - static_cast<uint32_t>(var2 >> 12)) * 3125u;
    if (p < 0x80000000UL) {
        p = (p << 1) / static_cast<uint32_t>(var1);
    } else {
        p = (p / static_cast<uint32_t>(var1)) * 2u;
    }
    var1 = mul32(c.dig_P9, w32(((p >> 3) * (p >> 3)) >> 13)) >> 12;
    var2 = mul32(w32(p >> 2), c.dig_P8) >> 13;
    return static_cast<uint32_t>(add32(w32(p), add32(add32(var1, var2), c.dig_P7) >> 4));
}

// ---- MS5611-01BA03 ------------------------------------------------------------------

// AN520 crc4(): n_rem = 0; word 7's low byte replaced by 0; for each of the
// 16 bytes, MSB of each word first: n_rem ^= byte, then 8 times
// n_rem = (n_rem & 0x8000) ? (n_rem << 1) ^ 0x3000 : n_rem << 1 (16 bits);
// the CRC is (n_rem >> 12) & 0xF.
uint8_t ms5611_crc4(const uint16_t* w) {
    uint16_t rem = 0;
    for (uint8_t i = 0; i < 16; ++i) {
        uint16_t word = w[i >> 1];
        if (i == 14 || i == 15) word &= 0xFF00u;
        rem ^= (i & 1u) ? static_cast<uint16_t>(word & 0x00FFu) : static_cast<uint16_t>(word >> 8);
        for (uint8_t bit = 0; bit < 8; ++bit) {
            rem = (rem & 0x8000u) ? static_cast<uint16_t>((rem << 1) ^ 0x3000u) : static_cast<uint16_t>(rem << 1);
        }
    }
    return static_cast<uint8_t>((rem >> 12) & 0x0Fu);
}

Result ms5611_parse_prom(const uint16_t* w, Ms5611Calib& c) {
    uint16_t any = 0, all = 0xFFFFu;
    for (uint8_t i = 0; i < 8; ++i) {
        any |= w[i];
        all &= w[i];
    }
    if (any == 0 || all == 0xFFFFu) return kErrFault;
    if (ms5611_crc4(w) != (w[7] & 0x000Fu)) return kErrFault;
    c.C1 = w[1];
    c.C2 = w[2];
    c.C3 = w[3];
    c.C4 = w[4];
    c.C5 = w[5];
    c.C6 = w[6];
    return kOk;
}

Result ms5611_parse_prom_bytes(const uint8_t* b, Ms5611Calib& c) {
    uint16_t w[8];
    for (uint8_t i = 0; i < 8; ++i) w[i] = static_cast<uint16_t>(static_cast<uint16_t>(b[2 * i]) << 8 | b[2 * i + 1]);
    return ms5611_parse_prom(w, c);
}

uint32_t ms5611_parse_adc(const uint8_t* b) {
    return static_cast<uint32_t>(b[0]) << 16 | static_cast<uint32_t>(b[1]) << 8 | b[2];
}

// Datasheet "Pressure and temperature calculation" (figure: flow chart and
// the table of variables with their recommended types and maximal sizes):
//   dT   = D2 - C5 * 2^8                      signed int 32 (25 bits)
//   TEMP = 2000 + dT * C6 / 2^23              signed int 32 (41-bit intermediate)
//   OFF  = C2 * 2^16 + (C4 * dT) / 2^7        signed int 64 (41 bits)
//   SENS = C1 * 2^15 + (C3 * dT) / 2^8        signed int 64 (41 bits)
//   P    = (D1 * SENS / 2^21 - OFF) / 2^15    signed int 32 (58-bit intermediate)
// and "Second order temperature compensation" (flow chart):
//   TEMP < 20 degC:   T2 = dT^2 / 2^31; OFF2 = 5 (TEMP - 2000)^2 / 2; SENS2 = 5 (TEMP - 2000)^2 / 4
//   TEMP < -15 degC:  OFF2 += 7 (TEMP + 1500)^2; SENS2 += 11 (TEMP + 1500)^2 / 2
//   TEMP >= 20 degC:  T2 = OFF2 = SENS2 = 0
//   TEMP -= T2; OFF -= OFF2; SENS -= SENS2   (then P from OFF and SENS)
// The divisions by 2^n are arithmetic right shifts (floor), as TE's worked
// examples with a negative dT require (docs/sensors.md). Bounds for any
// 16-bit C and 24-bit D: |dT| < 2^24, |dT * C6| < 2^40, |SENS| < 2^38,
// |D1 * SENS| < 2^62: nothing overflows.
void ms5611_compensate(const Ms5611Calib& c, uint32_t D1, uint32_t D2, bool second_order, Ms5611Result& r) {
    D1 &= 0xFFFFFFUL;
    D2 &= 0xFFFFFFUL;
    const int32_t dT = static_cast<int32_t>(D2) - (static_cast<int32_t>(c.C5) << 8);
    int32_t TEMP = 2000 + static_cast<int32_t>((static_cast<int64_t>(dT) * c.C6) >> 23);
    int64_t OFF = (static_cast<int64_t>(c.C2) << 16) + ((static_cast<int64_t>(c.C4) * dT) >> 7);
    int64_t SENS = (static_cast<int64_t>(c.C1) << 15) + ((static_cast<int64_t>(c.C3) * dT) >> 8);
    int32_t T2 = 0;
    int64_t OFF2 = 0, SENS2 = 0;
    if (second_order && TEMP < 2000) {
        T2 = static_cast<int32_t>((static_cast<int64_t>(dT) * dT) >> 31);
        const int64_t lo = static_cast<int64_t>(TEMP - 2000) * (TEMP - 2000);
        OFF2 = (5 * lo) >> 1;
        SENS2 = (5 * lo) >> 2;
        if (TEMP < -1500) {
            const int64_t vlo = static_cast<int64_t>(TEMP + 1500) * (TEMP + 1500);
            OFF2 = OFF2 + 7 * vlo;
            SENS2 = SENS2 + ((11 * vlo) >> 1);
        }
        TEMP -= T2;
        OFF -= OFF2;
        SENS -= SENS2;
    }
    r.dT = dT;
    r.TEMP = TEMP;
    r.OFF = OFF;
    r.SENS = SENS;
    r.P = static_cast<int32_t>((((static_cast<int64_t>(D1) * SENS) >> 21) - OFF) >> 15);
    r.T2 = T2;
    r.OFF2 = OFF2;
    r.SENS2 = SENS2;
}

// ---- ADXL345 -------------------------------------------------------------------------

// Data sheet, Register 0x31 DATA_FORMAT: FULL_RES 1 = resolution grows with
// the range (10 bits at +-2 g .. 13 bits at +-16 g), 0 = 10-bit mode;
// Justify 1 = left-justified (MSB) mode, 0 = right-justified with sign
// extension. Registers 0x32..0x37: DATAX0 (LSB), DATAX1 (MSB), ...
uint8_t adxl345_bits(uint8_t data_format) {
    return static_cast<uint8_t>((data_format & kAdxl345FullRes) ? 10u + (data_format & kAdxl345RangeMask) : 10u);
}

void adxl345_counts(const uint8_t* b, uint8_t data_format, int16_t* xyz) {
    const uint8_t shift = (data_format & kAdxl345Justify) ? static_cast<uint8_t>(16u - adxl345_bits(data_format)) : 0u;
    for (uint8_t i = 0; i < 3; ++i) xyz[i] = static_cast<int16_t>(le16s(b + 2 * i) >> shift);
}

// Table 1, sensitivity at XOUT, YOUT, ZOUT: +-2 g 10-bit and every range in
// full resolution 256 LSB/g typ. (scale factor 3.9 mg/LSB typ.), +-4 g 128,
// +-8 g 64, +-16 g 32 LSB/g: 2^-8 g times 2^range in 10-bit mode.
float adxl345_g_per_count(uint8_t data_format) {
    static const float kScale[4] FSW_FLASH = {0.00390625f, 0.0078125f, 0.015625f, 0.03125f};  // 2^-8 .. 2^-5
    float s;
    flash_read(&s, &kScale[(data_format & kAdxl345FullRes) ? 0 : data_format & kAdxl345RangeMask], sizeof s);
    return s;
}

float adxl345_g(int16_t count, uint8_t data_format) {
    return f32_from_i32(count) * adxl345_g_per_count(data_format);
}

// ---- MPU-6050 ---------------------------------------------------------------------------

void mpu6050_accel_counts(const uint8_t* b, int16_t* xyz) {
    for (uint8_t i = 0; i < 3; ++i) xyz[i] = mpu6050_be16(b + 2 * i);
}

// Register map 4.17 (ACCEL_XOUT..ACCEL_ZOUT), AFS_SEL 0..3: 16384, 8192,
// 4096, 2048 LSB/g.
float mpu6050_g_per_count(uint8_t afs_sel) {
    static const float kScale[4] FSW_FLASH = {6.103515625e-05f, 0.0001220703125f, 0.000244140625f,
                                              0.00048828125f};  // 2^-14 .. 2^-11
    float s;
    flash_read(&s, &kScale[afs_sel & 3u], sizeof s);
    return s;
}

float mpu6050_accel_g(int16_t count, uint8_t afs_sel) {
    return f32_from_i32(count) * mpu6050_g_per_count(afs_sel);
}

// Register map 4.18: Temperature in degrees C = (TEMP_OUT Register Value as
// a signed quantity)/340 + 36.53.
float mpu6050_temp_c(int16_t temp_out) {
    return f32_from_i32(temp_out) / 340.0f + 36.53f;
}

}  // namespace fsw
