// Benchmark driver (not a test): steps the generated tank machine N times
// with the state script's inputs, so every step runs TankVentControl.
#include "fswkit.h"
#include "sv.gen.h"
#include "tank.gen.h"

#if defined(ARDUINO)
#include "cycle_report.h"
#else
#include <stdlib.h>
#endif

namespace {
uint64_t g = 0;
fsw::Real pressure = 600;

// The script's inputs before a step ...
void inputs() {
    fsw::store<uint64_t>(fsw_gen::sv + fsw_gen::E_time, g);
    fsw::write_F64(fsw_gen::sv + fsw_gen::E_tankPressure, pressure);
}

// ... and the plant after it: the open valve lowers the pressure.
void plant() {
    pressure += fsw_gen::sv[fsw_gen::E_valveOpen] ? -1 : 1;
    g += 10;
}
}  // namespace

#if defined(ARDUINO)
// Times each step with Timer1 counting CPU cycles; prints the average and
// the worst over `kSteps` steps, then ends the simulation.
static const uint16_t kSteps = 1000;
void setup() {
    Serial.begin(115200);
    TCCR1A = 0;
    TCCR1B = 1;  // Timer1 at the CPU clock
    uint32_t total = 0;
    uint16_t worst = 0;
    for (uint16_t i = 0; i < kSteps; ++i) {
        inputs();
        const uint16_t t0 = TCNT1;
        const fsw::Result r = fsw_gen::tank::step();
        const uint16_t dt = static_cast<uint16_t>(TCNT1 - t0);
        if (r != fsw::kOk) pressure = -1;
        plant();
        total += dt;
        if (dt > worst) worst = dt;
    }
    report_cycles(total / kSteps, worst, fsw_gen::sv[fsw_gen::E_state]);
}
void loop() {}
#else
int main(int argc, char** argv) {
    const unsigned long n = argc > 1 ? strtoul(argv[1], 0, 10) : 0;
    for (unsigned long i = 0; i < n; ++i) {
        inputs();
        if (fsw_gen::tank::step() != fsw::kOk) return 2;
        plant();
    }
    return fsw_gen::sv[fsw_gen::E_state] == 1 ? 0 : 1;  // still in TankVentControl
}
#endif
