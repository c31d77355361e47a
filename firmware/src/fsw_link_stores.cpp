// The link's commands on the stores an application may have (docs/telemetry.md):
// the parameter store's, the flight recorder's and the reload store's, and
// what their acknowledgements carry. In an object of their own: generated
// code names them in its LinkConfig only for the stores it has, so a
// firmware without them links none of the stores' code (fsw_param, fsw_log,
// fsw_reload, the VM's verifier) nor the EEPROM's interrupt handler, which
// no link-time optimisation drops once its object is in.
#include "fsw_link.h"

#include "fsw_element.h"

namespace fsw {

namespace {

inline void put(uint8_t b) { link_put(b); }
inline void put_bytes(const void* p, uint16_t n) { link_put_bytes(p, n); }
void put_u16(uint16_t v) { put_bytes(&v, 2); }  // little-endian targets (fsw_config.h)
void put_u32(uint32_t v) { put_bytes(&v, 4); }

}  // namespace

// What a parameter command's ack carries after its 6 bytes: GET's values
// (first id, count, values: as many as the transmit buffer holds), INFO's
// store state, the id a refusal stopped at.
void link_param_ack(Link& l, const ParamStore& ps) {
    const uint16_t tx_cap = flash_get(l.cfg->tx_cap);
    const uint8_t op = l.ack_op;
    if (l.ack_status == kAckOk && op == kOpParamGet) {
        // room for values: the frame (header, ack, first, count, CRC) and its
        // COBS overhead within the transmit buffer
        uint16_t room = static_cast<uint16_t>(tx_cap - 24u - tx_cap / 254u);
        uint8_t n = 0;
        uint8_t v[8];
        for (; n < l.ack_y; ++n) {  // how many whole values fit
            const uint8_t size = param_value(ps, static_cast<uint8_t>(l.ack_x + n), v);
            if (size == 0 || size > room) break;
            room = static_cast<uint16_t>(room - size);
        }
        put(l.ack_x);
        put(n);
        for (uint8_t i = 0; i < n; ++i) put_bytes(v, param_value(ps, static_cast<uint8_t>(l.ack_x + i), v));
    } else if (l.ack_status == kAckOk && op == kOpParamInfo) {
        put(ps.source);
        put_u16(ps.seq);
        put_u16(param_crc(ps));
        put(param_count(ps));
        put_u32(flash_get(ps.cfg->hash));
    } else if (l.ack_status != kAckOk && l.ack_x != 0xFF &&
               (op == kOpParamSet || op == kOpParamStage || op == kOpParamCommit)) {
        put(l.ack_x);
    }
}

// A parameter command (kOpParamGet..kOpParamInfo) on the store.
uint8_t link_param_apply(Link& l, ParamStore& ps, uint8_t op, const uint8_t* a, uint8_t alen) {
    uint8_t bad = 0xFF;
    uint8_t st;
    if (op == kOpParamSet || op == kOpParamStage) {
        st = op == kOpParamSet ? param_set(ps, a, alen, bad) : param_stage(ps, a, alen, bad);
    } else if (op == kOpParamGet) {
        if (alen != 2) return kAckBadLength;
        l.ack_x = a[0];
        l.ack_y = a[1];
        return a[0] < param_count(ps) ? static_cast<uint8_t>(kAckOk) : static_cast<uint8_t>(kParamNoParam);
    } else if (op == kOpParamCommit) {
        if (alen != 2) return kAckBadLength;
        st = param_commit(ps, load<uint16_t>(a), bad);
    } else {
        if (alen != 0) return kAckBadLength;
        st = op == kOpParamSave    ? param_save(ps)
             : op == kOpParamBegin ? param_load_begin(ps)
                                   : static_cast<uint8_t>(kAckOk);
    }
    l.ack_x = bad;
    return st;
}

// What a recorder command's ack carries after its 6 bytes: INFO's state,
// READ's record, offset, count and bytes (as many as the transmit buffer holds).
void link_log_ack(Link& l, const Recorder& r) {
    if (l.ack_status != kAckOk) return;
    const LogConfig& lc = *r.cfg;  // FSW_FLASH: the fields, one at a time
    if (l.ack_op == kOpLogInfo) {
        put(r.mode);
        put(r.flight);
        put_u16(r.head);
        put_u16(r.seq);
        put_u16(flash_get(lc.slots));
        put(flash_get(lc.record));
        put_u16(r.dropped);
        put_u32(flash_get(lc.hash));
    } else if (l.ack_op == kOpLogRead) {
        const uint16_t tx_cap = flash_get(l.cfg->tx_cap);
        const uint16_t room = static_cast<uint16_t>(tx_cap - 24u - tx_cap / 254u);
        const uint8_t off = l.ack_x;
        const uint8_t n = l.ack_y < room ? l.ack_y : static_cast<uint8_t>(room);
        put_u16(r.rd_slot);
        put(off);
        put(n);
        uint8_t b[16];
        for (uint8_t done = 0; done < n;) {
            const uint8_t k = static_cast<uint8_t>(n - done > static_cast<int>(sizeof b) ? sizeof b : n - done);
            log_read(r, r.rd_slot, static_cast<uint8_t>(off + done), k, b);
            put_bytes(b, k);
            done = static_cast<uint8_t>(done + k);
        }
    }
}

// A recorder command (kOpLogInfo..kOpLogErase).
uint8_t link_log_apply(Link& l, Recorder& r, uint8_t op, const uint8_t* a, uint8_t alen) {
    if (op == kOpLogRead) {
        if (alen != 4) return kAckBadLength;
        const uint16_t slot = load<uint16_t>(a);
        if (slot >= flash_get(r.cfg->slots) || static_cast<uint16_t>(a[2]) + a[3] > flash_get(r.cfg->record)) {
            return kAckOutOfRange;
        }
        r.rd_slot = slot;
        l.ack_x = a[2];
        l.ack_y = a[3];
        return kAckOk;
    }
    if (alen != 0) return kAckBadLength;
    if (op == kOpLogErase) return log_erase(r) ? static_cast<uint8_t>(kAckOk) : static_cast<uint8_t>(kAckWrongState);
    return kAckOk;
}

// What a reload command's ack carries after its 6 bytes: INFO's state of
// the store (docs/reload.md), COMMIT's verifier reason when it refused.
void link_reload_ack(Link& l, const ReloadStore& s) {
    if (l.ack_op == kOpMachineCommit && l.ack_status == kAckBadImage) {
        put(l.ack_x);
        return;
    }
    if (l.ack_op != kOpMachineInfo || l.ack_status != kAckOk) return;
    ReloadConfig rc;
    flash_read(&rc, s.cfg, sizeof rc);
    put(s.active);
    put(s.pending);
    put(s.refused);
    put(s.reason);
    put(reload_writing(s) ? 1u : 0u);
    put_u16(rc.size);
    put_u16(rc.ram_size);
    put(s.up_slot);
    put_u16(s.up_len);
    put(s.up_nmask);
    put_u16(s.up_crc);
    put_u16(s.up_next);
    for (uint8_t i = 0; i < 2; ++i) {
        const ReloadSlot& sl = s.slot[i];
        put(sl.status);
        put_u16(sl.seq);
        put_u16(sl.len);
        put(sl.nmask);
        put_u16(sl.crc);
    }
}

// A reload command (kOpMachineInfo..kOpMachineActivate) on the store.
uint8_t link_reload_apply(Link& l, ReloadStore& s, uint8_t op, const uint8_t* a, uint8_t alen) {
    switch (op) {
        case kOpMachineBegin:
            if (alen != 5) return kAckBadLength;
            return reload_upload_begin(s, load<uint16_t>(a), a[2], load<uint16_t>(a + 3));
        case kOpMachineWrite:
            if (alen < 3) return kAckBadLength;
            return reload_write(s, load<uint16_t>(a), a + 2, static_cast<uint8_t>(alen - 2u));
        case kOpMachineCommit: {
            if (alen != 0) return kAckBadLength;
            uint8_t reason;
            const uint8_t st = reload_commit(s, reason);
            l.ack_x = reason;
            return st;
        }
        case kOpMachineActivate:
            if (alen != 1) return kAckBadLength;
            return reload_activate(s, a[0]);
        default:
            return alen == 0 ? static_cast<uint8_t>(kAckOk) : static_cast<uint8_t>(kAckBadLength);
    }
}

}  // namespace fsw
