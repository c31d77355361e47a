// accel_probe: the accelerometer drivers (fsw_accel.h) as an application
// runs them: the sleeping executor's cycle timer at 500 Hz, an ADXL345 at
// 0x53 (TWI), an ADXL345 on the SPI with its chip select on D9 (B1) and an
// MPU-6050 at 0x68, stepped once each per cycle, each flagging 5 unchanged
// readings in a row as stuck. (500 Hz, not 1 kHz: simavr shifts an SPI
// byte in 100 us, so the SPI driver's 9-byte burst takes about 0.9 ms of
// simulated time.) The host (tests/sim/test_baro_faults.py) reads `g_probe`
// from RAM while it sets the simulated parts' raw counts and failures.
#include "fswkit.h"

using namespace fsw;

struct Probe {
    uint8_t health[3];     // ADXL345 TWI, ADXL345 SPI, MPU-6050
    uint16_t faults[3];
    uint16_t readings[3];
    int16_t z[3];          // the last z counts
    uint32_t cycles;
};

extern "C" {
volatile Probe g_probe __attribute__((used));
}

static Adxl345 g_adxl(0x53, 0, 3, 0xC, 5);  // +-16 g, 400 Hz
static Adxl345 g_adxl_spi(9, 1, 3, 0xC, 5);
static Mpu6050 g_mpu(0x68, 3, 3, 5);        // +-16 g, DLPF 3: 1 kHz

extern "C" void setup() {
    pal::cycle_timer_begin(2000UL);
    sensors_begin(1, 1);
}

extern "C" void loop() {
    uint8_t skipped;
    if (pal::cycle_wait(skipped) == pal::kCycleNotDue) return;
    g_adxl.step();
    g_adxl_spi.step();
    g_mpu.step();
    volatile Probe& p = g_probe;
    const AccelDriver* d[3] = {&g_adxl, &g_adxl_spi, &g_mpu};
    for (uint8_t i = 0; i < 3; ++i) {
        p.health[i] = d[i]->health();
        p.faults[i] = d[i]->faults();
        p.readings[i] = d[i]->readings();
        p.z[i] = d[i]->counts(2);
    }
    p.cycles = p.cycles + 1u;
    pal::cycle_end();
}
