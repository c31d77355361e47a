// Arduino PSL, EEPROM: on AVR through its registers. Its own file so that a
// build that only reads the EEPROM (the bytecode VM's verifier, a sketch
// that loads a machine from a slot) links neither the cycle timer's and
// the ADC scan's interrupts of psl_arduino.cpp nor their state.
#include "fsw_config.h"

#if FSW_PLATFORM_ARDUINO

#include <Arduino.h>

#include "fsw_pal.h"

namespace fsw {
namespace pal {

#if defined(__AVR__)
// The EEPROM through its registers (datasheet 8.4): a write is started and
// left to the hardware; EERIE asks for the ready interrupt, whose handler
// (below) only turns itself off, so that a sleeping CPU wakes when a byte
// is done and the generated loop gives the writer (parameters, the flight
// recorder) its next byte. The handler is here, beside the write that
// enables it, so that every firmware that writes the EEPROM has it: an
// interrupt without a handler resets an AVR.
ISR(EE_READY_vect) { EECR = static_cast<uint8_t>(EECR & ~_BV(EERIE)); }
uint16_t eeprom_size() { return static_cast<uint16_t>(E2END + 1u); }
uint8_t eeprom_read(uint16_t addr) {
    while (EECR & _BV(EEPE)) {
    }
    EEAR = addr;
    EECR = static_cast<uint8_t>(EECR | _BV(EERE));
    return EEDR;
}
bool eeprom_ready() { return (EECR & _BV(EEPE)) == 0; }
void eeprom_write(uint16_t addr, uint8_t value) {
    EEAR = addr;
    EEDR = value;
    const IrqState saved = critical_enter();  // EEPE within 4 cycles of EEMPE
    EECR = static_cast<uint8_t>((EECR & ~(_BV(EEPM1) | _BV(EEPM0))) | _BV(EEMPE));
    EECR = static_cast<uint8_t>(EECR | _BV(EEPE) | _BV(EERIE));
    critical_exit(saved);
}
#else
// Another MCU: no EEPROM through this layer (parameters keep their defaults).
uint16_t eeprom_size() { return 0; }
uint8_t eeprom_read(uint16_t) { return 0xFF; }
bool eeprom_ready() { return true; }
void eeprom_write(uint16_t, uint8_t) {}
#endif

}  // namespace pal
}  // namespace fsw

#endif  // FSW_PLATFORM_ARDUINO
