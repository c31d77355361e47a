// Native (host) PSL: simulated clock and pins for tests and host runs, the
// console on stdout, and a re-entrant spin lock as the critical section.
#include "fsw_config.h"

#if FSW_PLATFORM_NATIVE

#include <poll.h>
#include <stdio.h>
#include <string.h>

#include <algorithm>
#include <vector>
#include <unistd.h>
#include <time.h>

#include "fsw_clock.h"
#include "fsw_log.h"
#include "fsw_pal.h"
#include "fsw_vm.h"
#include "psl_native.h"

namespace fsw {

// The recorder's store where no generated code names it (fsw_log.h).
extern const uint8_t log_nor_cs __attribute__((weak)) = kLogEeprom;
// The VM's features where no generated code names them (fsw_vm.h): all.
extern const uint16_t vm_features __attribute__((weak)) = kVmAllFeatures;

namespace {

uint64_t g_time_us;
bool g_real_time;
uint64_t g_real_origin_us;
Clock64 g_micros_ext;
Clock64 g_millis_ext;
uint16_t g_analog[256];
uint8_t g_pwm[256];
uint8_t g_level[256];
uint8_t g_mode[256];
bool g_modes_cleared;
uint8_t* g_cap_buf;
uint16_t g_cap_cap;
uint16_t* g_cap_len;
uint8_t g_in[256];
uint16_t g_in_head;
uint16_t g_in_len;
uint32_t g_kicks;
bool g_wdt_armed;
uint8_t g_reset_cause;
bool g_use_stdin;
uint32_t g_uart_baud;
uint16_t g_uart_buffer;
uint64_t g_uart_busy_until_bits;  // simulated time (in bit times) the last queued byte ends
uint32_t g_uart_overruns;
uint32_t g_written;
// console_send's runs not yet all sent, each with a copy of its bytes (console_sending)
struct SendRun {
    const uint8_t* at;
    std::vector<uint8_t> bytes;
};
std::vector<SendRun> g_runs;
// The EEPROM model: 1,024 bytes, erased (0xFF) at start, kept across
// sim_reset() (as a board keeps it across resets), written through to a
// file when one is named, and frozen after a given number of writes (a
// power cut: the writes before it stay, none after it lands).
const uint16_t kEepromSize = 1024;
uint8_t g_eeprom[kEepromSize];
bool g_eeprom_init;
uint32_t g_eeprom_writes;
uint32_t g_eeprom_reads;
uint32_t g_eeprom_freeze = 0xFFFFFFFFu;
FILE* g_eeprom_file;
// The SPI NOR flash model (psl_native.h). Its bytes are kept inverted, so
// that the zeroed array is an erased chip and pages never touched cost no
// memory.
const uint32_t kFlashMax = 16ul << 20;
uint8_t g_flash_inv[kFlashMax];
uint32_t g_flash_size = 8ul << 20;
uint32_t g_flash_ops;
uint32_t g_flash_freeze = 0xFFFFFFFFu;
FILE* g_flash_file;
uint64_t g_flash_busy_until;  // simulated us
bool g_flash_wel;
uint8_t g_spi_cmd;
uint32_t g_spi_n;  // bytes of the transaction so far
uint32_t g_spi_addr;
uint8_t g_spi_page[256];
uint16_t g_spi_page_n;
// The default device's chip select (spi_begin: the flash's) and the one
// selected now (0xFF: none); other devices answer through the responder.
uint8_t g_spi_flash_cs = 0xFF;
uint8_t g_spi_sel = 0xFF;
uint16_t g_spi_dev_n;  // bytes since the other device's select
native::SpiResponder g_spi_responder = 0;

void eeprom_init() {
    if (!g_eeprom_init) {
        memset(g_eeprom, 0xFF, sizeof g_eeprom);
        g_eeprom_init = true;
    }
}

// Re-entrant spin lock: the owner is the address of a thread-local byte.
__thread char t_token;
void* g_owner;
uint32_t g_depth;

uint64_t host_monotonic_us() {
    timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<uint64_t>(ts.tv_sec) * 1000000u + static_cast<uint64_t>(ts.tv_nsec) / 1000u;
}

uint64_t now_us() { return g_real_time ? host_monotonic_us() - g_real_origin_us : g_time_us; }

// The UART model: bytes still queued at time `now` (bit times: us * baud / 1e6).
uint32_t uart_queued() {
    const uint64_t now_bits = now_us() * g_uart_baud / 1000000u;
    if (g_uart_busy_until_bits <= now_bits) return 0;
    return static_cast<uint32_t>((g_uart_busy_until_bits - now_bits + 9u) / 10u);
}

void clear_modes() {
    if (!g_modes_cleared) {
        memset(g_mode, 0xFF, sizeof g_mode);
        g_modes_cleared = true;
    }
}

}  // namespace

namespace native {

void sim_set_time_us(uint64_t t) { g_time_us = t; }
void sim_advance_us(uint64_t dt) { g_time_us += dt; }
uint64_t sim_time_us() { return now_us(); }
void use_real_time(bool on) {
    g_real_time = on;
    g_real_origin_us = host_monotonic_us() - g_time_us;
}
void sim_set_analog(uint8_t pin, uint16_t raw) { g_analog[pin] = raw; }
uint8_t sim_pwm(uint8_t pin) { return g_pwm[pin]; }
void sim_set_digital(uint8_t pin, bool high) { g_level[pin] = high ? 1 : 0; }
bool sim_digital(uint8_t pin) { return g_level[pin] != 0; }
uint8_t sim_pin_mode(uint8_t pin) {
    clear_modes();
    return g_mode[pin];
}
void console_capture(uint8_t* buf, uint16_t cap, uint16_t* len) {
    g_cap_buf = buf;
    g_cap_cap = cap;
    g_cap_len = len;
    if (len != 0) *len = 0;
}
void console_use_stdin(bool on) { g_use_stdin = on; }
void console_model_uart(uint32_t baud, uint16_t buffer) {
    g_uart_baud = baud;
    g_uart_buffer = buffer;
    g_uart_busy_until_bits = 0;
}
uint32_t console_overruns() { return g_uart_overruns; }
uint32_t console_written() { return g_written; }
void console_feed(const uint8_t* data, uint16_t len) {
    for (uint16_t i = 0; i < len && g_in_len < sizeof g_in; ++i) {
        g_in[(g_in_head + g_in_len) % sizeof g_in] = data[i];
        ++g_in_len;
    }
}
uint32_t watchdog_kicks() { return g_kicks; }
bool watchdog_armed() { return g_wdt_armed; }
void sim_set_reset_cause(uint8_t cause) { g_reset_cause = cause; }

namespace {
TwiResponder g_twi_responder = 0;
}  // namespace
void twi_set_responder(TwiResponder r) { g_twi_responder = r; }
TwiResponder twi_responder() { return g_twi_responder; }
void spi_set_responder(SpiResponder r) { g_spi_responder = r; }

void sim_reset() {
    g_time_us = 0;
    g_flash_busy_until = 0;  // the flash keeps its bytes; an operation in progress ended
    g_flash_wel = false;
    g_spi_n = 0;
    g_real_time = false;
    memset(&g_micros_ext, 0, sizeof g_micros_ext);
    memset(&g_millis_ext, 0, sizeof g_millis_ext);
    memset(g_analog, 0, sizeof g_analog);
    memset(g_pwm, 0, sizeof g_pwm);
    memset(g_level, 0, sizeof g_level);
    g_modes_cleared = false;
    clear_modes();
    g_cap_buf = 0;
    g_cap_len = 0;
    g_in_head = 0;
    g_in_len = 0;
    g_kicks = 0;
    g_wdt_armed = false;
    g_reset_cause = 0;
    g_uart_baud = 0;
    g_uart_buffer = 0;
    g_uart_busy_until_bits = 0;
    g_uart_overruns = 0;
    g_written = 0;
    g_runs.clear();
}

void sim_eeprom_erase() {
    g_eeprom_init = false;
    eeprom_init();
    g_eeprom_writes = 0;
    g_eeprom_freeze = 0xFFFFFFFFu;
}
uint8_t* sim_eeprom() {
    eeprom_init();
    return g_eeprom;
}
uint32_t sim_eeprom_writes() { return g_eeprom_writes; }
uint32_t sim_eeprom_reads() { return g_eeprom_reads; }
void sim_eeprom_freeze_after(uint32_t writes) { g_eeprom_freeze = g_eeprom_writes + writes; }
bool sim_eeprom_file(const char* path) {
    eeprom_init();
    if (g_eeprom_file) fclose(g_eeprom_file);
    g_eeprom_file = fopen(path, "r+b");
    if (g_eeprom_file) {
        const size_t n = fread(g_eeprom, 1, sizeof g_eeprom, g_eeprom_file);
        if (n < sizeof g_eeprom) memset(g_eeprom + n, 0xFF, sizeof g_eeprom - n);
    } else {
        g_eeprom_file = fopen(path, "w+b");
    }
    if (!g_eeprom_file) return false;
    if (fseek(g_eeprom_file, 0, SEEK_SET) != 0 || fwrite(g_eeprom, 1, sizeof g_eeprom, g_eeprom_file) != sizeof g_eeprom ||
        fflush(g_eeprom_file) != 0) {
        fclose(g_eeprom_file);
        g_eeprom_file = 0;
        return false;
    }
    return true;
}

void sim_flash_set_size(uint32_t bytes) {
    g_flash_size = bytes >= (64ul << 10) && bytes <= kFlashMax && (bytes & (bytes - 1)) == 0 ? bytes : 8ul << 20;
    memset(g_flash_inv, 0, g_flash_size);
}
uint32_t sim_flash_size() { return g_flash_size; }
uint8_t sim_flash_byte(uint32_t addr) { return static_cast<uint8_t>(~g_flash_inv[addr & (g_flash_size - 1)]); }
uint32_t sim_flash_ops() { return g_flash_ops; }
void sim_flash_freeze_after(uint32_t ops) { g_flash_freeze = g_flash_ops + ops; }
bool sim_flash_file(const char* path) {
    if (g_flash_file) fclose(g_flash_file);
    g_flash_file = fopen(path, "r+b");
    static uint8_t chunk[4096];
    if (g_flash_file) {
        for (uint32_t a = 0; a < g_flash_size; a += sizeof chunk) {
            const size_t n = fread(chunk, 1, sizeof chunk, g_flash_file);
            for (size_t i = 0; i < sizeof chunk; ++i) g_flash_inv[a + i] = static_cast<uint8_t>(i < n ? ~chunk[i] : 0);
        }
    } else {
        g_flash_file = fopen(path, "w+b");
    }
    if (!g_flash_file || fseek(g_flash_file, 0, SEEK_SET) != 0) return false;
    for (uint32_t a = 0; a < g_flash_size; a += sizeof chunk) {
        for (size_t i = 0; i < sizeof chunk; ++i) chunk[i] = static_cast<uint8_t>(~g_flash_inv[a + i]);
        if (fwrite(chunk, 1, sizeof chunk, g_flash_file) != sizeof chunk) {
            fclose(g_flash_file);
            g_flash_file = 0;
            return false;
        }
    }
    if (fflush(g_flash_file) != 0) {
        fclose(g_flash_file);
        g_flash_file = 0;
        return false;
    }
    return true;
}

}  // namespace native

namespace {

bool flash_busy() { return now_us() < g_flash_busy_until; }

// Writes bytes [a, a + n) of the model through to its file.
void flash_write_through(uint32_t a, uint32_t n) {
    if (!g_flash_file || fseek(g_flash_file, static_cast<long>(a), SEEK_SET) != 0) return;
    for (uint32_t i = 0; i < n; ++i) fputc(static_cast<uint8_t>(~g_flash_inv[a + i]), g_flash_file);
    fflush(g_flash_file);
}

// The command of the transaction that just ended (chip select high).
void flash_end() {
    if (g_spi_n == 0 || flash_busy()) return;
    if (g_spi_cmd == 0x06 && g_spi_n == 1) g_flash_wel = true;
    if (g_spi_cmd == 0x04 && g_spi_n == 1) g_flash_wel = false;
    const bool program = g_spi_cmd == 0x02 && g_spi_n > 4, erase = g_spi_cmd == 0x20 && g_spi_n == 4;
    if (!(program || erase) || !g_flash_wel) return;
    g_flash_wel = false;
    if (g_flash_ops >= g_flash_freeze) return;  // after a power cut: nothing lands
    ++g_flash_ops;
    const uint32_t a = g_spi_addr & (g_flash_size - 1);
    if (program) {
        const uint32_t page = a & ~static_cast<uint32_t>(0xFFu);
        for (uint16_t i = 0; i < g_spi_page_n; ++i) {
            const uint32_t at = page | ((a + i) & 0xFFu);
            g_flash_inv[at] = static_cast<uint8_t>(g_flash_inv[at] | ~g_spi_page[i]);  // 1 -> 0 only
        }
        flash_write_through(page, 256);
        g_flash_busy_until = now_us() + 400u;
    } else {
        const uint32_t sector = a & ~static_cast<uint32_t>(0xFFFu);
        memset(g_flash_inv + sector, 0, 4096);
        flash_write_through(sector, 4096);
        g_flash_busy_until = now_us() + 45000u;
    }
}

}  // namespace

namespace pal {

void begin() { clear_modes(); }

uint16_t eeprom_size() { return kEepromSize; }
uint8_t eeprom_read(uint16_t addr) {
    eeprom_init();
    ++g_eeprom_reads;
    return addr < kEepromSize ? g_eeprom[addr] : 0xFF;
}
bool eeprom_ready() { return true; }
void eeprom_write(uint16_t addr, uint8_t value) {
    eeprom_init();
    if (addr >= kEepromSize || g_eeprom_writes >= g_eeprom_freeze) return;
    ++g_eeprom_writes;
    g_eeprom[addr] = value;
    if (g_eeprom_file && fseek(g_eeprom_file, addr, SEEK_SET) == 0) {
        fputc(value, g_eeprom_file);
        fflush(g_eeprom_file);
    }
}

void spi_bus_begin() {}
void spi_device(SpiDevice& d, uint8_t cs_pin, uint8_t mode, uint32_t max_hz) {
    (void)mode;
    (void)max_hz;
    d.cs_port = 0;
    d.cs_pin = cs_pin;
    d.cs_mask = 0;
    d.spcr = d.spsr = 0;
    g_mode[cs_pin] = kOutput;
    g_level[cs_pin] = 1;
}
void spi_select(const SpiDevice& d, bool on) {
    if (d.cs_pin == g_spi_flash_cs) {
        spi_select(on);
        return;
    }
    g_level[d.cs_pin] = on ? 0 : 1;
    g_spi_sel = on ? d.cs_pin : 0xFF;
    g_spi_dev_n = 0;
}
void spi_begin(uint8_t cs_pin) {
    clear_modes();
    g_mode[cs_pin] = kOutput;
    g_level[cs_pin] = 1;
    g_spi_flash_cs = cs_pin;
}
void spi_select(bool on) {
    if (!on) flash_end();
    g_spi_sel = on ? g_spi_flash_cs : 0xFF;
    g_spi_n = 0;
    g_spi_page_n = 0;
}
uint8_t spi_transfer(uint8_t out) {
    if (g_spi_sel != g_spi_flash_cs) {  // another device (or none selected)
        if (g_spi_sel == 0xFF || g_spi_responder == 0) return 0xFF;
        return g_spi_responder(g_spi_sel, g_spi_dev_n++, out);
    }
    const uint32_t i = g_spi_n++;
    if (i == 0) {
        g_spi_cmd = out;
        g_spi_addr = 0;
        return 0xFF;
    }
    if (g_spi_cmd == 0x05) return static_cast<uint8_t>((flash_busy() ? 1u : 0u) | (g_flash_wel ? 2u : 0u));
    if (flash_busy()) return 0xFF;
    if (g_spi_cmd == 0x9F) {
        uint8_t log2 = 0;
        while ((1ul << log2) < g_flash_size) ++log2;
        return i == 1 ? 0xEF : i == 2 ? 0x40 : i == 3 ? log2 : 0xFF;
    }
    if (i <= 3) {
        g_spi_addr = (g_spi_addr << 8) | out;
        return 0xFF;
    }
    if (g_spi_cmd == 0x03) return static_cast<uint8_t>(~g_flash_inv[(g_spi_addr + (i - 4)) & (g_flash_size - 1)]);
    if (g_spi_cmd == 0x02) {
        if (g_spi_page_n < 256) g_spi_page[g_spi_page_n++] = out;
        return 0xFF;
    }
    return 0xFF;
}

uint32_t micros32() { return static_cast<uint32_t>(now_us()); }
uint32_t millis32() { return static_cast<uint32_t>(now_us() / 1000u); }
uint64_t micros64() { return clock64_extend(g_micros_ext, micros32()); }
uint64_t millis64() { return clock64_extend(g_millis_ext, millis32()); }

uint16_t analog_read(uint8_t pin) { return g_analog[pin]; }
void analog_write(uint8_t pin, uint8_t duty) { g_pwm[pin] = duty; }
// The host converts at once: the counts are the pins' when the scan starts.
bool adc_scan_start(const uint8_t* pins, uint8_t stride, uint8_t n, volatile uint16_t* raw) {
    for (uint8_t i = 0; i < n; ++i) raw[i] = g_analog[pins[i * stride]];
    return true;
}
bool adc_scan_busy() { return false; }

void pin_mode(uint8_t pin, uint8_t mode) {
    clear_modes();
    g_mode[pin] = mode;
}
bool digital_read(uint8_t pin) { return g_level[pin] != 0; }
void digital_write(uint8_t pin, bool high) { g_level[pin] = high ? 1 : 0; }

void console_begin(uint32_t baud) { (void)baud; }
uint16_t console_write_space() {
    if (g_uart_baud == 0) return 0xFFFFu;
    const uint32_t q = uart_queued();
    return static_cast<uint16_t>(q >= g_uart_buffer ? 0u : g_uart_buffer - q);
}
namespace {
// Bytes onto the modelled line (its clock busy 10 bits a byte), into the
// capture buffer when one is set, else to standard output.
void uart_out(const uint8_t* data, uint16_t len) {
    g_written += len;
    if (g_uart_baud != 0) {
        const uint64_t now_bits = now_us() * g_uart_baud / 1000000u;
        if (g_uart_busy_until_bits < now_bits) g_uart_busy_until_bits = now_bits;
        g_uart_busy_until_bits += 10u * static_cast<uint64_t>(len);
    }
    if (g_cap_buf != 0) {
        for (uint16_t i = 0; i < len && *g_cap_len < g_cap_cap; ++i) g_cap_buf[(*g_cap_len)++] = data[i];
        return;
    }
    fwrite(data, 1, len, stdout);
    fflush(stdout);
}
}  // namespace

void console_write(const uint8_t* data, uint16_t len) {
    if (g_uart_baud != 0 && len > console_write_space()) ++g_uart_overruns;
    uart_out(data, len);
}
// console_send's runs are output at once, as console_write's bytes, and
// kept with a copy of their bytes until the model's clock has sent them: a
// byte that changed before it went out (the caller broke the contract,
// fsw_pal.h), or a third run, counts as an overrun.
namespace {

// Retires the bytes sent (the model's clock): each checked against its copy
// first, since the caller may reuse them only once console_sending() has
// passed them.
void retire_runs() {
    uint32_t handed = 0;
    for (const SendRun& r : g_runs) handed += static_cast<uint32_t>(r.bytes.size());
    const uint32_t q = g_uart_baud == 0 ? 0 : uart_queued();
    uint32_t sent = handed > q ? handed - q : 0;
    while (!g_runs.empty() && sent != 0) {
        SendRun& r = g_runs.front();
        const uint32_t n = sent < r.bytes.size() ? sent : static_cast<uint32_t>(r.bytes.size());
        if (memcmp(r.at, r.bytes.data(), n) != 0) ++g_uart_overruns;
        sent -= n;
        if (n == r.bytes.size()) {
            g_runs.erase(g_runs.begin());
        } else {
            r.at += n;
            r.bytes.erase(r.bytes.begin(), r.bytes.begin() + n);
        }
    }
}
}  // namespace

void console_send(const uint8_t* data, uint16_t len) {
    if (len == 0) return;
    retire_runs();
    if (!g_runs.empty() && g_runs.back().at + g_runs.back().bytes.size() == data) {
        g_runs.back().bytes.insert(g_runs.back().bytes.end(), data, data + len);
    } else {
        if (g_runs.size() >= 2) ++g_uart_overruns;  // a third run: not the contract
        g_runs.push_back(SendRun{data, std::vector<uint8_t>(data, data + len)});
    }
    uart_out(data, len);
}

const uint8_t* console_sending() {
    retire_runs();
    return g_runs.empty() ? 0 : g_runs.front().at;
}

bool console_needs_poll() { return false; }

int16_t console_read() {
    if (g_in_len == 0 && g_use_stdin) {
        pollfd p = {0, POLLIN, 0};
        uint8_t b;
        if (poll(&p, 1, 0) == 1 && read(0, &b, 1) == 1) return b;
    }
    if (g_in_len == 0) return -1;
    const uint8_t b = g_in[g_in_head];
    g_in_head = static_cast<uint16_t>((g_in_head + 1u) % sizeof g_in);
    --g_in_len;
    return b;
}

// The fed bytes read in place (fsw_pal.h), as the UART driver's ring is:
// stdin's bytes are taken into the same ring as far as the reader looks.
int16_t console_peek(uint8_t i) {
    while (i >= g_in_len && g_use_stdin && g_in_len < sizeof g_in) {
        pollfd p = {0, POLLIN, 0};
        uint8_t b;
        if (poll(&p, 1, 0) != 1 || read(0, &b, 1) != 1) break;
        g_in[(g_in_head + g_in_len) % sizeof g_in] = b;
        ++g_in_len;
    }
    if (i >= g_in_len) return -1;
    return g_in[(g_in_head + i) % sizeof g_in];
}

uint8_t* console_run(uint8_t n) {
    if (g_in_head + n > sizeof g_in) {  // wrapped round the ring's end: turned, its first byte at the front
        std::rotate(g_in, g_in + g_in_head, g_in + sizeof g_in);
        g_in_head = 0;
    }
    return g_in + g_in_head;
}

void console_drop(uint8_t n) {
    g_in_head = static_cast<uint16_t>((g_in_head + n) % sizeof g_in);
    g_in_len = static_cast<uint16_t>(g_in_len - n);
    if (g_in_len == 0) g_in_head = 0;  // empty: the next bytes go from the front
}

IrqState critical_enter() {
    void* const me = &t_token;
    if (__atomic_load_n(&g_owner, __ATOMIC_ACQUIRE) == me) {
        ++g_depth;
        return 0;
    }
    void* expected = 0;
    while (!__atomic_compare_exchange_n(&g_owner, &expected, me, true, __ATOMIC_ACQUIRE,
                                        __ATOMIC_RELAXED)) {
        expected = 0;
    }
    g_depth = 1;
    return 0;
}

void critical_exit(IrqState saved) {
    (void)saved;
    if (--g_depth == 0) __atomic_store_n(&g_owner, static_cast<void*>(0), __ATOMIC_RELEASE);
}

void watchdog_begin() { g_wdt_armed = true; }  // simulated whatever FSW_WATCHDOG says
void watchdog_kick() { ++g_kicks; }
uint8_t reset_cause() { return g_reset_cause; }

}  // namespace pal
}  // namespace fsw

#endif  // FSW_PLATFORM_NATIVE
