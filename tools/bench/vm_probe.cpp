// Footprint and timing probe for the bytecode VM (not a test): the tank
// machine stepped as generated code (FSW_VM_PROBE=1) or as its image through
// fsw::vm_step (2); 0 is the empty sketch. With FSW_VM_TIMING it times 1000
// steps on Timer1 and prints them as tools/bench/tank_driver.cpp does.
#include <Arduino.h>
#include "cycle_report.h"

#include "fswkit.h"
#include "sv.gen.h"
#if FSW_VM_PROBE == 1
#include "tank.gen.h"
#elif FSW_VM_PROBE == 2
#include "tank_image.h"  // kImage, kElems, kElemCount (tools/bench_vm.py writes it)
namespace {
alignas(fsw::kVmRamAlign) uint8_t ram[kRam];
fsw::Machine machine;
const fsw::VmLayout kLayout = {kElems, kElemCount, fsw_gen::kSchemaHash};
}  // namespace
#endif

namespace {
fsw::Result step() {
#if FSW_VM_PROBE == 1
    return fsw_gen::tank::step();
#elif FSW_VM_PROBE == 2
    return fsw::vm_step(kImage, kLayout, fsw_gen::sv, ram, machine);
#else
    return fsw::kOk;
#endif
}
uint64_t g = 0;
fsw::Real pressure = 600;
}  // namespace

void setup() {
#if FSW_VM_PROBE == 2
    // What a loader does once an image has arrived: verify, then reset.
    if (fsw::vm_verify(kImage, sizeof kImage, kLayout, sizeof ram) != fsw::kVmOk) digitalWrite(13, HIGH);
    fsw::vm_reset(kImage, ram, machine, 1);
#endif
#if FSW_VM_TIMING
    Serial.begin(115200);
    TCCR1A = 0;
    TCCR1B = 1;
    uint32_t total = 0;
    uint16_t worst = 0;
    for (uint16_t i = 0; i < 1000; ++i) {
        fsw::store<uint64_t>(fsw_gen::sv + fsw_gen::E_time, g);
        fsw::write_F64(fsw_gen::sv + fsw_gen::E_tankPressure, pressure);
        const uint16_t t0 = TCNT1;
        const fsw::Result r = step();
        const uint16_t dt = static_cast<uint16_t>(TCNT1 - t0);
        if (r != fsw::kOk) pressure = -1;
        pressure += fsw_gen::sv[fsw_gen::E_valveOpen] ? -1 : 1;
        g += 10;
        total += dt;
        if (dt > worst) worst = dt;
    }
    report_cycles(total / 1000, worst, fsw_gen::sv[fsw_gen::E_state]);
#endif
}

void loop() {
#if !FSW_VM_TIMING
    g += 10;
    fsw::store<uint64_t>(fsw_gen::sv + fsw_gen::E_time, g);
    if (step() != fsw::kOk) digitalWrite(13, HIGH);
#endif
}
