/* Timer1 as a 32-bit clock for the test probes (spiflash_probe, twi_probe):
   its overflows counted by an interrupt; the probe calls ticks_begin() once,
   then enables interrupts. */
#ifndef PROBE_TICKS_H
#define PROBE_TICKS_H

#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>

static volatile uint16_t t1_overflows;

ISR(TIMER1_OVF_vect) { t1_overflows++; }

/* Timer1 running at clk/8, its overflow interrupt on. */
static void ticks_begin(void) {
    TCCR1A = 0;
    TCCR1B = 1 << CS11;
    TIMSK1 = 1 << TOIE1;
}

/* Timer1 ticks (clk/8: 0.5 us) on 32 bits. */
static uint32_t ticks(void) {
    uint8_t sreg = SREG;
    cli();
    uint16_t lo = TCNT1;
    uint16_t hi = t1_overflows;
    if ((TIFR1 & (1 << TOV1)) && lo < 0x8000) hi++; /* wrapped since interrupts went off */
    SREG = sreg;
    return ((uint32_t)hi << 16) | lo;
}

#endif
