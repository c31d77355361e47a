// The flight recorder (docs/recorder.md). Three parts that never wait:
//   - the task samples the chosen elements into a RAM ring (before the
//     trigger the ring keeps the newest `before` seconds; after it, it is the
//     queue in front of the encoder);
//   - the encoder turns queued samples into the bytes of the open record
//     (held values in its header, deltas, escapes) and pushes them into a
//     small fifo, closing the record when a sample does not fit it;
//   - the writer (log_poll) puts one fifo byte into the EEPROM whenever it is
//     ready: a record's first byte is cleared first and written last, so a
//     power cut leaves every record whole or invalid. On an SPI NOR flash
//     (log_nor_cs; docs/recorder.md, "On an SPI NOR flash chip") it programs
//     a few bytes at a time whenever the chip is not busy, erases a sector
//     before its first record, and programs the kind last (an erased byte
//     reads 0xFF).
#include "fsw_log.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "fsw_crc.h"
#include "fsw_pal.h"

namespace fsw {

namespace {

// The writer's phases (Recorder::w_phase).
enum Phase : uint8_t {
    kWIdle = 0,
    kWClear = 1,  // the record's first byte becomes 0: no longer a valid record
    kWBody = 2,   // fifo bytes, in order, from byte 1
    kWTail = 3,   // the record is sealed: period, used, CRC at its end
    kWMagic = 4,  // last: its kind, and the record is whole
    kWErase = 5,  // every record's first byte becomes 0
};

// Recorder::flags
static const uint8_t kSealed = 0x01;     // the open record takes no more bytes
static const uint8_t kStartDue = 0x02;   // the flight's start record is still to be written
static const uint8_t kEnding = 0x04;     // the state records nothing: close the flight once drained

// Whether the writer has something to do: a phase, and in the body phase
// queued bytes or a sealed record. The loop calls the writer at every
// wake-up (every UART interrupt): an open record waiting for its next
// sample costs it this test only.
bool log_writing(const Recorder& r) {
    return r.w_phase != kWIdle && (r.w_phase != kWBody || r.f_len != 0 || (r.flags & kSealed) != 0);
}


uint8_t table_u8(const uint8_t* table, uint8_t i) { return flash_u8(table + i); }

uint32_t slot_addr(const LogConfig& c, uint16_t slot) {
    return flash_get(c.base) + static_cast<uint32_t>(slot) * flash_get(c.record);
}

uint8_t store_read(uint32_t addr) { return pal::eeprom_read(static_cast<uint16_t>(addr)); }

// A sealed record's last bytes: period, used, and the CRC of the record's
// bytes (r.crc) then those three.
void tail_bytes(const Recorder& r, uint8_t out[kLogTail]) {
    out[0] = static_cast<uint8_t>(r.period);
    out[1] = static_cast<uint8_t>(r.period >> 8);
    out[2] = r.used;
    uint16_t crc = r.crc;
    for (uint8_t i = 0; i < 3; ++i) crc = crc16_update(crc, out[i]);
    out[3] = static_cast<uint8_t>(crc);
    out[4] = static_cast<uint8_t>(crc >> 8);
}

// The record's kind is written: it is whole, and the next goes in the next slot.
void record_written(const LogConfig& c, Recorder& r) {
    r.w_phase = kWIdle;
    r.used = 0;
    r.flags = static_cast<uint8_t>(r.flags & ~kSealed);
    ++r.head;
    ++r.seq;
    if (r.head >= flash_get(c.slots) && !flash_get(c.newest)) r.mode = kLogFull;
}

// ---- the SPI NOR flash (W25Q-class; docs/recorder.md, "On an SPI NOR flash chip") ----
// Commands used: 05h status register 1 (BUSY bit 0), 06h write enable,
// 03h read, 02h page program, 20h 4 KiB sector erase.
const uint8_t kNorStatus = 0x05, kNorWriteEnable = 0x06, kNorRead = 0x03, kNorProgram = 0x02, kNorErase = 0x20;

// Selects the chip and sends `op` and a 24-bit address.
void nor_cmd(uint8_t op, uint32_t a) {
    pal::spi_select(true);
    pal::spi_transfer(op);
    pal::spi_transfer(static_cast<uint8_t>(a >> 16));
    pal::spi_transfer(static_cast<uint8_t>(a >> 8));
    pal::spi_transfer(static_cast<uint8_t>(a));
}

void nor_read(uint32_t a, uint8_t* out, uint8_t n) {
    nor_cmd(kNorRead, a);
    for (uint8_t i = 0; i < n; ++i) out[i] = pal::spi_transfer(0xFF);
    pal::spi_select(false);
}

// Whether the chip takes a command (no program or erase in progress).
bool nor_ready() {
    pal::spi_select(true);
    pal::spi_transfer(kNorStatus);
    const uint8_t st = pal::spi_transfer(0xFF);
    pal::spi_select(false);
    return (st & 0x01u) == 0;
}

// Write enable, then `op` at `a`, the chip left selected for a page
// program's bytes (a program never crosses a page: records are 32..128
// bytes, powers of two, inside one).
void nor_start(uint8_t op, uint32_t a) {
    pal::spi_select(true);
    pal::spi_transfer(kNorWriteEnable);
    pal::spi_select(false);
    nor_cmd(op, a);
}

// Starts a page program of `n` bytes at `a` or, with n == 0, a sector erase.
void nor_write(uint32_t a, const uint8_t* p, uint8_t n) {
    nor_start(n == 0 ? kNorErase : kNorProgram, a);
    for (uint8_t i = 0; i < n; ++i) pal::spi_transfer(p[i]);
    pal::spi_select(false);
}

// Whether every byte of slot `s` is erased (0xFF): nothing was written there.
bool nor_blank(const LogConfig& c, uint16_t s) {
    nor_cmd(kNorRead, slot_addr(c, s));
    bool blank = true;
    const uint8_t record = flash_get(c.record);
    for (uint8_t i = 0; i < record && blank; ++i) blank = pal::spi_transfer(0xFF) == 0xFF;
    pal::spi_select(false);
    return blank;
}

// Whether slot `s` holds a whole record (as slot_valid): its tail, then its
// bytes in one read.
bool nor_valid(const LogConfig& c, uint16_t s, uint16_t& seq, uint8_t& flight) {
    const uint32_t a = slot_addr(c, s);
    uint8_t tail[kLogTail];
    nor_read(a + flash_get(c.record) - kLogTail, tail, kLogTail);
    const uint8_t used = tail[2];
    if (used < kLogHeader || used > flash_get(c.record) - kLogTail) return false;
    uint8_t head[4];
    uint16_t crc = kCrcInit;
    nor_cmd(kNorRead, a);
    for (uint8_t i = 0; i < used; ++i) {
        const uint8_t b = pal::spi_transfer(0xFF);
        if (i < 4) head[i] = b;
        crc = crc16_update(crc, b);
    }
    pal::spi_select(false);
    for (uint8_t i = 0; i < 3; ++i) crc = crc16_update(crc, tail[i]);
    if ((head[0] != kLogStart && head[0] != kLogData) || crc != static_cast<uint16_t>(tail[3] | (tail[4] << 8)))
        return false;
    seq = static_cast<uint16_t>(head[1] | (head[2] << 8));
    flight = head[3];
    return true;
}

// Boot on the flash: the records were written from slot 0 on, so the first
// blank slot ends them (a binary search); the newest valid record is the
// last one before it that checks (torn ones, their kind never programmed,
// are skipped and never written again).
void nor_begin(const LogConfig& c, Recorder& r) {
    uint16_t lo = 0, hi = flash_get(c.slots);  // slots below lo are written, from hi on blank
    while (lo < hi) {
        const uint16_t mid = static_cast<uint16_t>(lo + (hi - lo) / 2u);
        if (nor_blank(c, mid)) hi = mid;
        else lo = static_cast<uint16_t>(mid + 1u);
    }
    r.head = lo;
    for (uint16_t s = lo; s-- > 0;) {
        uint16_t seq;
        uint8_t flight;
        if (nor_valid(c, s, seq, flight)) {
            r.seq = static_cast<uint16_t>(seq + 1u);
            r.flight = flight;
            break;
        }
    }
    if (r.head >= flash_get(c.slots)) r.mode = kLogFull;
}

// The writer on the flash: one command whenever the chip is not busy (the
// sleeping executor's loop runs about once a cycle: a program takes every
// byte the fifo holds). A sealed record's tail, then its kind, follow in the
// next passes.
void nor_poll(Recorder& r) {
    if (!log_writing(r) || !nor_ready()) return;
    const LogConfig& c = *r.cfg;
    const uint32_t a = slot_addr(c, r.w_slot);
    switch (r.w_phase) {
    case kWClear:  // a sector's first record: the sector is erased first
        r.w_phase = kWBody;
        r.w_pos = 1;
        if ((a & (kLogNorSector - 1u)) == 0) {
            nor_write(a, 0, 0);
            return;
        }
        // fall through - the body's first bytes in this pass
    case kWBody:
        if (r.f_len != 0) {  // every queued byte in one program
            nor_start(kNorProgram, a + r.w_pos);
            r.w_pos = static_cast<uint8_t>(r.w_pos + r.f_len);
            const uint8_t* const fifo = flash_get(c.fifo);
            const uint8_t cap = flash_get(c.fifo_cap);
            do {
                pal::spi_transfer(fifo[r.f_head]);
                r.f_head = static_cast<uint8_t>(r.f_head + 1u == cap ? 0u : r.f_head + 1u);
            } while (--r.f_len != 0);
            pal::spi_select(false);
            if (r.flags & kSealed) r.w_phase = kWTail;  // the tail in the next pass
            return;
        }
        if (!(r.flags & kSealed)) return;
        r.w_phase = kWTail;
        // fall through - nothing queued: the tail in this pass
    case kWTail: {
        uint8_t tail[kLogTail];
        tail_bytes(r, tail);
        nor_write(a + flash_get(c.record) - kLogTail, tail, kLogTail);
        r.w_phase = kWMagic;
        return;
    }
    case kWMagic:  // last: the kind, and the record is whole
        nor_write(a, &r.kind, 1);
        record_written(c, r);  // `full newest` is refused on a flash: full stops it
        return;
    case kWErase: {  // the sectors in use, from the one of `head` down to sector 0; `head` counts down
        const uint16_t per = static_cast<uint16_t>(kLogNorSector / flash_get(c.record));
        uint16_t s = r.head < flash_get(c.slots) ? r.head : static_cast<uint16_t>(flash_get(c.slots) - 1u);
        s = static_cast<uint16_t>(s - s % per);
        nor_write(slot_addr(c, s), 0, 0);
        if (s == 0) {
            r.w_phase = kWIdle;
            r.mode = kLogIdle;
        }
        r.head = s == 0 ? 0 : static_cast<uint16_t>(s - 1u);
        return;
    }
    default:
        r.w_phase = kWIdle;
    }
}

// Whether slot `s` holds a whole record; its sequence number and flight.
bool slot_valid(const LogConfig& c, uint16_t s, uint16_t& seq, uint8_t& flight) {
    const uint32_t a = slot_addr(c, s);
    const uint8_t magic = store_read(a);
    if (magic != kLogStart && magic != kLogData) return false;
    const uint8_t record = flash_get(c.record);
    const uint8_t used = store_read(a + record - 3u);
    if (used < kLogHeader || used > record - kLogTail) return false;
    uint16_t crc = kCrcInit;
    for (uint8_t i = 0; i < used; ++i) crc = crc16_update(crc, store_read(a + i));
    for (uint8_t i = static_cast<uint8_t>(record - kLogTail); i < record - 2u; ++i) crc = crc16_update(crc, store_read(a + i));
    const uint16_t stored = static_cast<uint16_t>(store_read(a + record - 2u) | (store_read(a + record - 1u) << 8));
    if (crc != stored) return false;
    seq = static_cast<uint16_t>(store_read(a + 1u) | (store_read(a + 2u) << 8));
    flight = store_read(a + 3u);
    return true;
}

uint32_t now_ms(const LogConfig& c) {
    uint64_t t;
    memcpy(&t, flash_get(c.sv) + flash_get(c.time_off), sizeof t);
    if (flash_get(c.time_us)) t /= 1000u;
    return static_cast<uint32_t>(t);
}

uint8_t state_of(const LogConfig& c) {
    uint32_t s;
    memcpy(&s, flash_get(c.sv) + flash_get(c.state_off), sizeof s);
    return s < flash_get(c.n_states) ? static_cast<uint8_t>(s) : 0u;
}

// round(v * scale), saturated at +-lim: 0x7FFFFFFF (`wide`, a delta's
// absolute value) or 0x7FFF (quant); NaN gives -lim. The limits are
// compared as binary32 constants (2^31 - 1 rounds to 2^31), not converted
// at each call.
int32_t quantise(float v, float scale, bool wide) {
    const float q = v * scale;
    const int32_t lim = wide ? 0x7FFFFFFFL : 0x7FFFL;
    const float flim = wide ? static_cast<float>(0x7FFFFFFFL) : static_cast<float>(0x7FFFL);
    if (!(q > -flim)) return -lim;  // NaN too
    if (q > flim) return lim;
    return static_cast<int32_t>(lroundf(q));
}

// One sample of every field, absolute, into `out` (sample_size - 2 bytes).
// A field's step is read only for the fields that are rounded to it.
void take(const LogConfig& c, uint8_t* out) {
    const uint8_t n_fields = flash_get(c.n_fields);
    const LogField* const fields = flash_get(c.fields);
    const uint8_t* const sv = flash_get(c.sv);
    for (uint8_t i = 0; i < n_fields; ++i) {
        const LogField* f = &fields[i];
        const uint8_t* o = reinterpret_cast<const uint8_t*>(&f->off);  // little-endian targets
        const uint8_t* p = sv + static_cast<uint16_t>(flash_u8(o) | flash_u8(o + 1) << 8);
        const uint8_t enc = flash_u8(&f->enc), width = flash_u8(&f->width);
        if (enc == kLogDelta || enc == kLogQuant) {
            float scale, v;
            flash_read(&scale, &f->scale, sizeof scale);
            memcpy(&v, p, sizeof v);
            const int32_t q = quantise(v, scale, enc == kLogDelta);
            memcpy(out, &q, width);  // little-endian: the low bytes
        } else {
            memcpy(out, p, width);
        }
        out += width;
    }
}

uint8_t* ring_at(const LogConfig& c, const Recorder& r, uint8_t k) {
    uint8_t i = static_cast<uint8_t>(r.r_first + k);
    const uint8_t cap = flash_get(c.ring_cap);
    if (i >= cap) i = static_cast<uint8_t>(i - cap);
    return flash_get(c.ring) + static_cast<uint16_t>(i) * flash_get(c.sample_size);
}

void ring_pop(const LogConfig& c, Recorder& r) {
    r.r_first = static_cast<uint8_t>(r.r_first + 1u == flash_get(c.ring_cap) ? 0u : r.r_first + 1u);
    --r.r_len;
}

// A ring sample's full time from its low 16 bits: samples are younger than 65 s.
uint32_t sample_time(const uint8_t* s, uint32_t now) {
    uint16_t t16;
    memcpy(&t16, s, 2);
    return now - static_cast<uint16_t>(static_cast<uint16_t>(now) - t16);
}

// The fifo position after the queued bytes (16-bit sum: a fifo may hold up to 255).
uint8_t fifo_end(const LogConfig& c, const Recorder& r) {
    uint16_t i = static_cast<uint16_t>(r.f_head + r.f_len);
    const uint8_t cap = flash_get(c.fifo_cap);
    if (i >= cap) i = static_cast<uint16_t>(i - cap);
    return static_cast<uint8_t>(i);
}

// Copies `n` bytes into the fifo from position `at`: the position after them.
FSW_NOINLINE uint8_t fifo_put(uint8_t* fifo, uint8_t cap, uint8_t at, const uint8_t* p, uint8_t n) {
    for (uint8_t k = 0; k < n; ++k) {
        fifo[at] = p[k];
        at = static_cast<uint8_t>(at + 1u == cap ? 0u : at + 1u);
    }
    return at;
}

// Bytes staged after the queued ones in the fifo, not yet part of the
// record: as many as the fifo has room for are written, all are counted.
// `commit` then takes them into the record (its size and CRC).
struct Stage {
    uint8_t* fifo;
    uint8_t cap;
    uint8_t at;    // where the next one goes
    uint8_t room;  // free bytes of the fifo
    uint8_t n;     // bytes staged
    void put_n(const uint8_t* p, uint8_t k) {
        if (n < room) at = fifo_put(fifo, cap, at, p, static_cast<uint8_t>(room - n < k ? room - n : k));
        n = static_cast<uint8_t>(n + k);
    }
    void put(uint8_t b) { put_n(&b, 1); }
};

Stage stage(const LogConfig& c, const Recorder& r) {
    Stage w;
    w.fifo = flash_get(c.fifo);
    w.cap = flash_get(c.fifo_cap);
    w.at = fifo_end(c, r);
    w.room = static_cast<uint8_t>(w.cap - r.f_len);
    w.n = 0;
    return w;
}

// The `n` staged bytes (all written: n <= the fifo's room) join the record.
void commit(const LogConfig& c, Recorder& r, uint8_t n) {
    uint8_t i = fifo_end(c, r);
    uint8_t hi = static_cast<uint8_t>(r.crc >> 8), lo = static_cast<uint8_t>(r.crc);
    const uint8_t* const fifo = flash_get(c.fifo);
    const uint8_t cap = flash_get(c.fifo_cap);
    for (uint8_t k = 0; k < n; ++k) {
        crc16_step(hi, lo, fifo[i]);
        i = static_cast<uint8_t>(i + 1u == cap ? 0u : i + 1u);
    }
    r.crc = static_cast<uint16_t>(hi << 8 | lo);
    r.f_len = static_cast<uint8_t>(r.f_len + n);
    r.used = static_cast<uint8_t>(r.used + n);
}

// Opens a record of `kind` in the head slot with its header and the `n`
// bytes at `body` after it (a record's opening fits the empty fifo,
// log_config_ok): false when the store is full.
bool open_record(const LogConfig& c, Recorder& r, uint8_t kind, uint32_t t0, const uint8_t* body, uint8_t n) {
    if (r.head >= flash_get(c.slots)) {
        if (!flash_get(c.newest)) {
            r.mode = kLogFull;
            return false;
        }
        r.head = 0;
    }
    r.kind = kind;
    r.used = 1;  // the kind: written last, counted in the CRC first
    r.crc = crc16_update(kCrcInit, kind);
    r.period = 0;
    r.flags = static_cast<uint8_t>(r.flags & ~kSealed);
    r.w_slot = r.head;
    r.w_phase = kWClear;
    // seq, flight, t0 (little-endian targets, fsw_config.h), then the body:
    // into the empty fifo, then into the record
    uint8_t* const fifo = flash_get(c.fifo);
    const uint8_t cap = flash_get(c.fifo_cap);
    uint8_t at = fifo_put(fifo, cap, fifo_end(c, r), reinterpret_cast<const uint8_t*>(&r.seq), 2);
    at = fifo_put(fifo, cap, at, &r.flight, 1);
    at = fifo_put(fifo, cap, at, reinterpret_cast<const uint8_t*>(&t0), 4);
    fifo_put(fifo, cap, at, body, n);
    commit(c, r, static_cast<uint8_t>(7u + n));
    return true;
}

void seal(Recorder& r) { r.flags |= kSealed; }

// The flight's start record: trigger time, schema and log hashes.
void write_start(const LogConfig& c, Recorder& r, uint32_t now) {
    static_assert(offsetof(LogConfig, hash) == offsetof(LogConfig, schema) + 4, "LogConfig: schema, hash");
    uint8_t hashes[8];  // schema, hash: out of flash, as they lie
    flash_read(hashes, &c.schema, sizeof hashes);
    if (!open_record(c, r, kLogStart, now, hashes, sizeof hashes)) return;
    seal(r);
    r.flags = static_cast<uint8_t>(r.flags & ~kStartDue);
}

// Stages the bytes the sample `s` (time t) takes appended to the open
// record, in one pass over the fields: a changed held value's escape
// ([0x80, field, value]; the held fields come first), then each delta's
// difference and the other fields' values. Returns their number, 0 when it
// cannot be appended: another period, a difference out of range, a held
// change without escapes, or no room in the record.
uint8_t stage_sample(const LogConfig& c, const Recorder& r, const uint8_t* s, uint32_t t, Stage& w) {
    if (r.period == 0 ? t == r.t_next || t - r.t_next > 0xFFFFu : t != r.t_next + r.period) return 0;
    const uint8_t* v = s + 2;
    const uint8_t* l = flash_get(c.last);
    const uint8_t n_fields = flash_get(c.n_fields);
    const LogField* const fields = flash_get(c.fields);
    for (uint8_t i = 0; i < n_fields; ++i) {
        const uint8_t enc = flash_u8(&fields[i].enc), width = flash_u8(&fields[i].width);
        if (enc == kLogHold) {
            uint8_t k = 0;  // a held value is a few bytes: compared here, not by a library call
            while (k < width && v[k] == l[k]) ++k;
            if (k != width) {
                if (!flash_get(c.escape)) return 0;
                w.put(kLogEscape);
                w.put(i);
                w.put_n(v, width);
            }
        } else if (enc == kLogDelta) {
            int32_t q, p;
            memcpy(&q, v, 4);
            memcpy(&p, l, 4);
            const int32_t d = q - p;
            if (d < -127 || d > 127) return 0;
            w.put(static_cast<uint8_t>(static_cast<int8_t>(d)));
        } else {
            w.put_n(v, width);
        }
        v += width;
        l += width;
    }
    return r.used + w.n + kLogTail <= flash_get(c.record) ? w.n : 0;
}

// Samples the encoder appends to the open record in one run of the task
// at most; a run that opens a record (its header and first sample) does
// only that. The ring queues the rest: the seconds kept before the trigger
// drain over the next runs, faster than samples come (at most one a run),
// and no run does all of it.
const uint8_t kEncodePerRun = 2;

// Moves queued samples into records while the fifo has room: a record's
// opening, or at most kEncodePerRun samples appended.
void encode(const LogConfig& c, Recorder& r, uint32_t now) {
    for (uint8_t moved = 0; moved < kEncodePerRun; ++moved) {
        if (r.w_phase >= kWTail || (r.flags & kSealed)) return;  // the sealed record is being finished
        if (r.w_phase == kWIdle) {  // nothing open
            if (r.mode != kLogRecording) return;
            if (r.flags & kStartDue) {
                write_start(c, r, now);
                return;
            }
            if (r.r_len == 0) {
                if (r.flags & kEnding) r.mode = kLogIdle;  // the flight is over
                return;
            }
            const uint8_t* s = ring_at(c, r, 0);
            const uint32_t t = sample_time(s, now);
            // held values, then the first sample: the sample's bytes as they lie
            if (!open_record(c, r, kLogData, t, s + 2, static_cast<uint8_t>(flash_get(c.sample_size) - 2u))) return;
            memcpy(flash_get(c.last), s + 2, flash_get(c.sample_size) - 2u);
            r.t_next = t;
            ring_pop(c, r);
            return;  // an opening is a whole run's work
        }
        if (r.r_len == 0) {
            if (r.flags & kEnding) seal(r);
            return;
        }
        const uint8_t* s = ring_at(c, r, 0);
        const uint32_t t = sample_time(s, now);
        Stage w = stage(c, r);
        const uint8_t n = stage_sample(c, r, s, t, w);
        if (n == 0) {
            seal(r);
            return;
        }
        if (n > w.room) return;  // the writer catches up first
        if (r.period == 0) r.period = static_cast<uint16_t>(t - r.t_next);
        r.t_next = t;
        commit(c, r, n);
        memcpy(flash_get(c.last), s + 2, flash_get(c.sample_size) - 2u);
        ring_pop(c, r);
    }
}

// Before the trigger: drops the oldest samples while the one after it is
// still at least `before` old, so what is kept covers `before` whole.
void trim(const LogConfig& c, Recorder& r, uint32_t now) {
    while (r.r_len >= 2 && now - sample_time(ring_at(c, r, 1), now) >= flash_get(c.before_ms)) ring_pop(c, r);
}

}  // namespace

void log_nor_begin(Recorder& r, const LogConfig* cfg) {
    memset(&r, 0, sizeof r);
    r.cfg = cfg;
    const LogConfig& c = *r.cfg;
    pal::spi_begin(log_nor_cs);
    nor_begin(c, r);
    r.state = state_of(c);
}

void log_nor_poll(Recorder& r) {
    if (r.w_phase != kWIdle) nor_poll(r);
}

void log_nor_read(const Recorder& r, uint16_t slot, uint8_t off, uint8_t n, uint8_t* out) {
    const LogConfig& c = *r.cfg;
    nor_read(slot_addr(c, slot) + off, out, n);
}

void log_eeprom_begin(Recorder& r, const LogConfig* cfg) {
    memset(&r, 0, sizeof r);
    r.cfg = cfg;
    const LogConfig& c = *r.cfg;
    bool any = false;
    uint16_t best = 0, best_seq = 0;
    uint8_t best_flight = 0;
    const uint16_t slots = flash_get(c.slots);
    for (uint16_t s = 0; s < slots; ++s) {
        uint16_t seq;
        uint8_t flight;
        if (!slot_valid(c, s, seq, flight)) continue;
        if (!any || static_cast<int16_t>(seq - best_seq) > 0) {
            any = true;
            best = s;
            best_seq = seq;
            best_flight = flight;
        }
    }
    if (any) {
        r.head = static_cast<uint16_t>(best + 1u);
        r.seq = static_cast<uint16_t>(best_seq + 1u);
        r.flight = best_flight;
        if (r.head >= slots && !flash_get(c.newest)) r.mode = kLogFull;
    }
    r.state = state_of(c);
}

void log_resume(Recorder& r, uint8_t flight, uint8_t mode) {
    if (mode != kLogRecording || r.mode != kLogIdle) return;  // nothing to go on with, or the store is full
    r.mode = kLogRecording;
    r.flight = flight;
    r.flags = kStartDue;
}

namespace {

// The rest of a run that takes a sample, sees the state change or has
// bytes to encode: out of line (its frame on the stack, and the registers
// it saves, are not paid by the other runs). The table is read out of
// flash a field at a time where it is used, here and in the writer: a copy
// of the whole (49 bytes) made this the deepest frame of the rocket's stack.
FSW_NOINLINE void log_run(Recorder& r, uint8_t st, uint8_t prev, uint8_t div, bool sample) {
    const LogConfig& c = *r.cfg;
    const uint32_t now = now_ms(c);
    const uint8_t trigger = flash_get(c.trigger);
    if (r.mode == kLogIdle && st == trigger && prev != trigger) {
        r.mode = kLogRecording;
        r.flight = static_cast<uint8_t>(r.flight == 0xFF ? 1u : r.flight + 1u);
        r.flags = kStartDue;
        trim(c, r, now);
    }
    if (r.mode == kLogRecording) {
        if (div == 0) r.flags |= kEnding;
        else r.flags = static_cast<uint8_t>(r.flags & ~kEnding);
    }
    if (sample && (r.mode == kLogIdle || r.mode == kLogRecording)) {
        const uint8_t ring_cap = flash_get(c.ring_cap);
        if (r.r_len == ring_cap) {
            if (r.mode == kLogIdle) {
                ring_pop(c, r);  // before the trigger: the oldest goes
            } else if (r.dropped != 0xFFFFu) {
                ++r.dropped;
            }
        }
        if (r.r_len < ring_cap) {
            uint8_t* s = ring_at(c, r, r.r_len);
            const uint16_t t16 = static_cast<uint16_t>(now);
            memcpy(s, &t16, 2);
            take(c, s + 2);
            ++r.r_len;
        }
        if (r.mode == kLogIdle) trim(c, r, now);  // keep only what the trigger would commit
    }
    encode(c, r, now);
}

}  // namespace

Result log_task(void* ctx) {
    Recorder& r = *static_cast<Recorder*>(ctx);
    // Most runs take no sample and find nothing to encode: they read only
    // the first fields of the table, a field at a time, and count the run.
    const LogConfig& h = *r.cfg;
    const uint8_t* const sv = flash_get(h.sv);
    uint32_t s32;
    memcpy(&s32, sv + flash_get(h.state_off), sizeof s32);
    const uint8_t st = s32 < flash_get(h.n_states) ? static_cast<uint8_t>(s32) : 0u;
    const uint8_t prev = r.state;
    r.state = st;
    const uint8_t div = table_u8(flash_get(h.divider), st);
    if (st != prev) r.countdown = static_cast<uint8_t>(div != 0 ? (div - r.runs % div) % div : 0u);  // in phase
    const bool sample = div != 0 && r.countdown == 0;
    if (div != 0) r.countdown = static_cast<uint8_t>((r.countdown == 0 ? div : r.countdown) - 1u);
    if (++r.runs == flash_get(h.runs_mod)) r.runs = 0;
    if (st == prev && !sample &&
        (r.mode != kLogRecording || (r.r_len == 0 && !(r.flags & (kStartDue | kEnding)))))
        return kOk;
    log_run(r, st, prev, div, sample);
    return kOk;
}

namespace {

// The writer's next EEPROM byte (the EEPROM is ready).
void eeprom_next(const LogConfig& c, Recorder& r) {
    const uint32_t a = slot_addr(c, r.w_slot);
    switch (r.w_phase) {
    case kWClear:
        pal::eeprom_write(static_cast<uint16_t>(a), 0x00);
        r.w_phase = kWBody;
        r.w_pos = 1;
        return;
    case kWBody:
        if (r.f_len != 0) {
            pal::eeprom_write(static_cast<uint16_t>(a + r.w_pos), flash_get(c.fifo)[r.f_head]);
            r.f_head = static_cast<uint8_t>(r.f_head + 1u == flash_get(c.fifo_cap) ? 0u : r.f_head + 1u);
            --r.f_len;
            ++r.w_pos;
        } else if (r.flags & kSealed) {
            r.w_phase = kWTail;
            r.w_pos = static_cast<uint8_t>(flash_get(c.record) - kLogTail);
        }
        return;
    case kWTail: {
        uint8_t tail[kLogTail];
        tail_bytes(r, tail);
        pal::eeprom_write(static_cast<uint16_t>(a + r.w_pos), tail[r.w_pos - (flash_get(c.record) - kLogTail)]);
        if (++r.w_pos == flash_get(c.record)) r.w_phase = kWMagic;
        return;
    }
    case kWMagic:
        pal::eeprom_write(static_cast<uint16_t>(a), r.kind);
        record_written(c, r);
        return;
    case kWErase:
        pal::eeprom_write(static_cast<uint16_t>(a), 0x00);
        if (++r.w_slot == flash_get(c.slots)) {
            r.w_phase = kWIdle;
            r.head = 0;
            r.mode = kLogIdle;
        }
        return;
    default:
        r.w_phase = kWIdle;
    }
}

}  // namespace

bool log_busy(const Recorder& r) { return log_writing(r); }

// On an AVR a byte takes 3.4 ms: one is written per call, and the
// EEPROM-ready interrupt wakes the loop for the next. A store that is ready
// again at once (simavr's, the host's model) takes a few per call, so the
// simulated writer is never slower than the silicon's.
namespace {
// Out of line, so that the configuration's copy is on the stack only while
// bytes are written, not in the frame of the loop that polls (generated
// code inlines log_eeprom_poll into main(), whose frame every path pays).
FSW_NOINLINE void eeprom_write_some(Recorder& r) {
    const LogConfig& c = *r.cfg;
    for (uint8_t n = 0; n < 8 && log_writing(r) && pal::eeprom_ready(); ++n) eeprom_next(c, r);
}
}  // namespace

void log_eeprom_poll(Recorder& r) {
    if (!log_writing(r) || !pal::eeprom_ready()) return;
    eeprom_write_some(r);
}

bool log_erase(Recorder& r) {
    const LogConfig& c = *r.cfg;
    if (r.mode == kLogRecording || r.mode == kLogErasing || r.w_phase != kWIdle) return false;
    if (table_u8(flash_get(c.erase_ok), state_of(c)) == 0) return false;
    r.mode = kLogErasing;
    r.r_len = 0;
    r.f_len = 0;
    r.w_slot = 0;
    r.w_phase = kWErase;
    return true;
}

// Weak: an application on an SPI NOR flash defines it (generated: log_nor_read).
__attribute__((weak)) void log_read(const Recorder& r, uint16_t slot, uint8_t off, uint8_t n, uint8_t* out) {
    const LogConfig& c = *r.cfg;
    const uint32_t a = slot_addr(c, slot) + off;
    for (uint8_t i = 0; i < n; ++i) out[i] = store_read(a + i);
}

}  // namespace fsw
