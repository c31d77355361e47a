// The flight recorder (docs/recorder.md): samples of chosen elements, kept
// on board in fixed-size, self-checking records from a trigger state to the
// end of the flight, with the seconds before the trigger held in RAM and
// committed when it fires. The tables are generated from the application's
// `[log]` section (FSW_FLASH). Records are written in the background, one
// byte whenever the store is ready, so nothing waits for it; a power cut
// loses at most the record being written.
#ifndef FSW_LOG_H
#define FSW_LOG_H

#include "fsw_types.h"

namespace fsw {

// Record kinds: a record's first byte, written last (docs/recorder.md).
static const uint8_t kLogStart = 0xF0;  // a flight's first record
static const uint8_t kLogData = 0xF1;   // samples
static const uint8_t kLogHeader = 8;    // magic, seq u16, flight, t0 u32 (ms); held values, samples follow
static const uint8_t kLogTail = 5;      // period u16 (ms), used u8, CRC-16: the record's last bytes
static const uint8_t kLogEscape = 0x80; // the first delta byte of a sample: a held element changes

// The store: the chip select's board pin of an SPI NOR flash (docs/recorder.md, "On an SPI NOR flash chip"),
// or kLogEeprom. The generated code of an application with a recorder
// defines it (a strong constant: LTO folds it, so an application links only
// its own store's code; a weak definition would not be folded right by
// avr-gcc 5.4). The native PSL has a weak one (kLogEeprom) for host
// programs that link the runtime without a recorder.
static const uint8_t kLogEeprom = 0xFF;
extern const uint8_t log_nor_cs;
static const uint16_t kLogNorSector = 4096;  // bytes a sector erase clears; records never straddle one

// How an element is stored (docs/recorder.md, "Encodings").
enum LogEnc : uint8_t {
    kLogRaw = 0,    // its bytes, every sample (`width` of them: narrowed state numbers)
    kLogHold = 1,   // its bytes once in the record's header; a change is an escape in the samples
    kLogDelta = 2,  // round(value / step): 4 bytes in the first sample, then 1 signed byte of difference
    kLogQuant = 3,  // round(value / step), 2 signed bytes every sample
};

// One logged element (FSW_FLASH, in record order).
struct LogField {
    uint16_t off;   // its offset in the state vector
    uint8_t type;   // ElemType
    uint8_t enc;    // LogEnc
    uint8_t width;  // bytes of its absolute value in a sample (raw/hold: stored bytes; delta 4; quant 2)
    float scale;    // delta, quant: 1 / step
};

// The recorder's tables (FSW_FLASH).
struct LogConfig {
    // the fields every run of the task reads, first: log_task reads only
    // these, a field at a time, unless the run takes a sample or has work
    // to do (then it copies the whole table)
    const uint8_t* sv;          // the state vector
    const uint8_t* divider;     // per state id (0..n_states-1; id 0 unused): task runs between samples, 0: none
    uint16_t state_off;         // the machine's `S` element (U32)
    uint16_t runs_mod;          // a multiple of every divider: the run counter wraps there
    uint8_t n_states;           // rows of divider / erase_ok
    uint8_t trigger;            // the state whose entry starts a flight
    // the rest
    const LogField* fields;     // n_fields rows
    const uint8_t* erase_ok;    // per state id: 1 where an erase is allowed
    uint8_t* ring;              // RAM: ring_cap samples of sample_size bytes (time u16 first)
    uint8_t* fifo;              // RAM: fifo_cap bytes waiting for the store
    uint8_t* last;              // RAM: the previous sample's absolute values (sample_size - 2 bytes)
    uint32_t schema;            // schema hash of the application
    uint32_t hash;              // log hash: fields, encodings, record size (docs/recorder.md)
    uint32_t before_ms;         // kept before the trigger
    uint16_t time_off;          // the time element `G` (U64, ms or us)
    uint32_t base;              // store address of slot 0
    uint16_t slots;             // records the store holds
    uint16_t period_ms;         // one task run, ms
    uint8_t record;             // bytes per record, 32..255
    uint8_t n_fields;
    uint8_t sample_size;        // bytes of a ring entry: time (low 16 bits, ms), then each field's width
    uint8_t ring_cap;
    uint8_t fifo_cap;
    uint8_t n_hold;             // fields 0..n_hold-1 are held; the delta fields follow them
    bool escape;                // the first field after the held ones is a delta: a held change is an
                                // escape in the samples (else it closes the record)
    bool newest;                // full: overwrite the oldest records (else stop)
    bool time_us;               // `G` counts microseconds
};


// What the recorder is doing (Recorder::mode).
enum LogMode : uint8_t {
    kLogIdle = 0,       // waiting for the trigger; samples go round the RAM ring
    kLogRecording = 1,  // a flight is being recorded
    kLogFull = 2,       // the store is full (`full stop`): nothing more until an erase
    kLogErasing = 3,    // an erase is under way
};

// The recorder's run-time record (RAM).
struct Recorder {
    const LogConfig* cfg;   // FSW_FLASH
    uint32_t t_next;        // the open record: time its next sample must have
    uint16_t head;          // slot of the record being built (or the next one)
    uint16_t seq;           // its sequence number
    uint16_t dropped;       // samples lost: the ring was full (saturates)
    uint16_t crc;           // CRC of the open record's bytes so far
    uint16_t runs;          // task runs since boot, modulo runs_mod: a sample every `divider` of them
    uint16_t w_slot;        // the writer: slot and byte it writes next
    uint16_t period;        // the open record's sample period, ms (0: one sample so far)
    uint8_t w_pos;
    uint8_t w_phase;        // fsw_log.cpp
    uint8_t kind;           // the open record's kind (kLogStart, kLogData)
    uint8_t flags;          // fsw_log.cpp
    uint8_t flight;         // number of the current (or last) flight
    uint8_t mode;           // LogMode
    uint8_t r_first;        // ring: oldest sample
    uint8_t r_len;          // ring: samples in it
    uint8_t f_head;         // fifo: oldest byte
    uint8_t f_len;          // fifo: bytes in it
    uint8_t used;           // bytes of the open record so far (0: none open)
    uint8_t state;          // the machine's state at the last run
    uint16_t rd_slot;       // the record a LOG_READ being acknowledged reads (the link keeps
                            // its offset and count)
    uint8_t countdown;      // task runs to the next sample in this state (runs % divider, kept)
};

// Boot: finds the newest valid record (blocking reads of each record's
// bytes: a few ms for an Uno's EEPROM) and goes on after it. On an SPI NOR
// flash: a binary search for the first blank slot (every byte 0xFF), then
// the newest valid record before it; a torn record there is skipped. Out of
// line: the frame is on the stack at boot only, not in main()'s.
FSW_NOINLINE void log_eeprom_begin(Recorder& r, const LogConfig* cfg);
FSW_NOINLINE void log_nor_begin(Recorder& r, const LogConfig* cfg);
// After the firmware resumed its flight from a reset in flight
// (fsw_resume.h): `flight` and `mode` are the recorder's as kept. A flight
// that was being recorded goes on with the same number: a start record is
// written again (`fsw dump` shows the flight as resumed there), then its
// samples; the record that was open at the reset is lost, as at a power cut.
void log_resume(Recorder& r, uint8_t flight, uint8_t mode);
// The recorder task's step (ctx = the Recorder): samples, the trigger, the
// encoder (a record's opening, or at most two queued samples appended, a
// run: the ring holds the rest). Never blocks, never faults.
Result log_task(void* recorder);
// The background writer: the next byte into the store when it is ready
// (on an SPI NOR flash, a command whenever the chip is not busy). Called
// from loop() between cycles.
void log_eeprom_poll(Recorder& r);
void log_nor_poll(Recorder& r);
// Whether the writer has bytes to put into the store (either store).
bool log_busy(const Recorder& r);
// The store's entry points, chosen where log_nor_cs is known: the generated
// code, which defines it, calls these, so the compiler drops the other
// store's calls before the link (LTO alone does not fold the constant away).
inline void log_begin(Recorder& r, const LogConfig* cfg) {
    if (log_nor_cs != kLogEeprom) log_nor_begin(r, cfg);
    else log_eeprom_begin(r, cfg);
}
inline void log_poll(Recorder& r) {
    if (log_nor_cs != kLogEeprom) log_nor_poll(r);
    else log_eeprom_poll(r);
}
// Starts erasing the log (every record's first byte cleared; on an SPI NOR
// flash the sectors in use, the last first); false when the
// machine is in a state that forbids it or a flight is being recorded.
bool log_erase(Recorder& r);
// `n` bytes of slot `slot` from `off` into `out` (a dump reads raw records).
// The runtime's is the EEPROM's, weak: the generated code of an application
// on an SPI NOR flash defines log_read as log_nor_read.
void log_read(const Recorder& r, uint16_t slot, uint8_t off, uint8_t n, uint8_t* out);
void log_nor_read(const Recorder& r, uint16_t slot, uint8_t off, uint8_t n, uint8_t* out);

// ---- compile-time checks of the tables -----------------------------------------
// Records of at least the header, one sample and the tail; a sample that
// fits the fifo; a ring of at least two samples.
// `opening`: a data record's header and first sample (and a start record's
// 16 bytes; all but the kind go through the fifo); `worst_sample`: the most
// bytes a later sample takes.
constexpr bool log_config_ok(uint16_t record, uint8_t opening, uint8_t worst_sample, uint8_t ring_cap,
                             uint8_t fifo_cap, uint16_t slots) {
    return record >= 32 && record <= 255 && static_cast<uint16_t>(opening + worst_sample + kLogTail) <= record &&
           opening <= static_cast<uint16_t>(fifo_cap + 1u) &&
           worst_sample <= fifo_cap && ring_cap >= 2 && slots >= 2;
}

}  // namespace fsw

#endif  // FSW_LOG_H
