// Footprint probe (not a test): an Arduino sketch that is empty, or that
// runs the hand-written tank machine from loop() with G = millis64(). The
// difference of the two builds is what the machine + its state vector add.
#include <Arduino.h>

#include "fswkit.h"

#if FSW_SIZE_TANK
using namespace fsw;
#include "../tank_hand.inc"
#endif

extern "C" void setup(void) {
#if FSW_SIZE_TANK
    tank_init(kTankVentControl);
#endif
}

extern "C" void loop(void) {
#if FSW_SIZE_TANK
    store<uint64_t>(tank_sv + kOffTime, pal::millis64());
    if (tank_step() != kOk) digitalWrite(13, HIGH);
#endif
}
