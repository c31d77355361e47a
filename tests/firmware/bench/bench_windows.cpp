// Benchmark driver (not a test): pushes `count` pseudo-random samples through
// one kind of window of size 100, or steps the hand-written tank machine, so
// that callgrind's instruction count per update can be read off as
// (Ir(count) - Ir(0)) / count. Usage: bench_windows none|avg|max|min|median|tank COUNT
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fswkit.h"

using namespace fsw;

#include "../tank_hand.inc"

static RollAvgN<100> w_avg;
static RollMaxN<100> w_max;
static RollMinN<100> w_min;
static RollMedianN<100> w_med;

int main(int argc, char** argv) {
    if (argc != 3) return 2;
    const char* kind = argv[1];
    const long count = atol(argv[2]);
    uint32_t s = 2463534242u;
    Real acc = 0;
    if (strcmp(kind, "tank") == 0) {
        tank_init(kTankVentControl);
        write_F64(tank_sv + kOffTankPressure, 700);
        for (long i = 0; i < count; ++i) {
            store<uint64_t>(tank_sv + kOffTime, static_cast<uint64_t>(i) * 10u);
            if (tank_step() != kOk) return 1;
        }
        printf("%u\n", static_cast<unsigned>(tank_sv[kOffValveOpen]));
        return 0;
    }
    for (long i = 0; i < count; ++i) {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        const Real x = static_cast<Real>(s % 100000u) / 7;
        switch (kind[0] == 'm' ? kind[1] : kind[0]) {
            case 'a': w_avg.push(x); acc += w_avg.value(); break;
            case 'v': w_avg.push(x); break;
            case 'n': acc += x; break;  // harness overhead only
            case 'x': w_max.push(x); acc += w_max.value(); break;
            case 'i': w_min.push(x); acc += w_min.value(); break;
            case 'e': w_med.push(x); acc += w_med.value(); break;
            default: return 2;
        }
    }
    printf("%g\n", static_cast<double>(acc));
    return 0;
}
