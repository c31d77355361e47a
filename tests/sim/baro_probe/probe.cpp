// baro_probe: the barometer drivers (fsw_baro.h) on the interrupt-driven TWI
// (fsw_twi.h) as an application runs them: the sleeping executor's cycle
// timer at 1 kHz, a BMP280 at 0x76 (x1/x1, forced) and an MS5611 at 0x77
// (OSR 1024) stepped once each per cycle, both flagging 5 unchanged
// conversions in a row as stuck. The host (tests/sim/test_baro_faults.py)
// reads `g_probe` from RAM (SimBoard.symbol / peek) while it sets the
// simulated parts' raw counts and failures mid-run. Linked against the
// suites' libfswkit.a and Arduino core (mk/firmware.mk).
#include "fswkit.h"

using namespace fsw;

struct Probe {
    uint8_t bmp_health, ms_health;
    uint16_t bmp_faults, ms_faults, bmp_readings, ms_readings;
    int32_t bmp_temp_centi, ms_temp_centi;
    uint32_t bmp_p_q8;
    int32_t ms_p;
    uint32_t cycles;           // executor cycles run
    uint16_t worst_bmp_us, worst_ms_us;  // longest step of each driver (micros32)
    uint16_t worst_cycle_us;   // longest cycle's busy time (both steps)
    TwiCounters twi;           // the bus's transactions and failures
};

extern "C" {
volatile Probe g_probe __attribute__((used));
}

static Bmp280 g_bmp(0x76, 1, 1, 5);
static Ms5611 g_ms(0x77, 2, 5);

static inline uint16_t clamp16(uint32_t v) { return v > 0xFFFFu ? 0xFFFFu : static_cast<uint16_t>(v); }

extern "C" void setup() {
    pal::cycle_timer_begin(1000UL);
    twi_begin(400000UL);
}

extern "C" void loop() {
    uint8_t skipped;
    if (pal::cycle_wait(skipped) == pal::kCycleNotDue) return;
    const uint32_t t0 = pal::micros32();
    g_bmp.step();
    const uint32_t t1 = pal::micros32();
    g_ms.step();
    const uint32_t t2 = pal::micros32();
    volatile Probe& p = g_probe;
    if (clamp16(t1 - t0) > p.worst_bmp_us) p.worst_bmp_us = clamp16(t1 - t0);
    if (clamp16(t2 - t1) > p.worst_ms_us) p.worst_ms_us = clamp16(t2 - t1);
    if (clamp16(t2 - t0) > p.worst_cycle_us) p.worst_cycle_us = clamp16(t2 - t0);
    p.bmp_health = g_bmp.health();
    p.ms_health = g_ms.health();
    p.bmp_faults = g_bmp.faults();
    p.ms_faults = g_ms.faults();
    p.bmp_readings = g_bmp.readings();
    p.ms_readings = g_ms.readings();
    p.bmp_temp_centi = g_bmp.temp_centi();
    p.ms_temp_centi = g_ms.temp_centi();
    p.bmp_p_q8 = g_bmp.pressure_q24_8();
    p.ms_p = g_ms.pressure_int();
    const TwiCounters c = twi_counters();
    p.twi.transactions = c.transactions;
    p.twi.nack_addr = c.nack_addr;
    p.twi.nack_data = c.nack_data;
    p.twi.bus_error = c.bus_error;
    p.twi.timeout = c.timeout;
    p.cycles = p.cycles + 1u;
    pal::cycle_end();
}
