// The UART0 driver's receive ring (psl_arduino_console.cpp; with the core's
// Serial, the ring a link that reads commands in place takes Serial's bytes
// into) for a program whose code does not size it: FSW_CONSOLE_RX_SIZE bytes. Generated code
// defines its own, sized for what its ground keeps in flight (docs/runtime.md,
// "The console"). Strong definitions in an object of their own, which the
// linker takes out of the runtime's archive only when nothing defined them
// before it (as fsw_app.cpp's constants: avr-gcc 5.4 would fold a weak
// mask's own value even where a strong one overrides it).
#include "fsw_config.h"

#if FSW_PLATFORM_ARDUINO

#include <stdint.h>

extern "C" {
uint8_t fsw_console_rx[FSW_CONSOLE_RX_SIZE];
extern const uint8_t fsw_console_rx_mask = FSW_CONSOLE_RX_SIZE - 1;
}

#endif
