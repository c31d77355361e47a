// Footprint probe (not a test): an empty sketch, or one that steps the
// generated tank machine from loop() with G counting up. The difference is
// what the machine and its state vector add.
#include <Arduino.h>

#include "fswkit.h"
#if FSW_SIZE_TANK
#include "sv.gen.h"
#include "tank.gen.h"
#endif

void setup() {}

void loop() {
#if FSW_SIZE_TANK
    static uint64_t g;
    g += 10;
    fsw::store<uint64_t>(fsw_gen::sv + fsw_gen::E_time, g);
    if (fsw_gen::tank::step() != fsw::kOk) digitalWrite(13, HIGH);
#endif
}
