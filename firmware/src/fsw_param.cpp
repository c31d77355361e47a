// Parameters (docs/parameters.md): two EEPROM banks, boot from the newest
// valid one, changes from the ground, and a writer that puts one byte into
// the EEPROM whenever it is ready, so that nothing waits for it.
#include "fsw_param.h"

#include "fsw_app.h"
#include "fsw_crc.h"
#include "fsw_pal.h"


namespace fsw {

namespace {

// The writer's phases.
enum Job : uint8_t {
    kIdle = 0,
    kClearThenStage = 1,  // a load begins: clear the staging bank's magic
    kStage = 2,           // a load is open: staged values go to the bank as they come
    kClear = 3,           // a save begins: clear the target bank's magic
    kValues = 4,          // the value block (a load's staged values are there already)
    kHeader = 5,          // sequence number, table hash, CRC
    kMagic = 6,           // last: the bank is whole
};


ParamDef def(const ParamConfig& c, uint8_t id) {
    ParamDef d;
    flash_read(&d, &flash_get(c.defs)[id], sizeof d);
    return d;
}

uint16_t bank_size(const ParamConfig& c) { return static_cast<uint16_t>(kParamHeader + flash_get(c.size)); }
uint16_t bank_base(const ParamConfig& c, uint8_t bank) {
    return static_cast<uint16_t>(flash_get(c.eeprom_base) + (bank ? bank_size(c) : 0u));
}
// The bank a save or load writes: the one that is not current.
uint8_t target_bank(const ParamStore& s) { return (s.source & 3u) == kParamBankA ? 1u : 0u; }

// A value as a key: `n` bytes, most significant first, whose order as
// unsigned bytes (memcmp) is the value's order. Signed integers have their
// sign bit flipped; floats are sign-magnitude, so a negative one is
// inverted whole and a positive one has its sign bit set; -0 is 0. A NaN's
// key lies beyond an infinity's, so outside every finite range.
void order_key(uint8_t type, const uint8_t* v, uint8_t n, uint8_t* key) {
    bool zero = true;
    for (uint8_t i = 0; i < n; ++i) {
        key[i] = v[n - 1u - i];
        if (i != 0 && key[i] != 0) zero = false;
    }
    if (type == kF32 || type == kF64) {
        if (zero && (key[0] & 0x7Fu) == 0) key[0] = 0;  // -0 is 0
        if (key[0] & 0x80u) {
            for (uint8_t i = 0; i < n; ++i) key[i] = static_cast<uint8_t>(~key[i]);
            return;
        }
    } else if (type > kI64) {
        return;  // unsigned
    }
    key[0] = static_cast<uint8_t>(key[0] ^ 0x80u);
}

// Whether `v` is a value parameter `d` may take (ranges are finite).
bool in_range(const ParamConfig& c, const ParamDef& d, const uint8_t* v) {
    if (d.type == kBool) return v[0] <= 1u;
    // MIN, then MAX, through one buffer (this is on the deepest path of
    // the stack: a ground's SET, through the check of each value)
    uint8_t k[8], raw[8] = {0}, bound[8];
    const uint8_t n = elem_size(d.type);
    const uint8_t* const lim = flash_get(c.pool) + d.range;
    order_key(d.type, v, n, k);
    flash_read(raw, lim, n);
    order_key(d.type, raw, n, bound);
    if (memcmp(bound, k, n) > 0) return false;
    flash_read(raw, lim + n, n);
    order_key(d.type, raw, n, bound);
    return memcmp(k, bound, n) <= 0;
}

// Whether the declaring machine is in a state that allows a change.
bool state_allows(const ParamConfig& c, const ParamDef& d) {
    ParamWhen w;
    flash_read(&w, &flash_get(c.whens)[d.when], sizeof w);
    uint32_t st;
    memcpy(&st, flash_get(c.sv) + w.state_off, sizeof st);
    if (st == 0 || (st - 1u) / 8u >= w.n) return false;
    return (flash_u8(flash_get(c.pool) + w.mask + (st - 1u) / 8u) >> ((st - 1u) % 8u)) & 1u;
}

void set_bytes(const ParamConfig& c, const ParamDef& d, const uint8_t* v) {
    const bool lock = app_has(kAppSvLock) && flash_get(c.lock);  // (fsw_app.h)
    const pal::IrqState saved = lock ? pal::critical_enter() : 0;
    memcpy(d.ptr, v, elem_size(d.type));
    if (lock) pal::critical_exit(saved);
}
void get_bytes(const ParamConfig& c, const ParamDef& d, uint8_t* v) {
    const bool lock = app_has(kAppSvLock) && flash_get(c.lock);  // (fsw_app.h)
    const pal::IrqState saved = lock ? pal::critical_enter() : 0;
    memcpy(v, d.ptr, elem_size(d.type));
    if (lock) pal::critical_exit(saved);
}

// Walks `args`, (id, value)...: kParamOk when every entry is a known id
// with a whole value in range; else the status and the id it stopped at.
uint8_t check_entries(const ParamConfig& c, const uint8_t* a, uint8_t len, uint8_t& bad) {
    uint8_t i = 0;
    if (len == 0) return kParamBadLength;
    while (i < len) {
        const uint8_t id = a[i];
        bad = id;
        if (id >= flash_get(c.n)) return kParamNoParam;
        const ParamDef d = def(c, id);
        const uint8_t n = elem_size(d.type);
        if (static_cast<uint16_t>(i) + 1u + n > len) return kParamBadLength;
        if (!in_range(c, d, a + i + 1)) return kParamOutOfRange;
        i = static_cast<uint8_t>(i + 1u + n);
    }
    bad = 0xFF;
    return kParamOk;
}

// CRC of the live value block, continuing `crc`.
uint16_t live_crc(const ParamConfig& c, uint16_t crc) {
    const uint8_t n = flash_get(c.n);
    for (uint8_t id = 0; id < n; ++id) {
        const ParamDef d = def(c, id);
        uint8_t v[8];
        get_bytes(c, d, v);
        crc = crc16(v, elem_size(d.type), crc);
    }
    return crc;
}

// CRC of a bank's contents: sequence number, table hash, value block (the
// live values, or the EEPROM's at `ee` when `ee` is not 0xFFFF).
uint16_t bank_crc(const ParamConfig& c, uint16_t seq, uint16_t ee) {
    uint16_t crc = kCrcInit;
    crc = crc16_update(crc, static_cast<uint8_t>(seq));
    crc = crc16_update(crc, static_cast<uint8_t>(seq >> 8));
    for (uint8_t i = 0; i < 4; ++i) crc = crc16_update(crc, static_cast<uint8_t>(flash_get(c.hash) >> (8u * i)));
    if (ee == 0xFFFFu) return live_crc(c, crc);
    const uint16_t size = flash_get(c.size);
    for (uint16_t i = 0; i < size; ++i) crc = crc16_update(crc, pal::eeprom_read(static_cast<uint16_t>(ee + i)));
    return crc;
}

// A bank's stored CRC (high byte first, at offset 7).
uint16_t stored_crc(uint16_t base) {
    return static_cast<uint16_t>((pal::eeprom_read(static_cast<uint16_t>(base + 7u)) << 8) |
                                 pal::eeprom_read(static_cast<uint16_t>(base + 8u)));
}

uint16_t ee_u16(uint16_t addr) {
    return static_cast<uint16_t>(pal::eeprom_read(addr) | (pal::eeprom_read(static_cast<uint16_t>(addr + 1u)) << 8));
}

// Whether bank `b` is whole, of this table, with a good CRC and values in
// range; its sequence number in `seq`.
bool bank_valid(const ParamConfig& c, uint8_t b, uint16_t& seq) {
    const uint16_t base = bank_base(c, b);
    if (pal::eeprom_read(base) != kParamMagic) return false;
    seq = ee_u16(static_cast<uint16_t>(base + 1u));
    uint32_t hash = 0;
    for (uint8_t i = 4; i-- > 0;) hash = (hash << 8) | pal::eeprom_read(static_cast<uint16_t>(base + 3u + i));
    if (hash != flash_get(c.hash)) return false;
    const uint16_t stored = stored_crc(base);
    const uint16_t values = static_cast<uint16_t>(base + kParamHeader);
    if (bank_crc(c, seq, values) != stored) return false;
    const uint8_t n = flash_get(c.n);
    for (uint8_t id = 0; id < n; ++id) {
        const ParamDef d = def(c, id);
        uint8_t v[8];
        for (uint8_t k = 0; k < elem_size(d.type); ++k) v[k] = pal::eeprom_read(static_cast<uint16_t>(values + d.off + k));
        if (!in_range(c, d, v)) return false;
    }
    return true;
}

// The live values differ from the current bank (or the defaults).
// Whether a live value differs from its default. Out of line: its two
// buffers are not in refresh_dirty's frame, on the path to the live CRC.
FSW_NOINLINE bool differs_from_defaults(const ParamConfig& c) {
    const uint8_t n = flash_get(c.n);
    for (uint8_t id = 0; id < n; ++id) {
        const ParamDef d = def(c, id);
        uint8_t v[8], w[8];
        get_bytes(c, d, v);
        flash_read(w, flash_get(c.defaults) + d.off, elem_size(d.type));
        if (memcmp(v, w, elem_size(d.type)) != 0) return true;
    }
    return false;
}

void refresh_dirty(ParamStore& s, const ParamConfig& c) {
    bool dirty;
    if ((s.source & 3u) == kParamDefaults) {
        dirty = differs_from_defaults(c);
    } else {
        const uint16_t base = bank_base(c, static_cast<uint8_t>((s.source & 3u) - kParamBankA));
        dirty = bank_crc(c, s.seq, 0xFFFFu) != stored_crc(base);
    }
    s.source = static_cast<uint8_t>((s.source & ~kParamDirty) | (dirty ? kParamDirty : 0u));
}

bool staged(const ParamConfig& c, uint8_t id) { return (flash_get(c.staged)[id >> 3] >> (id & 7u)) & 1u; }

// The byte of the header (bank offsets 1..8) being written, new sequence
// number first.
uint8_t header_byte(const ParamStore& s, const ParamConfig& c, uint8_t i) {
    const uint16_t seq = static_cast<uint16_t>(s.seq + 1u);
    if (i < 2) return static_cast<uint8_t>(seq >> (8u * i));
    if (i < 6) return static_cast<uint8_t>(flash_get(c.hash) >> (8u * (i - 2u)));
    return i == 6 ? static_cast<uint8_t>(s.w_crc >> 8) : static_cast<uint8_t>(s.w_crc);
}

// A bank is being written that a SET, a SAVE or a BEGIN must wait for (the
// writer past kStage): a save, or a committed load. A load still open
// (BEGIN .. COMMIT) holds none of them, so that a ground that left one open
// stops nothing till a reset: a SET changes live values, which the load's
// COMMIT then finds in its CRC; a SAVE ends the load and writes the bank
// the load was staging into; a BEGIN starts the load again.
bool bank_busy(const ParamStore& s) { return s.w_job >= kClear; }

}  // namespace

void param_begin(ParamStore& s, const ParamConfig* cfg) {
    memset(&s, 0, sizeof s);
    s.cfg = cfg;
    const ParamConfig& c = *s.cfg;
    memset(flash_get(c.staged), 0, (flash_get(c.n) + 7u) / 8u);
    uint16_t seq_a = 0, seq_b = 0;
    const bool fits = pal::eeprom_size() >= param_eeprom_end(flash_get(c.eeprom_base), flash_get(c.size));
    const bool a = fits && bank_valid(c, 0, seq_a);
    const bool b = fits && bank_valid(c, 1, seq_b);
    if (a || b) {
        const uint8_t bank = a && b ? (static_cast<int16_t>(seq_b - seq_a) > 0 ? 1u : 0u) : b ? 1u : 0u;
        const uint16_t values = static_cast<uint16_t>(bank_base(c, bank) + kParamHeader);
        const uint8_t n = flash_get(c.n);
        for (uint8_t id = 0; id < n; ++id) {
            const ParamDef d = def(c, id);
            uint8_t v[8];
            for (uint8_t k = 0; k < elem_size(d.type); ++k) v[k] = pal::eeprom_read(static_cast<uint16_t>(values + d.off + k));
            set_bytes(c, d, v);
        }
        s.seq = bank ? seq_b : seq_a;
        s.source = bank ? kParamBankB : kParamBankA;
    } else {
        const uint8_t n = flash_get(c.n);
        for (uint8_t id = 0; id < n; ++id) {
            const ParamDef d = def(c, id);
            uint8_t v[8];
            flash_read(v, flash_get(c.defaults) + d.off, elem_size(d.type));
            set_bytes(c, d, v);
        }
        s.source = kParamDefaults;
    }
}

uint8_t param_set(ParamStore& s, const uint8_t* a, uint8_t len, uint8_t& bad) {
    const ParamConfig& c = *s.cfg;
    bad = 0xFF;
    if (bank_busy(s)) return kParamBusy;
    const uint8_t st = check_entries(c, a, len, bad);
    if (st != kParamOk) return st;
    for (uint8_t i = 0; i < len;) {  // a change only in an allowed state
        const ParamDef d = def(c, a[i]);
        const uint8_t n = elem_size(d.type);
        uint8_t v[8];
        get_bytes(c, d, v);
        if (memcmp(v, a + i + 1, n) != 0 && !state_allows(c, d)) {
            bad = a[i];
            return kParamWrongState;
        }
        i = static_cast<uint8_t>(i + 1u + n);
    }
    for (uint8_t i = 0; i < len;) {
        const ParamDef d = def(c, a[i]);
        const uint8_t n = elem_size(d.type);
        set_bytes(c, d, a + i + 1);
        i = static_cast<uint8_t>(i + 1u + n);
    }
    refresh_dirty(s, c);
    return kParamOk;
}

uint8_t param_save(ParamStore& s) {
    if (bank_busy(s)) return kParamBusy;
    s.loading = 0;  // an open load ends: its STAGE and COMMIT answer NO_LOAD, its staged values never live
    s.source |= kParamWriting;
    s.w_job = kClear;
    return kParamOk;
}

uint8_t param_load_begin(ParamStore& s) {
    if (bank_busy(s)) return kParamBusy;
    const ParamConfig& c = *s.cfg;
    memset(flash_get(c.staged), 0, (flash_get(c.n) + 7u) / 8u);
    s.q_len = 0;
    s.loading = 1;
    s.source |= kParamWriting;
    s.w_job = kClearThenStage;
    return kParamOk;
}

uint8_t param_stage(ParamStore& s, const uint8_t* a, uint8_t len, uint8_t& bad) {
    bad = 0xFF;
    if (!s.loading || s.w_job > kStage) return kParamNoLoad;
    const ParamConfig& c = *s.cfg;
    const uint8_t st = check_entries(c, a, len, bad);
    if (st != kParamOk) return st;
    if (static_cast<uint16_t>(s.q_len) + len > sizeof s.queue) return kParamBusy;
    memcpy(s.queue + s.q_len, a, len);
    s.q_len = static_cast<uint8_t>(s.q_len + len);
    for (uint8_t i = 0; i < len;) {
        const uint8_t id = a[i];
        uint8_t* const bits = flash_get(c.staged);
        bits[id >> 3] = static_cast<uint8_t>(bits[id >> 3] | (1u << (id & 7u)));
        i = static_cast<uint8_t>(i + 1u + elem_size(def(c, id).type));
    }
    return kParamOk;
}

uint8_t param_commit(ParamStore& s, uint16_t crc, uint8_t& bad) {
    bad = 0xFF;
    if (!s.loading || s.w_job > kStage) return kParamNoLoad;
    if (s.q_len != 0 || s.w_job != kStage || !pal::eeprom_ready()) return kParamBusy;
    const ParamConfig& c = *s.cfg;
    const uint16_t values = static_cast<uint16_t>(bank_base(c, target_bank(s)) + kParamHeader);
    // the block the load makes: staged values from the bank, the others live
    uint16_t sum = kCrcInit;
    uint8_t v[8], w[8];
    const uint8_t count = flash_get(c.n);
    for (uint8_t id = 0; id < count; ++id) {
        const ParamDef d = def(c, id);
        const uint8_t n = elem_size(d.type);
        get_bytes(c, d, v);
        if (staged(c, id)) {
            for (uint8_t k = 0; k < n; ++k) w[k] = pal::eeprom_read(static_cast<uint16_t>(values + d.off + k));
            if (memcmp(v, w, n) != 0 && !state_allows(c, d)) {
                if (bad == 0xFF) bad = id;  // the first refused, reported once the CRC holds
            }
            memcpy(v, w, n);
        }
        sum = crc16(v, n, sum);
    }
    if (sum != crc) {
        bad = 0xFF;
        return kParamMismatch;
    }
    if (bad != 0xFF) return kParamWrongState;
    for (uint8_t id = 0; id < count; ++id) {  // in one step: the loaded set is live
        if (!staged(c, id)) continue;
        const ParamDef d = def(c, id);
        for (uint8_t k = 0; k < elem_size(d.type); ++k) v[k] = pal::eeprom_read(static_cast<uint16_t>(values + d.off + k));
        set_bytes(c, d, v);
    }
    s.w_job = kValues;
    s.w_id = 0;
    s.w_b = 0;
    return kParamOk;
}

uint8_t param_value(const ParamStore& s, uint8_t id, uint8_t* out) {
    const ParamConfig& c = *s.cfg;
    if (id >= flash_get(c.n)) return 0;
    const ParamDef d = def(c, id);
    get_bytes(c, d, out);
    return elem_size(d.type);
}

uint8_t param_count(const ParamStore& s) { return flash_get(s.cfg->n); }

uint16_t param_crc(const ParamStore& s) { return live_crc(*s.cfg, kCrcInit); }

bool param_busy(const ParamStore& s) { return s.w_job != kIdle && s.cfg != 0; }

namespace {
// param_poll's writing, out of line: the configuration's copy is on the
// stack only while a byte is written, not in the frame of the loop that
// polls (generated code inlines param_poll into main()).
FSW_NOINLINE void write_next(ParamStore& s);
}  // namespace

void param_poll(ParamStore& s) {
    if (s.w_job == kIdle || s.cfg == 0 || !pal::eeprom_ready()) return;
    write_next(s);
}

namespace {
void write_next(ParamStore& s) {
    const ParamConfig& c = *s.cfg;
    const uint16_t base = bank_base(c, target_bank(s));
    switch (s.w_job) {
    case kClearThenStage:
    case kClear:
        pal::eeprom_write(base, 0x00);
        s.w_job = s.w_job == kClear ? kValues : kStage;
        s.w_id = 0;
        s.w_b = 0;
        return;
    case kStage: {
        if (s.q_len == 0) return;
        const ParamDef d = def(c, s.queue[0]);
        const uint8_t n = elem_size(d.type);
        pal::eeprom_write(static_cast<uint16_t>(base + kParamHeader + d.off + s.w_b), s.queue[1 + s.w_b]);
        if (++s.w_b == n) {
            s.w_b = 0;
            s.q_len = static_cast<uint8_t>(s.q_len - 1u - n);
            memmove(s.queue, s.queue + 1 + n, s.q_len);
        }
        return;
    }
    case kValues:
        while (s.w_id < flash_get(c.n)) {
            const ParamDef d = def(c, s.w_id);
            if (s.loading && staged(c, s.w_id)) {  // already in the bank
                ++s.w_id;
                continue;
            }
            uint8_t v[8];
            get_bytes(c, d, v);
            pal::eeprom_write(static_cast<uint16_t>(base + kParamHeader + d.off + s.w_b), v[s.w_b]);
            if (++s.w_b == elem_size(d.type)) {
                s.w_b = 0;
                ++s.w_id;
            }
            return;
        }
        s.w_crc = bank_crc(c, static_cast<uint16_t>(s.seq + 1u), 0xFFFFu);
        s.w_job = kHeader;
        s.w_id = 0;
        return;
    case kHeader:
        pal::eeprom_write(static_cast<uint16_t>(base + 1u + s.w_id), header_byte(s, c, s.w_id));
        if (++s.w_id == 8) s.w_job = kMagic;
        return;
    case kMagic:
        pal::eeprom_write(base, kParamMagic);
        s.seq = static_cast<uint16_t>(s.seq + 1u);
        s.source = static_cast<uint8_t>(target_bank(s) ? kParamBankB : kParamBankA);  // writing and dirty off
        s.loading = 0;
        s.w_job = kIdle;
        memset(flash_get(c.staged), 0, (flash_get(c.n) + 7u) / 8u);
        refresh_dirty(s, c);
        return;
    default:
        s.w_job = kIdle;
    }
}
}  // namespace

}  // namespace fsw
