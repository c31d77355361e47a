/* Unity settings for `pio test`: the firmware suites' own (64-bit asserts;
   on AVR, output through the polled UART0 that simavr shows). Its presence
   here tells PlatformIO not to generate a Serial-based one. */
#include "../../firmware/unity_config.h"
