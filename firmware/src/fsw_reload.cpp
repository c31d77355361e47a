// Machines replaced at run time (fsw_reload.h, docs/reload.md).
#include "fsw_reload.h"

#include "fsw_crc.h"
#include "fsw_pal.h"

namespace fsw {

namespace {

const uint8_t kNoSeg = 2;

ReloadConfig config(const ReloadStore& s) {
    ReloadConfig c;
    flash_read(&c, s.cfg, sizeof c);
    return c;
}

// Whether activation order `a` is after `b`: serial-number arithmetic, so
// that the order wraps after 65,535 activations and the newest is still
// the newest (the two slots' orders are never 32,768 apart: each
// activation takes the other's plus one).
bool later(uint16_t a, uint16_t b) { return static_cast<int16_t>(static_cast<uint16_t>(a - b)) > 0; }

uint16_t slot_addr(const ReloadConfig& c, uint8_t which) {  // which: 1 or 2
    return static_cast<uint16_t>(c.eeprom_base + (which - 1u) * (kReloadHeader + c.size));
}

// The CRC `crc` carried on over `n` EEPROM bytes from `addr`.
uint16_t eeprom_crc(uint16_t crc, uint16_t addr, uint16_t n) {
    for (uint16_t i = 0; i < n; ++i) crc = crc16_update(crc, pal::eeprom_read(static_cast<uint16_t>(addr + i)));
    return crc;
}

uint16_t payload_crc(uint16_t addr, uint16_t n) { return eeprom_crc(kCrcInit, addr, n); }

// Reads slot `which`'s header and checks its payload's CRC: false when the
// slot holds nothing whole.
bool read_slot(const ReloadConfig& c, uint8_t which, ReloadSlot& out) {
    const uint16_t a = slot_addr(c, which);
    uint8_t h[kReloadHeader];
    for (uint8_t i = 0; i < kReloadHeader; ++i) h[i] = pal::eeprom_read(static_cast<uint16_t>(a + i));
    out.status = kSlotEmpty;
    out.seq = static_cast<uint16_t>(h[2] | (h[3] << 8));
    out.len = static_cast<uint16_t>(h[4] | (h[5] << 8));
    out.nmask = h[6];
    out.crc = static_cast<uint16_t>(h[7] | (h[8] << 8));
    if (h[0] != kReloadMagic || out.len == 0 || static_cast<uint32_t>(out.len) + out.nmask > c.size ||
        payload_crc(static_cast<uint16_t>(a + kReloadHeader), static_cast<uint16_t>(out.len + out.nmask)) != out.crc) {
        memset(&out, 0, sizeof out);  // kSlotEmpty
        return false;
    }
    out.status = h[1] == kSlotBoot ? kSlotBoot : kSlotStored;
    return true;
}

// The state mask after an image the verifier passed (at `a`, `len` bytes,
// its state count at byte 18): a bit for each of the image's states, and
// at least one set. A mask the ground did not make so would leave a
// machine that no state lets go (not even back to the generated one), and
// EEPROM keeps it across a reflash.
FSW_NOINLINE uint8_t mask_check(uint16_t a, uint16_t len, uint8_t nmask) {
    uint8_t left = pal::eeprom_read(static_cast<uint16_t>(a + 18u));  // states not yet looked at
    if (nmask != static_cast<uint8_t>((left + 7u) / 8u)) return kVmBadMask;
    uint8_t any = 0;
    for (a = static_cast<uint16_t>(a + len); left != 0; ++a) {  // bits past the last state do not count
        const uint8_t n = left < 8u ? left : 8u;
        any = static_cast<uint8_t>(any | (pal::eeprom_read(a) & static_cast<uint8_t>(0xFFu >> (8u - n))));
        left = static_cast<uint8_t>(left - n);
    }
    return any != 0 ? static_cast<uint8_t>(kVmOk) : static_cast<uint8_t>(kVmBadMask);
}

// The image in slot `which` checked where it lies (CRC again, then the
// verifier and the mask), in one call: at boot.
uint8_t check_slot(const ReloadConfig& c, const ReloadSlot& sl, uint8_t which) {
    const uint16_t a = static_cast<uint16_t>(slot_addr(c, which) + kReloadHeader);
    if (payload_crc(a, static_cast<uint16_t>(sl.len + sl.nmask)) != sl.crc) return kReloadCrcFails;
    const uint8_t r = vm_verify_eeprom(a, sl.len, *c.layout, c.ram_size);
    return r != kVmOk ? r : mask_check(a, sl.len, sl.nmask);
}

// Copies slot `which` (checked) into the running image's buffer and starts
// it from its first state; with `fresh` false (a resumed flight) the
// machine's record and its RAM are left as they were kept.
FSW_NOINLINE void run_slot(ReloadStore& s, const ReloadConfig& c, uint8_t which, bool fresh = true) {
    const ReloadSlot& sl = s.slot[which - 1u];
    // (the bounds in registers: a store to the image could alias the store's
    // record, which the loop would read again each byte: 66 AVR cycles a
    // byte, about 30 so)
    const uint16_t a = static_cast<uint16_t>(slot_addr(c, which) + kReloadHeader);
    const uint16_t n = static_cast<uint16_t>(sl.len + sl.nmask);
    uint8_t* const im = c.image;
    for (uint16_t i = 0; i < n; ++i) im[i] = pal::eeprom_read(static_cast<uint16_t>(a + i));
    if (fresh) vm_reset(c.image, c.ram, *c.machine, 1);
    s.active = which;
}

// Slot `which` made the one to boot: activated after the other slot (as
// ACTIVATE does), both written back in the background.
void mark_boot(ReloadStore& s, uint8_t which) {
    ReloadSlot& sl = s.slot[which - 1u];
    const ReloadSlot& o = s.slot[2u - which];  // the order after the other slot's (this one's own may be stale)
    sl.seq = static_cast<uint16_t>((o.status != kSlotEmpty ? o.seq : sl.seq) + 1u);
    sl.status = kSlotBoot;
    s.sync = true;
}

// The slot a boot runs first: the newest activated one (0: none).
uint8_t newest_boot(const ReloadStore& s) {
    uint8_t best = 0;
    for (uint8_t w = 1; w <= 2; ++w) {
        const ReloadSlot& sl = s.slot[w - 1u];
        if (sl.status == kSlotBoot && (best == 0 || later(sl.seq, s.slot[best - 1u].seq))) best = w;
    }
    return best;
}

// No slot boots: the generated machine runs (ACTIVATE 0), written back in the background.
void mark_built_in(ReloadStore& s) {
    for (uint8_t i = 0; i < 2; ++i) {
        if (s.slot[i].status == kSlotBoot) {
            s.slot[i].status = kSlotStored;
            s.sync = true;
        }
    }
}

// Whether the running machine's current state allows another to take over.
bool allowed(const ReloadStore& s, const ReloadConfig& c) {
    const uint32_t st = c.machine->state;
    if (c.machine->started == 0 || st == 0) return true;  // nothing has run yet
    const uint32_t byte = (st - 1u) / 8u;
    const uint8_t bit = static_cast<uint8_t>(1u << ((st - 1u) % 8u));
    if (s.active == kReloadBuiltIn) {
        return byte < c.n_allow && (flash_u8(c.allow + byte) & bit) != 0;
    }
    const ReloadSlot& sl = s.slot[s.active - 1u];
    return byte < sl.nmask && (c.image[sl.len + byte] & bit) != 0;
}

void leave(const ReloadStore& s, const ReloadConfig& c) {
    if (s.active == kReloadBuiltIn) c.leave();
    else vm_leave(c.image, *c.layout, c.sv, c.ram, *c.machine);
}

void activate_now(ReloadStore& s, const ReloadConfig& c, uint8_t which) {
    if (which == s.active) return;
    if (which == kReloadBuiltIn) {
        leave(s, c);
        s.active = kReloadBuiltIn;
        c.reset(1);
        mark_built_in(s);  // boot the generated machine
        s.sync = true;
        return;
    }
    leave(s, c);  // the slot is checked (check_slice): its CRC and the verifier passed
    run_slot(s, c, which);
    mark_boot(s, which);
}

// Queues a run of bytes for the writer (`seg` 0 or 1; run 0 starts first).
void queue_run(ReloadStore& s, uint8_t seg, uint16_t addr, uint8_t n) {
    s.w_addr[seg] = addr;
    s.w_n[seg] = n;
}

void start_writer(ReloadStore& s) {
    s.w_seg = 0;
    s.w_i = 0;
}

// Whether the check that runs is the open upload's (a COMMIT's).
bool checking_upload(const ReloadStore& s) { return s.ck_slot != 0 && s.ck_slot == s.up_slot; }

// Starts the check of slot `which`: the open upload's bytes, or a committed
// image an activation waits for.
void check_start(ReloadStore& s, uint8_t which) {
    s.ck_slot = which;
    s.ck_at = 0;
    s.ck_crc = kCrcInit;
    vm_check_begin(s.vm);
}

// A slice of the check that runs: FSW_RELOAD_SLICE bytes of the CRC, or as
// many EEPROM reads of the verifier (and the unit of work it is in); when
// the check is over, its verdict goes to the COMMIT that asks next, or to
// the pending activation. (Out of line, as run_slot: tools/bench_reload.py
// times each call.)
FSW_NOINLINE void check_slice(ReloadStore& s, const ReloadConfig& c) {
    const uint8_t w = s.ck_slot;
    const bool upload = w == s.up_slot;
    ReloadSlot& sl = s.slot[w - 1u];
    const uint16_t len = upload ? s.up_len : sl.len;
    const uint16_t total = static_cast<uint16_t>(len + (upload ? s.up_nmask : sl.nmask));
    const uint16_t a = static_cast<uint16_t>(slot_addr(c, w) + kReloadHeader);
    uint8_t r;
    if (s.ck_at < total) {
        const uint16_t end =
            total - s.ck_at > FSW_RELOAD_SLICE ? static_cast<uint16_t>(s.ck_at + FSW_RELOAD_SLICE) : total;
        const uint16_t crc =
            eeprom_crc(s.ck_crc, static_cast<uint16_t>(a + s.ck_at), static_cast<uint16_t>(end - s.ck_at));
        s.ck_crc = crc;
        s.ck_at = end;
        if (end < total || crc == (upload ? s.up_crc : sl.crc)) return;  // (the verifier from the next slice)
        r = kReloadCrcFails;
    } else {
        r = vm_check_eeprom(s.vm, a, len, *c.layout, c.ram_size, FSW_RELOAD_SLICE);
        if (r == kVmMore) return;
        if (r == kVmOk) r = mask_check(a, len, upload ? s.up_nmask : sl.nmask);
    }
    s.ck_slot = 0;
    if (upload) {
        s.ck_result = r == kVmOk ? kReloadOk : r == kReloadCrcFails ? kReloadMismatch : kReloadBadImage;
        s.ck_reason = r == kReloadCrcFails ? static_cast<uint8_t>(kVmOk) : r;
    } else if (r == kVmOk) {
        s.ready = w;
    } else {  // refused: the running machine goes on untouched
        s.pending = kReloadNone;
        s.refused = w;
        s.reason = r;
        if (r == kReloadCrcFails) sl.status = kSlotEmpty;  // the bytes changed in the EEPROM
    }
}

}  // namespace

void reload_begin(ReloadStore& s, const ReloadConfig* cfg, uint8_t resumed) {
    memset(&s, 0, sizeof s);
    s.cfg = cfg;
    s.pending = kReloadNone;
    s.w_seg = kNoSeg;
    s.ck_result = kReloadNone;
    const ReloadConfig c = config(s);
    for (uint8_t w = 1; w <= 2; ++w) read_slot(c, w, s.slot[w - 1u]);
    if (resumed == kReloadBuiltIn) {  // a resumed flight: the generated machine goes on, as kept
        mark_built_in(s);  // (a reset may have cut the write of an ACTIVATE 0 short)
        return;
    }
    if ((resumed == 1u || resumed == 2u) && check_slot(c, s.slot[resumed - 1u], resumed) == kVmOk) {
        run_slot(s, c, resumed, false);  // the uploaded machine goes on, its state and RAM as kept
        if (newest_boot(s) != resumed) mark_boot(s, resumed);  // (... or of its ACTIVATE)
        return;
    }
    for (uint8_t tries = 0; tries < 2; ++tries) {  // the newest activated image first
        const uint8_t best = newest_boot(s);
        if (best == 0) return;  // the generated machine
        const uint8_t r = check_slot(c, s.slot[best - 1u], best);
        if (r == kVmOk) {
            run_slot(s, c, best);
            return;
        }
        s.refused = best;
        s.reason = r;
        s.slot[best - 1u].status = kSlotStored;  // not booted again (until activated)
        s.sync = true;
    }
}

Result reload_step(ReloadStore& s) {
    const ReloadConfig c = config(s);
    // (with the writer idle and the EEPROM ready: the check and the copy read
    // the EEPROM, and a read waits for a byte being written)
    if (s.w_seg == kNoSeg && pal::eeprom_ready()) {
        if (s.ck_slot == 0 && s.pending != kReloadNone && s.pending != kReloadBuiltIn && s.ready != s.pending)
            check_start(s, s.pending);
        if (s.ck_slot != 0) {
            check_slice(s, c);  // a slice a step: the switch at a later one
            s.sliced = true;
        } else if (s.pending != kReloadNone && (s.pending == kReloadBuiltIn || s.ready == s.pending) &&
                   allowed(s, c)) {
            const uint8_t which = s.pending;
            s.pending = kReloadNone;
            s.ready = 0;
            activate_now(s, c, which);
        }
    }
    if (s.active == kReloadBuiltIn) return c.step();
    return vm_step(c.image, *c.layout, c.sv, c.ram, *c.machine);
}

bool reload_writing(const ReloadStore& s) { return s.w_seg != kNoSeg || s.sync; }

uint8_t reload_upload_begin(ReloadStore& s, uint16_t len, uint8_t nmask, uint16_t crc) {
    const ReloadConfig c = config(s);
    if (static_cast<uint32_t>(len) + nmask > c.size) return kReloadTooBig;
    if (len == 0) return kReloadBadLength;
    if (reload_writing(s) || checking_upload(s)) return kReloadBusy;
    // never the slot that runs: an empty one, else the older
    uint8_t to;
    if (s.active != kReloadBuiltIn) {
        to = static_cast<uint8_t>(3u - s.active);
    } else if (s.slot[0].status == kSlotEmpty || s.slot[1].status == kSlotEmpty) {
        to = s.slot[0].status == kSlotEmpty ? 1u : 2u;
    } else {
        to = s.slot[0].seq <= s.slot[1].seq ? 1u : 2u;
    }
    if (s.pending == to) return kReloadWrongState;
    memset(&s.slot[to - 1u], 0, sizeof s.slot[0]);  // kSlotEmpty from the first byte written
    s.ck_result = kReloadNone;  // the last upload's, not asked for
    s.up_slot = to;
    s.up_len = len;
    s.up_nmask = nmask;
    s.up_crc = crc;
    s.up_next = 0;
    s.queue[0] = 0;  // the header's magic goes first: a cut from here on leaves the slot empty
    queue_run(s, 0, slot_addr(c, to), 1);
    queue_run(s, 1, 0, 0);
    start_writer(s);
    return kReloadOk;
}

uint8_t reload_write(ReloadStore& s, uint16_t off, const uint8_t* data, uint8_t n) {
    if (s.up_slot == 0) return kReloadNoLoad;
    if (n == 0 || n > FSW_RELOAD_QUEUE) return kReloadBadLength;
    if (static_cast<uint32_t>(off) + n > static_cast<uint32_t>(s.up_len) + s.up_nmask) return kReloadOutOfRange;
    if (reload_writing(s) || checking_upload(s)) return kReloadBusy;
    const ReloadConfig c = config(s);
    s.ck_result = kReloadNone;  // a check of the bytes before: void
    memcpy(s.queue, data, n);
    queue_run(s, 0, static_cast<uint16_t>(slot_addr(c, s.up_slot) + kReloadHeader + off), n);
    queue_run(s, 1, 0, 0);
    start_writer(s);
    if (off <= s.up_next && off + n > s.up_next) s.up_next = static_cast<uint16_t>(off + n);
    return kReloadOk;
}

uint8_t reload_commit(ReloadStore& s, uint8_t& reason) {
    reason = kVmOk;
    if (s.up_slot == 0) return kReloadNoLoad;
    if (reload_writing(s)) return kReloadBusy;
    const uint16_t total = static_cast<uint16_t>(s.up_len + s.up_nmask);
    if (s.up_next < total) return kReloadNoLoad;
    const ReloadConfig c = config(s);
    if (s.ck_result == kReloadNone) {  // the check: started, running, or after an activation's
        if (s.ck_slot == 0) {
            check_start(s, s.up_slot);
        } else if (!s.sliced && pal::eeprom_ready()) {  // no machine step carried it on since the last COMMIT
            check_slice(s, c);
        }
        s.sliced = false;
        return kReloadBusy;
    }
    const uint8_t st = s.ck_result;
    s.ck_result = kReloadNone;
    if (st == kReloadMismatch) return kReloadMismatch;  // the upload stays open: WRITEs may mend it
    const uint8_t to = s.up_slot;
    const uint16_t a = slot_addr(c, to);
    s.up_slot = 0;  // whatever follows, the upload is over
    if (st != kReloadOk) {
        reason = s.ck_reason;
        s.refused = to;
        s.reason = reason;
        return kReloadBadImage;
    }
    ReloadSlot& sl = s.slot[to - 1u];
    sl.status = kSlotStored;
    sl.seq = 0;
    sl.len = s.up_len;
    sl.nmask = s.up_nmask;
    sl.crc = s.up_crc;
    // the header's body, then its magic
    const uint8_t h[kReloadHeader - 1] = {kSlotStored, 0, 0, static_cast<uint8_t>(sl.len), static_cast<uint8_t>(sl.len >> 8),
                                          sl.nmask, static_cast<uint8_t>(sl.crc), static_cast<uint8_t>(sl.crc >> 8)};
    memcpy(s.queue, h, sizeof h);
    s.queue[sizeof h] = kReloadMagic;
    queue_run(s, 0, static_cast<uint16_t>(a + 1u), sizeof h);
    queue_run(s, 1, a, 1);
    start_writer(s);
    return kReloadOk;
}

uint8_t reload_activate(ReloadStore& s, uint8_t which) {
    if (which > 2) return kReloadOutOfRange;
    if (which != kReloadBuiltIn && s.slot[which - 1u].status == kSlotEmpty) return kReloadNoImage;
    if (which != kReloadBuiltIn && s.up_slot == which) return kReloadNoImage;
    const uint8_t p = which == s.active ? kReloadNone : which;
    if (p != s.pending) {
        if (s.ck_slot != 0 && !checking_upload(s)) s.ck_slot = 0;  // the check for the one asked before: void
        s.ready = 0;
        s.pending = p;
    }
    return kReloadOk;
}

void reload_poll(ReloadStore& s) {
    if (!pal::eeprom_ready()) return;
    if (s.w_seg == kNoSeg) {
        if (!s.sync) return;
        // the status and seq bytes of each whole slot, as the store has them
        // (status first: a cut before the seq leaves the slots in their old
        // order, so the machine that ran before keeps its place at boot; and
        // the slot activated longer ago first, so that a cut between the two
        // never leaves it the only one marked to boot)
        s.sync = false;
        const ReloadConfig c = config(s);
        const uint8_t first = later(s.slot[0].seq, s.slot[1].seq) ? 2u : 1u;  // the older first
        uint8_t r = 0;
        for (uint8_t k = 0; k < 2; ++k) {
            const uint8_t w = k == 0 ? first : static_cast<uint8_t>(3u - first);
            const ReloadSlot& sl = s.slot[w - 1u];
            if (sl.status == kSlotEmpty) continue;
            s.queue[3u * r] = sl.status;
            s.queue[3u * r + 1u] = static_cast<uint8_t>(sl.seq);
            s.queue[3u * r + 2u] = static_cast<uint8_t>(sl.seq >> 8);
            queue_run(s, r, static_cast<uint16_t>(slot_addr(c, w) + 1u), 3);
            ++r;
        }
        if (r == 0) return;
        if (r < 2) queue_run(s, 1, 0, 0);
        start_writer(s);
    }
    // the next byte that differs from the EEPROM's
    while (s.w_seg < kNoSeg) {
        const uint8_t seg = s.w_seg;
        if (s.w_i >= s.w_n[seg]) {
            s.w_seg = static_cast<uint8_t>(seg + 1u);
            s.w_i = 0;
            if (s.w_seg < kNoSeg && s.w_n[s.w_seg] == 0) s.w_seg = kNoSeg;
            continue;
        }
        const uint8_t qi = static_cast<uint8_t>((seg == 0 ? 0u : s.w_n[0]) + s.w_i);
        const uint16_t addr = static_cast<uint16_t>(s.w_addr[seg] + s.w_i);
        ++s.w_i;
        if (pal::eeprom_read(addr) != s.queue[qi]) {
            pal::eeprom_write(addr, s.queue[qi]);
            return;  // one byte a call: the next when the EEPROM is ready
        }
    }
}

}  // namespace fsw
