// The serial link: telemetry (samples, hello, health, acks, snapshots) and
// the uplink command parser. Frames are composed straight into one transmit
// buffer by the COBS encoder; nothing here waits for the UART.
#include "fsw_link.h"

#include "fsw_cobs.h"
#include "fsw_crc.h"
#include "fsw_element.h"
#include "fsw_pal.h"
#include "fsw_sv.h"
#include "fsw_version.h"

namespace fsw {

static_assert(offsetof(LinkCounters, dropped) == offsetof(LinkCounters, frames) + 4, "health frame layout");
static_assert(offsetof(LinkCounters, last_seq) == offsetof(LinkCounters, rx_ok) + 12, "health frame layout");

namespace {

enum Pending : uint8_t { kPendAck = 1, kPendHello = 2, kPendHealth = 4 };
const uint16_t kNoSnapshot = 0xFFFFu;

inline void inc16(uint16_t& c) {
    if (c != 0xFFFFu) ++c;
}

inline void read_config(const Link& l, LinkConfig& c) { flash_read(&c, l.cfg, sizeof c); }

// Hands as much of the transmit buffer to the console as it takes now.
void pump(Link& l) {
    if (l.tx_len == 0) return;
    uint16_t n = static_cast<uint16_t>(l.tx_len - l.tx_pos);
    const uint16_t space = pal::console_write_space();
    if (n > space) n = space;
    if (n != 0) {
        pal::console_write(l.tx + l.tx_pos, n);
        l.tx_pos = static_cast<uint16_t>(l.tx_pos + n);
    }
    if (l.tx_pos >= l.tx_len) l.tx_len = l.tx_pos = 0;
}

inline bool tx_free(Link& l) {
    pump(l);
    return l.tx_len == 0;
}

void frame_begin(Link& l, CobsEncoder& e, uint8_t type, uint32_t time32) {
    cobs_begin(e, l.tx);
    cobs_put(e, type);
    cobs_put(e, static_cast<uint8_t>(l.n.frames));
    cobs_put_u32(e, time32);
}

void frame_end(Link& l, CobsEncoder& e) {
    l.tx_len = cobs_end(e);
    l.tx_pos = 0;
    ++l.n.frames;
    pump(l);
}

// State vector bytes into the frame, atomically when the lock is on.
void put_sv(CobsEncoder& e, const LinkConfig& c, uint16_t off, uint16_t n) {
    if (c.lock) {
        SvGuard<true> g;
        cobs_put_bytes(e, c.sv + off, n);
    } else {
        cobs_put_bytes(e, c.sv + off, n);
    }
}

void copy_sv(const LinkConfig& c, uint16_t off, uint16_t n, uint8_t* dst) {
    const StateVector sv = {c.sv, c.sv_size, c.lock};
    const Result r = sv_copy_out(sv, off, n, dst);  // link_begin checked every span
    (void)r;
}

// Sends the open batch of stream i (and the current region when `with_now`).
void send_batch(Link& l, const LinkConfig& c, const LinkStream& s, LinkStreamState& st, uint8_t i,
                bool with_now) {
    const uint8_t stored = st.count;
    st.count = 0;
    if (!tx_free(l)) {
        ++l.n.dropped;
        return;
    }
    CobsEncoder e;
    frame_begin(l, e, static_cast<uint8_t>(kFrameSample | i), st.t0);
    cobs_put_bytes(e, s.store, static_cast<uint16_t>(stored * s.size));
    if (with_now) put_sv(e, c, s.off, s.size);
    frame_end(l, e);
}

void take_sample(Link& l, const LinkConfig& c, uint8_t i, uint32_t now32) {
    LinkStream s;
    flash_read(&s, &c.streams[i], sizeof s);
    LinkStreamState& st = c.stream_state[i];
    const uint16_t late = c.ex != 0 ? c.ex->late : 0;
    // Samples of a frame are evenly spaced: a batch the executor broke by
    // skipping cycles goes out as it is.
    if (st.count != 0 && late != st.late0) send_batch(l, c, s, st, i, false);
    if (st.count == 0) {
        st.t0 = now32;
        st.late0 = late;
    }
    if (static_cast<uint8_t>(st.count + 1u) < s.batch) {
        copy_sv(c, s.off, s.size, s.store + st.count * s.size);
        ++st.count;
        return;
    }
    send_batch(l, c, s, st, i, true);
}

void send_ack(Link& l, const LinkConfig& c) {
    CobsEncoder e;
    frame_begin(l, e, kFrameAck, static_cast<uint32_t>(c.now()));
    cobs_put_u16(e, l.ack_seq);
    cobs_put(e, l.ack_op);
    cobs_put(e, l.ack_status);
    cobs_put_u16(e, l.n.last_seq);
    frame_end(l, e);
}

uint8_t reset_cause_of(const LinkConfig& c) { return c.ex != 0 ? c.ex->reset_cause : pal::reset_cause(); }

void send_hello(Link& l, const LinkConfig& c) {
    const uint64_t t = c.now();
    CobsEncoder e;
    frame_begin(l, e, kFrameHello, static_cast<uint32_t>(t));
    cobs_put(e, kLinkProtocol);
    cobs_put_u32(e, c.schema);
    cobs_put_u32(e, static_cast<uint32_t>(t >> 32));
    cobs_put_u32(e, l.n.frames);
    cobs_put(e, FSW_RUNTIME_VERSION_MAJOR);
    cobs_put(e, FSW_RUNTIME_VERSION_MINOR);
    cobs_put(e, FSW_RUNTIME_VERSION_PATCH);
    cobs_put(e, reset_cause_of(c));
    cobs_put_u16(e, l.n.last_seq);
    frame_end(l, e);
}

void send_health(Link& l, const LinkConfig& c) {
    const uint64_t t = c.now();
    CobsEncoder e;
    frame_begin(l, e, kFrameHealth, static_cast<uint32_t>(t));
    cobs_put_u32(e, static_cast<uint32_t>(t >> 32));
    // frames, dropped (u32) as they lie in LinkCounters (little-endian targets)
    cobs_put_bytes(e, reinterpret_cast<const uint8_t*>(&l.n.frames), 8);
    cobs_put_u32(e, c.ex != 0 ? c.ex->cycles : 0);
    cobs_put_u16(e, c.ex != 0 ? c.ex->late : 0);
    cobs_put(e, reset_cause_of(c));
    // rx_ok .. last_seq: seven u16, in order
    cobs_put_bytes(e, reinterpret_cast<const uint8_t*>(&l.n.rx_ok), 14);
    const uint8_t n_tasks = c.ex != 0 ? c.ex->cfg.n_tasks : 0;
    for (uint8_t i = 0; i < n_tasks; ++i) {
        const TaskStats& s = c.ex->cfg.stats[i];
        cobs_put(e, executor_task_mode(*c.ex, i));
        cobs_put(e, static_cast<uint8_t>(s.faults > 0xFFu ? 0xFFu : s.faults));
        cobs_put_u16(e, s.overruns);
        cobs_put_u16(e, static_cast<uint16_t>(s.worst_us > 0xFFFFu ? 0xFFFFu : s.worst_us));
    }
    frame_end(l, e);
}

void send_snapshot(Link& l, const LinkConfig& c) {
    const uint16_t off = l.snapshot_at;
    uint16_t n = static_cast<uint16_t>(c.sv_size - off);
    if (n > c.snapshot_chunk) n = c.snapshot_chunk;
    CobsEncoder e;
    frame_begin(l, e, kFrameSnapshot, static_cast<uint32_t>(c.now()));
    cobs_put_u16(e, off);
    put_sv(e, c, off, n);
    frame_end(l, e);
    l.snapshot_at = static_cast<uint16_t>(off + n) >= c.sv_size ? kNoSnapshot : static_cast<uint16_t>(off + n);
}

// Sends waiting control frames while the transmit buffer is free:
// acknowledgements first, then hello, health, snapshot chunks.
void service(Link& l, const LinkConfig& c) {
    while (tx_free(l)) {
        if (l.pending & kPendAck) {
            l.pending = static_cast<uint8_t>(l.pending & ~kPendAck);
            send_ack(l, c);
        } else if (l.pending & kPendHello) {
            l.pending = static_cast<uint8_t>(l.pending & ~kPendHello);
            send_hello(l, c);
        } else if (l.pending & kPendHealth) {
            l.pending = static_cast<uint8_t>(l.pending & ~kPendHealth);
            send_health(l, c);
        } else if (l.snapshot_at != kNoSnapshot) {
            send_snapshot(l, c);
        } else {
            return;
        }
    }
}

// ---- uplink ----------------------------------------------------------------

uint8_t apply_set(const LinkConfig& c, const uint8_t* a, uint8_t alen) {
    if (alen < 2) return kAckBadLength;
    const uint16_t index = static_cast<uint16_t>(a[0] | (a[1] << 8));
    for (uint8_t k = 0; k < c.n_writable; ++k) {
        LinkWritable w;
        flash_read(&w, &c.writable[k], sizeof w);
        if (w.index != index) continue;
        const uint8_t size = elem_size(w.type);
        if (size == 0 || alen != static_cast<uint8_t>(2u + size)) return kAckBadLength;
        uint8_t v[8];
        memcpy(v, a + 2, size);
        if (w.type == kBool) v[0] = v[0] != 0 ? 1 : 0;
        const StateVector sv = {c.sv, c.sv_size, c.lock};
        return sv_copy_in(sv, w.off, size, v) == kOk ? kAckOk : kAckNotWritable;
    }
    return kAckNotWritable;
}

uint8_t apply(Link& l, const LinkConfig& c, uint8_t op, const uint8_t* a, uint8_t alen) {
    switch (op) {
        case kOpPing:
            return alen == 0 ? kAckOk : kAckBadLength;
        case kOpHello:
            if (alen != 0) return kAckBadLength;
            l.pending |= kPendHello;
            return kAckOk;
        case kOpSnapshot:
            if (alen != 0) return kAckBadLength;
            l.snapshot_at = 0;
            return kAckOk;
        case kOpSet:
            return apply_set(c, a, alen);
        case kOpMode: {
            if (alen != 2) return kAckBadLength;
            if (c.ex == 0 || a[0] >= c.ex->cfg.n_tasks) return kAckBadTask;
            if (a[1] > kModeEnabled) return kAckBadMode;
            if (a[0] == c.uplink_task && a[1] != kModeEnabled) return kAckLocked;
            executor_set_task_mode(*c.ex, a[0], a[1]);
            return kAckOk;
        }
        default:
            return kAckUnknownOp;
    }
}

// One received frame (COBS-encoded, delimiter stripped): decode, verify,
// apply, queue the acknowledgement. Anything not verified is only counted.
void handle_frame(Link& l, const LinkConfig& c) {
    const int16_t n = cobs_decode(l.rx, l.rx_len);
    if (n < 5) {  // op, seq (2), CRC (2)
        inc16(l.n.rx_malformed);
        return;
    }
    if (crc16(l.rx, static_cast<uint16_t>(n)) != 0) {
        inc16(l.n.rx_crc);
        return;
    }
    const uint8_t op = l.rx[0];
    const uint16_t seq = static_cast<uint16_t>(l.rx[1] | (l.rx[2] << 8));
    const uint16_t ahead = static_cast<uint16_t>(seq - l.n.last_seq);
    uint8_t status;
    if (ahead == 0 || ahead >= 0x8000u) {
        inc16(l.n.rx_replayed);
        status = kAckReplay;
    } else {
        l.n.last_seq = seq;
        status = apply(l, c, op, l.rx + 3, static_cast<uint8_t>(n - 5));
        inc16(status == kAckOk ? l.n.rx_ok
              : status == kAckUnknownOp || status == kAckBadLength ? l.n.rx_malformed
                                                                    : l.n.rx_refused);
    }
    l.ack_seq = seq;
    l.ack_op = op;
    l.ack_status = status;
    l.pending |= kPendAck;
}

}  // namespace

Result link_begin(Link& l, const LinkConfig* cfg) {
    memset(&l, 0, sizeof l);
    l.cfg = cfg;
    LinkConfig c;
    read_config(l, c);
    if (c.sv == 0 || c.tx == 0 || c.now == 0 || c.tx_cap < cobs_max_encoded(kLinkHeader + 2u + 19u) ||
        (c.n_streams != 0 && (c.streams == 0 || c.stream_state == 0)) ||
        (c.n_writable != 0 && c.writable == 0) || c.snapshot_chunk == 0 || c.n_streams > 128) {
        return kErrConfig;
    }
    for (uint8_t i = 0; i < c.n_streams; ++i) {
        LinkStream s;
        flash_read(&s, &c.streams[i], sizeof s);
        if (s.every == 0 || s.batch == 0 || (s.batch > 1 && s.store == 0) ||
            static_cast<uint32_t>(s.off) + s.size > c.sv_size ||
            cobs_max_encoded(static_cast<uint16_t>(kLinkHeader + 2u + s.batch * s.size)) > c.tx_cap) {
            return kErrConfig;
        }
        LinkStreamState& st = c.stream_state[i];
        memset(&st, 0, sizeof st);
        st.countdown = static_cast<uint16_t>(i % s.every);  // spread streams over runs
    }
    for (uint8_t k = 0; k < c.n_writable; ++k) {
        LinkWritable w;
        flash_read(&w, &c.writable[k], sizeof w);
        if (elem_size(w.type) == 0 || static_cast<uint32_t>(w.off) + elem_size(w.type) > c.sv_size) {
            return kErrConfig;
        }
    }
    l.tx = c.tx;
    l.snapshot_at = kNoSnapshot;
    l.health_countdown = c.health_every;
    l.hello_countdown = c.hello_every;
    l.pending = kPendHello;
    pal::console_begin(c.baud);
    return kOk;
}

Result link_telemetry_task(void* p) {
    Link& l = *static_cast<Link*>(p);
    LinkConfig c;
    read_config(l, c);
    pump(l);
    const uint32_t now32 = static_cast<uint32_t>(c.now());
    for (uint8_t i = 0; i < c.n_streams; ++i) {
        LinkStreamState& st = c.stream_state[i];
        if (st.countdown != 0) {
            --st.countdown;
            continue;
        }
        LinkStream s;
        flash_read(&s, &c.streams[i], sizeof s);
        st.countdown = static_cast<uint16_t>(s.every - 1u);
        take_sample(l, c, i, now32);
    }
    if (c.health_every != 0 && --l.health_countdown == 0) {
        l.health_countdown = c.health_every;
        l.pending |= kPendHealth;
        if (c.hello_every != 0 && --l.hello_countdown == 0) {
            l.hello_countdown = c.hello_every;
            l.pending |= kPendHello;
        }
    }
    service(l, c);
    return kOk;
}

Result link_uplink_task(void* p) {
    Link& l = *static_cast<Link*>(p);
    LinkConfig c;
    read_config(l, c);
    service(l, c);
    for (uint8_t k = 0; k < FSW_LINK_RX_PER_RUN; ++k) {
        if (l.pending & kPendAck) break;  // one acknowledgement waits at a time
        const int16_t b = pal::console_read();
        if (b < 0) break;
        if (b == 0) {
            if (l.rx_over) {
                inc16(l.n.rx_oversized);
            } else if (l.rx_len != 0) {
                handle_frame(l, c);
            }
            l.rx_len = 0;
            l.rx_over = false;
            service(l, c);
        } else if (l.rx_len < sizeof l.rx) {
            l.rx[l.rx_len++] = static_cast<uint8_t>(b);
        } else {
            l.rx_over = true;
        }
    }
    return kOk;
}

void link_poll(Link& l) {
    if (l.cfg == 0) return;
    pump(l);
    if (l.tx_len != 0 || (l.pending == 0 && l.snapshot_at == kNoSnapshot)) return;
    LinkConfig c;
    read_config(l, c);
    service(l, c);
}

}  // namespace fsw
