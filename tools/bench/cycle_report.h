// What the AVR benchmark probes print when their steps are done (read by
// tools/bench_firmware.py and tools/bench_vm.py): the average and the worst
// step in Timer1 counts, the timing's own cost (two reads back to back,
// subtracted by the bench) and the machine's state; then the CPU sleeps for
// good, which ends the simulation.
#ifndef FSW_BENCH_CYCLE_REPORT_H
#define FSW_BENCH_CYCLE_REPORT_H

#include <Arduino.h>
#include <avr/sleep.h>

inline void report_cycles(uint32_t average, uint16_t worst, uint8_t state) {
    // Two reads back to back with interrupts off: an interrupt between them
    // (Timer0's, every 16,384 cycles) would count its own cycles as the
    // timing's cost, subtracted from every step's average.
    const uint8_t sreg = SREG;
    cli();
    const uint16_t t0 = TCNT1;
    const uint16_t t1 = TCNT1;
    SREG = sreg;
    Serial.print("cycles ");
    Serial.print(average);
    Serial.print(" worst ");
    Serial.print(worst);
    Serial.print(" overhead ");
    Serial.print(static_cast<uint16_t>(t1 - t0));
    Serial.print(" state ");
    Serial.println(state);
    Serial.flush();
    cli();
    sleep_enable();
    sleep_cpu();
}

#endif  // FSW_BENCH_CYCLE_REPORT_H
