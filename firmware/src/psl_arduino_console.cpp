// Arduino PSL, Console: the serial port. Its own file so that a build that
// never uses the console does not link HardwareSerial (157 B of RAM on AVR).
#include "fsw_config.h"

#if FSW_PLATFORM_ARDUINO

#include <Arduino.h>

#include "fsw_pal.h"

namespace fsw {
namespace pal {

void console_begin(uint32_t baud) { Serial.begin(baud); }
void console_write(const uint8_t* data, uint16_t len) { Serial.write(data, len); }
int16_t console_read() { return static_cast<int16_t>(Serial.read()); }
uint16_t console_write_space() { return static_cast<uint16_t>(Serial.availableForWrite()); }

}  // namespace pal
}  // namespace fsw

#endif  // FSW_PLATFORM_ARDUINO
