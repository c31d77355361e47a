// Footprint probe (not a test): a sketch that starts the sensor buses and
// steps one driver from loop(), its readings stored where the optimiser
// cannot drop them. FSW_SENSOR: 0 nothing, 1 the TWI master alone (the
// buses started, a transaction started and polled), 2 BMP280, 3 MS5611,
// 4 ADXL345 on the TWI, 5 ADXL345 on the SPI, 6 MPU-6050. The difference
// between two builds is what a driver adds (tools/bench_firmware.py sensors).
#include <Arduino.h>

#include "fswkit.h"

volatile float g_out[3];
volatile uint8_t g_health;

#if FSW_SENSOR == 2
static fsw::Bmp280 g_drv(0x76, 1, 3, 50, 3);
#elif FSW_SENSOR == 3
static fsw::Ms5611 g_drv(0x77, 2, 50, 3);
#elif FSW_SENSOR == 4
static fsw::Adxl345 g_drv(0x53, 0, 3, 0xC, 50, 3);
#elif FSW_SENSOR == 5
static fsw::Adxl345 g_drv(9, 1, 3, 0xC, 50, 3);
#elif FSW_SENSOR == 6
static fsw::Mpu6050 g_drv(0x68, 3, 3, 50, 3);
#endif

void setup() {
#if FSW_SENSOR >= 1
    fsw::sensors_begin(1, FSW_SENSOR == 5 ? 1 : 0);
#endif
}

void loop() {
#if FSW_SENSOR == 1
    static uint8_t r[2];
    static volatile uint8_t st;
    const uint8_t reg = 0xD0;
    if (!fsw::twi_busy()) (void)fsw::twi_start(0x76, &reg, 1, r, 2, &st);
    g_health = static_cast<uint8_t>(r[0] + st);
#elif FSW_SENSOR >= 2
    g_drv.step();
    g_health = g_drv.health();
#if FSW_SENSOR <= 3
    g_out[0] = g_drv.pressure_pa();
    g_out[1] = g_drv.temp_c();
#else
    g_out[0] = g_drv.x_g();
    g_out[1] = g_drv.y_g();
    g_out[2] = g_drv.z_g();
#endif
#endif
}
