// Hooks into the native (host) PSL: a simulated clock tests advance by hand,
// simulated pins tests set and read, console capture and input.
#ifndef PSL_NATIVE_H
#define PSL_NATIVE_H

#include "fsw_types.h"

#if FSW_PLATFORM_NATIVE

namespace fsw {
namespace native {

// Simulated time in microseconds. micros32()/millis32() are its low 32 bits
// (so they wrap exactly like a board's), micros64()/millis64() extend them.
void sim_set_time_us(uint64_t t);
void sim_advance_us(uint64_t dt);
uint64_t sim_time_us();
// Follow the host's monotonic clock instead of the simulated one.
void use_real_time(bool on);

// Pins 0..255: ADC values read by analog_read, PWM duty written by
// analog_write, digital levels and modes.
void sim_set_analog(uint8_t pin, uint16_t raw);
uint8_t sim_pwm(uint8_t pin);
void sim_set_digital(uint8_t pin, bool high);
bool sim_digital(uint8_t pin);
uint8_t sim_pin_mode(uint8_t pin);  // 0xFF: never set

// Console: output goes to stdout unless a capture buffer is set; input
// comes from bytes fed here, or from stdin (non-blocking) when enabled.
void console_use_stdin(bool on);
void console_capture(uint8_t* buf, uint16_t cap, uint16_t* len);
void console_feed(const uint8_t* data, uint16_t len);
// A UART model on the simulated clock: console_write_space() is `buffer`
// minus the bytes not yet sent at `baud` (10 bits a byte). baud 0: no limit
// (the default). Bytes written past the space count in console_overruns()
// (a write that would have blocked on a board).
void console_model_uart(uint32_t baud, uint16_t buffer);
uint32_t console_overruns();
// Bytes written to the console since sim_reset().
uint32_t console_written();

// Watchdog and reset cause.
uint32_t watchdog_kicks();
bool watchdog_armed();
void sim_set_reset_cause(uint8_t cause);

// The EEPROM model (1,024 bytes, kept across sim_reset()): erased to 0xFF;
// its bytes; writes so far, reads so far (pal::eeprom_read's calls: what a
// check in slices counts, fsw_vm.h); a power cut after `writes` more writes
// (later writes are lost); a file it is loaded from and written through to
// (false when it cannot be opened or written).
void sim_eeprom_erase();
uint8_t* sim_eeprom();
uint32_t sim_eeprom_writes();
uint32_t sim_eeprom_reads();
void sim_eeprom_freeze_after(uint32_t writes);
bool sim_eeprom_file(const char* path);

// The SPI NOR flash model: a W25Q-class chip on the SPI (whatever the chip
// select's pin), kept across sim_reset(). Commands: 06h/04h write enable /
// disable, 05h status register 1 (BUSY bit 0, WEL bit 1), 9Fh JEDEC ID
// (EF 40 log2(size)), 03h read, 02h page program (ANDs bytes in: 1->0 only,
// wrapping within its 256-byte page), 20h 4 KiB sector erase (0xFF). BUSY
// lasts 0.4 ms after a program and 45 ms after an erase on the simulated
// clock; meanwhile only 05h is answered. Its size (a power of two, 64 KiB
// to 16 MiB: 8 MiB until set; setting it erases the chip); a byte; the
// page programs and erases started; a power cut after `ops` more of them
// (later ones are lost); a file it is loaded from and written through to
// (false when it cannot be opened or written).
void sim_flash_set_size(uint32_t bytes);
uint32_t sim_flash_size();
uint8_t sim_flash_byte(uint32_t addr);
uint32_t sim_flash_ops();
void sim_flash_freeze_after(uint32_t ops);
bool sim_flash_file(const char* path);

// The TWI (fsw_twi.h) on the host: a scripted responder plays every slave.
// It is called once per transaction, on the first twi_busy() poll after
// twi_start(), with the address, the bytes written and the buffer for the
// nr bytes to read, and returns a TwiStatus (kTwiOk, kTwiNackAddr,
// kTwiNackData, kTwiBusError). 0 (the default): every address is NACKed.
// Not reset by sim_reset().
typedef uint8_t (*TwiResponder)(uint8_t addr7, const uint8_t* w, uint8_t nw, uint8_t* r, uint8_t nr);
void twi_set_responder(TwiResponder r);
TwiResponder twi_responder();

// The SPI's other devices (spi_device / spi_select(device), any chip
// select but the default device's, which is the flash model): a scripted
// responder called for each byte shifted while one is selected, with its
// chip-select pin, the byte's index since the select and the byte out;
// it returns the byte in. 0 (the default): every byte reads 0xFF (nobody
// drives MISO). Not reset by sim_reset().
typedef uint8_t (*SpiResponder)(uint8_t cs_pin, uint16_t index, uint8_t out);
void spi_set_responder(SpiResponder r);

// Back to power-on state: time 0, pins cleared, counters zero.
void sim_reset();

}  // namespace native
}  // namespace fsw

#endif  // FSW_PLATFORM_NATIVE
#endif  // PSL_NATIVE_H
