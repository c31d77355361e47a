// The serial link: telemetry (samples, hello, health, acks, snapshots) and
// the uplink command parser. Frames are composed straight into the transmit
// buffer and framed there in one pass (cobs_frame); nothing here waits for
// the UART.
#include "fsw_link.h"

#include "fsw_app.h"
#include "fsw_cobs.h"
#include "fsw_crc.h"
#include "fsw_element.h"
#include "fsw_pal.h"
#include "fsw_sv.h"
#include "fsw_version.h"

namespace fsw {

// Health and ack frames send these fields as they lie in memory
// (little-endian targets, fsw_config.h).
static_assert(offsetof(LinkCounters, dropped) == offsetof(LinkCounters, frames) + 4, "health frame layout");
static_assert(offsetof(LinkCounters, last_seq) == offsetof(LinkCounters, rx_ok) + 12, "health frame layout");
static_assert(offsetof(Executor, late) == offsetof(Executor, cycles) + 4 &&
                  offsetof(Executor, reset_cause) == offsetof(Executor, cycles) + 6,
              "health frame layout");
static_assert(offsetof(Link, ack_op) == offsetof(Link, ack_seq) + 2 &&
                  offsetof(Link, ack_status) == offsetof(Link, ack_seq) + 3,
              "ack frame layout");

// The body bytes of the frame being composed (fsw_link.h: the stores' acks
// in fsw_link_stores.cpp add theirs through these too).
namespace {
uint8_t* g_at;  // the frame's first byte in the transmit buffer
uint8_t* g_w;   // where the next body byte goes
}  // namespace

FSW_NOINLINE void link_put(uint8_t b) { *g_w++ = b; }
FSW_NOINLINE void link_put_bytes(const void* p, uint16_t n) {
    uint8_t* const w = g_w;
    g_w = w + n;
    memcpy(w, p, n);  // last: nothing kept across it (a frame less on the stack's deep paths)
}

namespace {

inline void put(uint8_t b) { link_put(b); }
inline void put_bytes(const void* p, uint16_t n) { link_put_bytes(p, n); }

enum Pending : uint8_t { kPendAck = 1, kPendHello = 2, kPendHealth = 4 };
const uint16_t kNoSnapshot = 0xFFFFu;

void inc16(uint16_t& c) {
    if (c != 0xFFFFu) ++c;
}


// Copies state vector bytes, atomically when the `lock` option is on.
void sv_move(bool lock, void* dst, const void* src, uint16_t n) {
    const pal::IrqState saved = lock ? pal::critical_enter() : 0;
    memcpy(dst, src, n);
    if (lock) pal::critical_exit(saved);
}

// The transmit buffer, and its size: max(tx_cap, tx_size) of the
// configuration (FSW_FLASH; read where used, no copy in the Link).
inline uint8_t* tx_buf(const Link& l) { return flash_get(l.cfg->tx); }
inline uint16_t tx_bytes(const Link& l) {
    const uint16_t cap = flash_get(l.cfg->tx_cap), size = flash_get(l.cfg->tx_size);
    return size > cap ? size : cap;
}

// The console sends the frames from the transmit buffer where they were
// built (pal::console_send: no copy); the core's Serial takes them only as
// it is asked (the kit's UART driver by itself: this is then nothing).
inline void pump() {
    if (pal::console_needs_poll()) (void)pal::console_sending();
}

// Room for a frame of up to `need` encoded bytes; tx_len is then where it
// goes. The buffer (max(tx_cap, tx_size) bytes) holds at most two runs of
// frames: the one the UART sends, and one at the buffer's front that it
// goes on with once that one's end is out. A frame goes after the run
// frames were added to last, or, when it does not fit there and the UART
// is in that run, at the front, in the bytes the UART has sent; else there
// is no room for it yet. (A sample frame's `need` is its size bound; a
// control frame's, whose size is known only once composed, the longest
// frame's.) `at` is where the UART is (pal::console_sending(), asked by
// the caller: this then calls nothing, and saves nothing on the stack's
// deep paths, the sample frame's).
bool tx_room(Link& l, uint16_t need, const uint8_t* at) {
    const uint16_t size = tx_bytes(l);
    if (at == 0) {  // every byte out: the buffer is free
        l.tx_len = 0;
        return need <= size;
    }
    const uint16_t sent = static_cast<uint16_t>(at - tx_buf(l));  // the UART's place
    if (sent < l.tx_len) {  // in the run frames go after: the bytes before it are free
        if (need <= size - l.tx_len) return true;
        if (need > sent) return false;
        l.tx_len = 0;  // a second run, at the front
        return true;
    }
    return need <= sent - l.tx_len;  // in the run before: the bytes up to it
}

// The frame being composed: its body is written raw where its encoding
// goes (one byte after the frame's start, cobs_frame), then framed in one
// pass. A frame is composed whole within one call, so one write pointer
// serves every link; the helpers below keep each field to one short call.
// A value is stored from its registers where the body goes (little-endian
// targets, fsw_config.h): no copy of it on the caller's stack, the control
// frames' composer's being on the deepest path of the stack.
FSW_NOINLINE void put_u16(uint16_t v) {
    store<uint16_t>(g_w, v);
    g_w += 2;
}
FSW_NOINLINE void put_u32(uint32_t v) {
    store<uint32_t>(g_w, v);
    g_w += 4;
}

// The header: type, the frame counter's low byte (frame_begin), then the
// low 32 bits of the time; its high 32 bits lie after it, where the body's
// first 4 bytes go (a health frame's are they; a hello takes them and puts
// them again after its first 5; any other frame's body writes over them:
// every frame's room holds them): put_time.
// The frame goes after the bytes the transmit buffer still holds. Two
// calls, each of which saves nothing: with the time an argument of the
// first, in r14-r21, avr-gcc saved the four of them that are call-saved,
// though it only read them (4 bytes on the stack's deepest path, the
// telemetry step's sample frame's, an interrupt on top).
FSW_NOINLINE void frame_begin(Link& l, uint8_t type) {
    uint8_t* const at = tx_buf(l) + l.tx_len;
    g_at = at;
    at[1] = type;
    at[2] = static_cast<uint8_t>(l.n.frames);
    g_w = at + 3;
}
FSW_NOINLINE void put_time(uint64_t time) {
    store<uint64_t>(g_w, time);
    g_w += 4;
}

const uint16_t kNoFrame = 0xFFFFu;  // frame_end's `n`: no frame (a sample frame with no room)

// Frames the body in place, and `src`'s `n` bytes after it, copied in as
// they are framed (a sample frame's stored samples: no copy of them into
// the frame first), then, where `now` is a stream's row, that stream's
// current region out of the state vector likewise, and hands the frame to
// the UART, which sends it from where it lies.
// Called by the caller of the frame's composer (send_control's, service;
// send_batch's, the telemetry task's step) once the composer has returned:
// the framer's frame goes on the caller's, not on the composer's (18 and
// 28 bytes then, on the deepest paths of the stack). `n` kNoFrame: none.
FSW_NOINLINE void frame_end(Link& l, const uint8_t* src, uint16_t n, const LinkStream* now) {
    if (n == kNoFrame) return;
    const uint8_t* src2 = 0;
    uint16_t n2 = 0;
    if (now != 0) {
        src2 = flash_get(l.cfg->sv) + flash_get(now->off);
        n2 = flash_get(now->size);
    }
    const uint16_t len = cobs_frame(g_at, static_cast<uint16_t>(g_w - g_at - 1), src, n, src2, n2);
    l.tx_len = static_cast<uint16_t>(l.tx_len + len);
    ++l.n.frames;
    pal::console_send(g_at, len);  // (last: nothing kept across it)
}

// State vector bytes into the frame, atomically when the lock is on.
void put_sv(const uint8_t* sv, bool lock, uint16_t off, uint16_t n) {
    const pal::IrqState saved = lock ? pal::critical_enter() : 0;
    put_bytes(sv + off, n);
    if (lock) pal::critical_exit(saved);
}

// The state vector's `lock` option (fsw_app.h: never, where the application has none).
inline __attribute__((always_inline)) bool sv_lock(const LinkConfig& c) {
    return app_has(kAppSvLock) && flash_get(c.lock);
}

// What a sample frame's composer leaves for its framing: the stored
// samples' bytes, copied in from the stream's store as they are framed
// (`n` 0: none, or put in already with the lock on), or no frame at all
// (`n` kNoFrame: the batch was dropped). The current region follows them
// (frame_end's `now`).
struct SampleTail {
    const uint8_t* src;
    uint16_t n;
};

// Composes the frame of stream i's open batch (and of the current region
// when `with_now`): its header into the transmit buffer, the stored samples
// and the region left for the framer, which copies them in (or put in
// already, the region atomically, when the lock is on). The telemetry
// task's step frames and hands it (frame_end): the
// framer is then called from the step's frame, not from this one's, and the
// deepest path of the stack (the step's, the framer's) is this frame's 18
// bytes shorter. `row` is the stream's row in flash (FSW_FLASH), its
// fields read where used.
SampleTail send_batch(Link& l, const LinkConfig& f, const LinkStream& row, LinkStreamState& st, uint8_t i,
                      bool with_now) {
#if defined(__AVR__)
    FSW_SAVES_IN_RUN("r15");  // (fsw_types.h) the registers it saves through the shared routine
#endif
    const uint16_t size = flash_get(row.size);
    const uint8_t stored = st.count;
    st.count = 0;
    // the frame's encoded size bound: body, CRC, code bytes (body / 128: a
    // bound of body / 254 without a division), delimiter
    const uint16_t body = static_cast<uint16_t>(kLinkHeader + (stored + (with_now ? 1u : 0u)) * size);
    if (!tx_room(l, static_cast<uint16_t>(body + 4u + (body >> 7)), pal::console_sending())) {
        ++l.n.dropped;
        return SampleTail{0, kNoFrame};
    }
    frame_begin(l, static_cast<uint8_t>(kFrameSample | i));
    put_time(st.t0);
    const uint8_t* const store = flash_get(row.store);
    const uint16_t stored_n = static_cast<uint16_t>(stored * size);
    if (!sv_lock(f)) return SampleTail{store, stored_n};
    put_bytes(store, stored_n);  // the lock on: the current region copied in atomically, after them
    if (with_now) put_sv(flash_get(f.sv), true, flash_get(row.off), size);
    return SampleTail{0, 0};
}

void take_sample(Link& l, const LinkConfig& f, const LinkStream& row, LinkStreamState& st, uint8_t i,
                 uint32_t now32) {
    const uint16_t skipped = flash_get(f.ex)->skipped;
    // Samples of a frame are evenly spaced: a batch the executor broke by
    // skipping cycles goes out as it is (a cycle that only started late
    // still takes its sample).
    if (st.count != 0 && skipped != st.skipped0) {
        const SampleTail t = send_batch(l, f, row, st, i, false);
        frame_end(l, t.src, t.n, 0);
    }
    if (st.count == 0) {
        st.t0 = now32;
        st.skipped0 = skipped;
    }
    if (static_cast<uint8_t>(st.count + 1u) < flash_get(row.batch)) {
        const uint16_t size = flash_get(row.size);
        sv_move(sv_lock(f), flash_get(row.store) + st.count * size, flash_get(f.sv) + flash_get(row.off), size);
        ++st.count;
        return;
    }
    const SampleTail t = send_batch(l, f, row, st, i, true);
    // the current region copied in as it is framed, after the stored samples (with the lock, put
    // in atomically by send_batch)
    frame_end(l, t.src, t.n, sv_lock(f) ? 0 : &row);
}

// The parameter store's source byte of hello and health frames.
inline __attribute__((always_inline)) uint8_t param_source(const LinkConfig& c) {
    const ParamStore* const params = app_has(kAppParams) ? flash_get(c.params) : 0;
    return params != 0 ? params->source : static_cast<uint8_t>(kParamNone);
}

// One control frame composed (`type` is kFrameAck, kFrameHello,
// kFrameHealth or kFrameSnapshot); the caller (service) frames and hands it
// (frame_end), so the framer's frame goes on the caller's, not on this
// one's (28 bytes then, the deepest of the link's). The control path (service, send_control, the uplink's
// apply) reads the configuration `c`, an FSW_FLASH object, a field at a
// time where it uses one: no copy of the whole on the stack, whose deepest
// reach is on this path (a copy was 54 of the rocket's 192 bytes).
FSW_NOINLINE void send_control(Link& l, const LinkConfig& c, uint8_t type) {
    // the header takes the time's low half, hello and health its high half, which frame_begin
    // leaves after the header (a copy of the time on this frame's stack was 8 of the bytes on the
    // deepest path of the stack)
    frame_begin(l, type);
    put_time(flash_get(c.now)());
    const Executor& ex = *flash_get(c.ex);
    if (type == kFrameAck) {
        put_bytes(&l.ack_seq, 4);  // cmd_seq, op, status
        put_bytes(&l.n.last_seq, 2);
        // what the application has of the stores (fsw_app.h), and of those what the configuration
        // names; a store's function read only where the store is (a flash load is never dropped,
        // even when its value is not used: 24 B of the core rocket's flash read three of them)
        ParamStore* const params = app_has(kAppParams) ? flash_get(c.params) : 0;
        if (params != 0) {
            const LinkParamAckFn param_ack = flash_get(c.param_ack);
            if (param_ack != 0) param_ack(l, *params);
        }
        Recorder* const log = app_has(kAppLog) ? flash_get(c.log) : 0;
        if (log != 0) {
            const LinkLogAckFn log_ack = flash_get(c.log_ack);
            if (log_ack != 0) log_ack(l, *log);
        }
        ReloadStore* const reload = app_has(kAppReload) ? flash_get(c.reload) : 0;
        if (reload != 0) {
            const LinkReloadAckFn reload_ack = flash_get(c.reload_ack);
            if (reload_ack != 0) reload_ack(l, *reload);
        }
    } else if (type == kFrameHello) {
        // the time's high half, where frame_begin left it, goes after the protocol and the schema: taken
        // into registers and put again (a memmove of it and a step of the write pointer were 18 B more)
        const uint32_t time_hi = load<uint32_t>(g_w);
        put(kLinkProtocol);
        put_u32(flash_get(c.schema));
        put_u32(time_hi);
        put_bytes(&l.n.frames, 4);
        // the runtime's version, then the reset cause: two bytes a store (little-endian, fsw_config.h)
        put_u16(FSW_RUNTIME_VERSION_MAJOR | FSW_RUNTIME_VERSION_MINOR << 8);
        put_u16(static_cast<uint16_t>(FSW_RUNTIME_VERSION_PATCH | ex.reset_cause << 8));
        put_bytes(&l.n.last_seq, 2);
        put(param_source(c));
    } else if (type == kFrameHealth) {
        g_w += 4;  // the time's high half, where frame_begin left it
        put_bytes(&l.n.frames, 8);   // frames, dropped
        put_bytes(&ex.cycles, 7);    // cycles, late, reset_cause
        put_bytes(&l.n.rx_ok, 14);   // rx_ok .. last_seq
        put(param_source(c));
        const ExecConfig& ec = *ex.cfg;  // FSW_FLASH: the fields it uses, one at a time
        const uint8_t n_tasks = flash_get(ec.n_tasks);
        const TaskStats* const stats = flash_get(ec.stats);
        // (the rows and the state vector only for the tasks' mode elements, fsw_app.h)
        const Task* const tasks = app_has(kAppModeElems) ? flash_get(ec.tasks) : 0;
        const uint8_t* const sv = app_has(kAppModeElems) ? flash_get(ec.sv) : 0;
        for (uint8_t i = 0; i < n_tasks; ++i) {
            const TaskStats& s = stats[i];
            const ElemOff mode_off =  // the task's mode: its element, or its record
                app_has(kAppModeElems) ? flash_get(tasks[i].mode_off) : static_cast<ElemOff>(kNoElement);
            // worst_us saturated to 16 bits: its high half looked at, not a 32-bit compare (14 B)
            const uint16_t worst =
                static_cast<uint16_t>(s.worst_us >> 16) != 0 ? 0xFFFFu : static_cast<uint16_t>(s.worst_us);
            // the row's 6 bytes written where they go (no copy of them on the stack)
            put(mode_off != kNoElement ? sv[mode_off] : s.mode);
            put(s.faults);  // saturates at 255
            put_u16(s.overruns);
            put_u16(worst);
        }
        if (app_has(kAppPyro)) {
            const PyroGate* const pyro = flash_get(c.pyro);
            const uint8_t n_pyro = flash_get(c.n_pyro);
            for (uint8_t i = 0; i < n_pyro; ++i) put(pyro[i].status);  // kPyro* bits (fsw_io.h)
        }
        if (app_has(kAppSensors)) {
            const uint8_t* const sensors = flash_get(c.sensors);
            const uint8_t n_sensors = flash_get(c.n_sensors);
            for (uint8_t i = 0; i < n_sensors; ++i) put(sensors[i]);  // kSensor* codes (fsw_sensor.h)
        }
    } else {
        const uint16_t off = l.snapshot_at, sv_size = flash_get(c.sv_size), chunk = flash_get(c.snapshot_chunk);
        uint16_t n = static_cast<uint16_t>(sv_size - off);
        if (n > chunk) n = chunk;
        put_u16(off);
        put_sv(flash_get(c.sv), sv_lock(c), off, n);
        l.snapshot_at = static_cast<uint16_t>(off + n) >= sv_size ? kNoSnapshot : static_cast<uint16_t>(off + n);
    }
}

// Sends waiting control frames while the transmit buffer has room:
// acknowledgements first, then hello, health, snapshot chunks. Hello and
// health frames (the two long ones) are composed only between cycles
// (`big`: from link_poll, never in a task's step), and after one the next
// waits for a whole executor cycle to pass, so no cycle with the gap after
// it composes both.
void service(Link& l, const LinkConfig& c, bool big) {
    const uint16_t tx_cap = flash_get(c.tx_cap);
    const Executor* const ex = flash_get(c.ex);
    while (tx_room(l, tx_cap, pal::console_sending())) {
        const uint8_t p = l.pending;
        const uint8_t cycle = static_cast<uint8_t>(ex->cycles);
        const bool big_ok = big && static_cast<uint8_t>(cycle - l.big_cycle) >= 2u;
        // the frame sent: the lowest bit of those it may send (an ack, a hello, a health frame, in
        // that order), else a snapshot chunk
        const uint8_t may = big_ok ? p : static_cast<uint8_t>(p & kPendAck);
        const uint8_t bit = static_cast<uint8_t>(may & (0u - may));
        uint8_t type;
        if (bit == kPendAck) {
            type = kFrameAck;
        } else if (bit != 0) {
            static_assert(kPendHello >> 1 == kFrameHello && kPendHealth >> 1 == kFrameHealth, "service's frame types");
            type = static_cast<uint8_t>(bit >> 1);
            l.big_cycle = cycle;
        } else if (l.snapshot_at != kNoSnapshot) {
            type = kFrameSnapshot;
        } else {
            return;
        }
        l.pending = static_cast<uint8_t>(p & ~bit);
        send_control(l, c, type);
        frame_end(l, 0, 0, 0);
    }
}

// ---- uplink ----------------------------------------------------------------

// Whether the element at `off` is one the executor writes: a task's mode,
// overruns or worst_us, the reset cause. Modes change only by MODE, and the
// executor's records never by the ground, whatever the writable table lists.
bool executor_owns(const LinkConfig& c, ElemOff off) {
    const ExecConfig& ec = *flash_get(c.ex)->cfg;  // FSW_FLASH: the fields, one at a time
    if (off == flash_get(ec.reset_cause_off)) return true;
    if (!app_has(kAppModeElems | kAppMirrors)) return false;  // no task has an element (fsw_app.h)
    const uint8_t n_tasks = flash_get(ec.n_tasks);
    const Task* const tasks = flash_get(ec.tasks);
    for (uint8_t i = 0; i < n_tasks; ++i) {
        ElemOff own[3];  // mode, overruns, worst_us: adjacent in a Task row
        flash_read(own, &tasks[i].mode_off, sizeof own);
        if (off == own[0] || off == own[1] || off == own[2]) return true;
    }
    return false;
}

// elem_size of each type, looked up at run time (its shifts, inline, were
// 52 B of the core rocket's flash; the table and its load are 21).
constexpr uint8_t kElemSizes[kBool + 1] FSW_FLASH = {1, 2, 4, 8, 1, 2, 4, 8, 4, 8, 1};
constexpr bool elem_sizes_ok(uint8_t t) {
    return t > kBool || (kElemSizes[t] == elem_size(t) && elem_sizes_ok(static_cast<uint8_t>(t + 1u)));
}
static_assert(elem_sizes_ok(0), "kElemSizes follows elem_size");

uint8_t apply_set(const LinkConfig& c, const uint8_t* a, uint8_t alen) {
    if (alen < 2) return kAckBadLength;
    const uint16_t index = load<uint16_t>(a);
    const uint8_t n_writable = flash_get(c.n_writable);
    const LinkWritable* const rows = flash_get(c.writable);
    for (uint8_t k = 0; k < n_writable; ++k) {
        const LinkWritable& w = rows[k];  // FSW_FLASH: its fields read where used (no copy on the stack)
        if (flash_get(w.index) != index) continue;
        const uint8_t type = flash_get(w.type);
        const uint8_t size = flash_get(kElemSizes[type]);  // (a known type: link_writable_ok)
        if (alen != static_cast<uint8_t>(2u + size)) return kAckBadLength;
        const ElemOff off = flash_get(w.off);
        if (executor_owns(c, off)) return kAckLocked;
        uint8_t* const p = flash_get(c.sv) + off;
        const bool lock = sv_lock(c);
        const pal::IrqState saved = lock ? pal::critical_enter() : 0;
        memcpy(p, a + 2, size);
        if (type == kBool) *p = *p != 0 ? 1 : 0;  // a bool is stored as 0 or 1
        if (lock) pal::critical_exit(saved);
        return kAckOk;
    }
    return kAckNotWritable;
}

FSW_NOINLINE uint8_t apply(Link& l, const LinkConfig& c, uint8_t op, const uint8_t* a, uint8_t alen) {
#if defined(__AVR__)
    FSW_SAVES_IN_RUN("r12");  // (fsw_types.h) a command's, not a cycle's: the shared routine's cycles are paid rarely
#endif
    if (op == kOpSet) return apply_set(c, a, alen);
    // a store's commands; without the store (fsw_app.h, or none named): UNKNOWN_OP below
    if (app_has(kAppParams) && op >= kOpParamGet && op <= kOpParamInfo) {
        ParamStore* const params = flash_get(c.params);
        const LinkParamApplyFn param_apply = flash_get(c.param_apply);
        if (params == 0 || param_apply == 0) return kAckUnknownOp;
        return param_apply(l, *params, op, a, alen);
    }
    if (app_has(kAppLog) && op >= kOpLogInfo && op <= kOpLogErase) {
        Recorder* const log = flash_get(c.log);
        const LinkLogApplyFn log_apply = flash_get(c.log_apply);
        if (log == 0 || log_apply == 0) return kAckUnknownOp;
        return log_apply(l, *log, op, a, alen);
    }
    if (app_has(kAppReload) && op >= kOpMachineInfo && op <= kOpMachineActivate) {
        ReloadStore* const reload = flash_get(c.reload);
        const LinkReloadApplyFn reload_apply = flash_get(c.reload_apply);
        if (reload == 0 || reload_apply == 0) return kAckUnknownOp;
        return reload_apply(l, *reload, op, a, alen);
    }
    if (op == kOpMode) {
        if (alen != 2) return kAckBadLength;
        Executor& ex = *flash_get(c.ex);
        if (a[0] >= flash_get(ex.cfg->n_tasks)) return kAckBadTask;
        if (a[1] > kModeEnabled) return kAckBadMode;
        // the uplink task (the ground would lock itself out) and the task that ends the pyro
        // pulses (a pin high then would stay high) run always
        if ((a[0] == flash_get(c.uplink_task) || (app_has(kAppPyro) && a[0] == flash_get(c.pyro_task))) &&
            a[1] != kModeEnabled)
            return kAckLocked;
        executor_set_task_mode(ex, a[0], a[1]);
        return kAckOk;
    }
    if (op < kOpPing || op > kOpSnapshot) return kAckUnknownOp;
    if (alen != 0) return kAckBadLength;
    if (op == kOpHello) l.pending |= kPendHello;
    if (op == kOpSnapshot) l.snapshot_at = 0;
    return kAckOk;
}

// The frame's COBS decoded in place, its CRC worked out on the way
// (cobs_decode and crc16 in one pass, on 8-bit counts: a frame is at most
// FSW_LINK_RX_CAP bytes): its length, or 0 where a block runs past its end;
// `crc_ok`: the CRC over the decoded bytes, the frame's own last, is 0 (it
// matches). A block's implied zero goes out as the next block's code byte is
// read (there is one only where bytes follow). None of the frame's bytes is
// zero (the uplink took them up to the delimiter): a code or data byte of
// zero is not looked for.
static_assert(FSW_LINK_RX_CAP <= 255, "FSW_LINK_RX_CAP: a frame's length is a byte");
inline __attribute__((always_inline)) uint8_t decode_frame(uint8_t* rx, uint8_t len, bool& crc_ok) {
    const uint8_t* in = rx;
    uint8_t* out = rx;
    uint8_t hi = static_cast<uint8_t>(kCrcInit >> 8), lo = static_cast<uint8_t>(kCrcInit);
    uint8_t run = 0;     // data bytes left in the open block (0: the next byte is a code)
    bool zero = false;   // a zero goes out before the next block
    for (; len != 0; --len) {
        uint8_t b = *in++;
        if (run == 0) {  // a code byte: its block's data bytes follow
            run = static_cast<uint8_t>(b - 1u);
            if (run >= len) return 0;
            const bool z = zero;
            zero = b != 0xFFu;
            if (!z) continue;
            b = 0;
        } else {
            --run;
        }
        *out++ = b;
        crc16_step(hi, lo, b);
    }
    crc_ok = (hi | lo) == 0;
    return static_cast<uint8_t>(out - rx);
}

// One received frame, its `len` bytes at `rx` (COBS-encoded, delimiter
// stripped), decoded where they lie: decode, verify, apply, queue the
// acknowledgement. Anything not verified is only counted.
inline __attribute__((always_inline)) void handle_frame(Link& l, const LinkConfig& c, uint8_t* rx, uint8_t len) {
    bool crc_ok;
    const uint8_t n = decode_frame(rx, len, crc_ok);
    if (n < 5) {  // op, seq (2), CRC (2)
        inc16(l.n.rx_malformed);
        return;
    }
    if (!crc_ok) {
        inc16(l.n.rx_crc);
        return;
    }
    const uint8_t op = rx[0];
    const uint16_t seq = load<uint16_t>(rx + 1);
    const uint16_t ahead = static_cast<uint16_t>(seq - l.n.last_seq);
    uint8_t status;
    if (ahead == 0 || ahead >= 0x8000u) {
        inc16(l.n.rx_replayed);
        status = kAckReplay;
    } else {
        l.n.last_seq = seq;
        status = apply(l, c, op, rx + 3, static_cast<uint8_t>(n - 5u));
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

void link_begin(Link& l_, const LinkConfig* cfg) {
    Link& l = *by_pointer(&l_);
    // (zero since the reset where the link is begun once, as generated code does: fsw_app.h kAppBeginAgain)
    const bool clear = app_has(kAppBeginAgain);
    if (clear) memset(&l, 0, sizeof l);
    l.cfg = cfg;
    // The fields one at a time (no copy of the configuration on the stack:
    // generated code inlines this into main(), whose frame every path pays).
    const LinkConfig& c = *cfg;
    const uint8_t n_streams = flash_get(c.n_streams);
    const LinkStream* const streams = flash_get(c.streams);
    LinkStreamState* const states = flash_get(c.stream_state);
    for (uint8_t i = 0; i < n_streams; ++i) {
        const uint16_t every = flash_get(streams[i].every);  // (the row's one field used here)
        LinkStreamState& st = states[i];
        if (clear) memset(&st, 0, sizeof st);
        uint16_t first = i;  // i mod every: streams of equal rate take turns
        while (first >= every) first = static_cast<uint16_t>(first - every);
        st.countdown = first;
    }
    l.snapshot_at = kNoSnapshot;
    l.health_countdown = flash_get(c.health_every);
    l.hello_countdown = flash_get(c.hello_every);
    l.big_cycle = 0xFEu;  // the boot hello may go in the first cycle
    l.pending = kPendHello;
    // A delimiter first: a reset that cut a frame short leaves the ground
    // mid-frame, and without it the boot hello would be taken as the rest
    // of that frame and lost with it. (Sent from the transmit buffer, where
    // the frames after it go behind it.)
    uint8_t* const tx = flash_get(c.tx);
    tx[0] = 0;
    pal::console_send(tx, 1);
    l.tx_len = 1;
}

// The telemetry task's step: samples the streams due and sends the sample
// frames; control frames wait for link_poll, right after the cycle. It reads
// the fields it uses out of flash one at a time (no copy of the whole
// configuration: the task runs every cycle, and 4 runs in 10 on the rocket
// sample nothing), and the time once, when a stream is due.
Result link_telemetry_task(void* p) {
    Link& l = *static_cast<Link*>(p);
    const LinkConfig& f = *l.cfg;
    pump();
    uint32_t now32 = 0;
    bool have_now = false;
    const uint8_t n_streams = flash_get(f.n_streams);
    // the stream's row (FSW_FLASH) and record walked along with i: its row read where its fields
    // are used, no copy of it on the stack, on the deepest path of the rocket's (this task's
    // frame, the framer's)
    const LinkStream* row = flash_get(f.streams);
    LinkStreamState* st = flash_get(f.stream_state);
    for (uint8_t i = 0; i < n_streams; ++i, ++row, ++st) {
        if (st->countdown != 0) {
            --st->countdown;
            continue;
        }
        if (!have_now) {
            now32 = static_cast<uint32_t>(flash_get(f.now)());
            have_now = true;
        }
        st->countdown = static_cast<uint16_t>(flash_get(row->every) - 1u);
        take_sample(l, f, *row, *st, i, now32);
    }
    const uint16_t health_every = flash_get(f.health_every);
    if (health_every != 0 && --l.health_countdown == 0) {
        l.health_countdown = health_every;
        l.pending |= kPendHealth;
        const uint8_t hello_every = flash_get(f.hello_every);
        if (hello_every != 0 && --l.hello_countdown == 0) {
            l.hello_countdown = hello_every;
            l.pending |= kPendHello;
        }
    }
    return kOk;
}

namespace {

// Where the uplink reads a command (fsw_app.h kAppRxRing, kAppRxBuffer):
// where the console's receive ring holds it (pal::console_peek: no copy),
// or in the receive buffer the configuration names (LinkConfig rx), which
// is read out of flash only then.
inline __attribute__((always_inline)) bool rx_in_ring(const LinkConfig& c) {
    return app_has(kAppRxRing) && (!app_has(kAppRxBuffer) || flash_get(c.rx) == 0);
}

// The next byte received: in the ring, the one after the command's bytes
// so far (they stay there until its delimiter); else the ring's next.
inline __attribute__((always_inline)) int16_t next_byte(const Link& l, bool ring) {
    return ring ? pal::console_peek(l.rx_len) : pal::console_read();
}

// A delimiter received: the frame before it handled (or counted, when it
// was too long), and taken off the ring where it was read there. Out of
// line: the registers its decoding takes are then not saved on the uplink
// run's frame, which the service's calls, the deepest path of the stack, go
// on (on the core rocket 7 registers saved there, where 12 were).
FSW_NOINLINE void frame_received(Link& l, const LinkConfig& c) {
    const bool ring = rx_in_ring(c);
    const uint8_t n = l.rx_len;
    if (l.rx_over) {
        inc16(l.n.rx_oversized);
    } else if (n != 0) {
        handle_frame(l, c, ring ? pal::console_run(n) : flash_get(c.rx), n);
    }
    if (ring) pal::console_drop(static_cast<uint8_t>(n + 1u));  // the frame and its delimiter
    l.rx_len = 0;
    l.rx_over = false;
}

// The uplink task's run past its first look: the control frames waiting
// sent (service: `b` is -1 where its caller found some, or a snapshot,
// waiting, else the byte it read, and none waits), then the bytes
// received, `b` first, into the frame being received (where the ring
// holds it, until its delimiter, or the receive buffer); at a delimiter
// the frame is handled and the link serviced. The configuration is read out
// of flash a field at a time where it is used (send_control).
FSW_NOINLINE void uplink_run(Link& l, int16_t b) {
#if defined(__AVR__)
    FSW_SAVES_IN_RUN("r16");  // (fsw_types.h) run only when a byte came or a frame waits, not every cycle
#endif
    const LinkConfig& c = *l.cfg;
    const bool ring = rx_in_ring(c);
    if (b < 0) service(l, c, false);
    for (uint8_t k = 0; k < FSW_LINK_RX_PER_RUN; ++k) {
        if (k != 0 || b < 0) {  // (else b is the byte the caller read)
            if (l.pending & kPendAck) break;  // one acknowledgement waits at a time
            b = next_byte(l, ring);
            if (b < 0) break;
        }
        if (b == 0) {
            frame_received(l, c);
            service(l, c, false);
        } else if (!l.rx_over && l.rx_len < FSW_LINK_RX_CAP) {
            if (!ring) flash_get(c.rx)[l.rx_len] = static_cast<uint8_t>(b);
            ++l.rx_len;
        } else {  // too long: its bytes dropped up to its delimiter
            l.rx_over = true;
            if (ring) {
                pal::console_drop(static_cast<uint8_t>(l.rx_len + 1u));  // those so far and this one
                l.rx_len = 0;
            }
        }
    }
}

}  // namespace

// Most runs have nothing to send and receive nothing: with no control
// frame waiting, service would only hand the transmit buffer to the
// console, so such a run does that and looks for a received byte, and
// nothing more (the rest of the run is out of line: its frame on the
// stack is not paid by these runs).
Result link_uplink_task(void* p) {
    Link& l = *static_cast<Link*>(p);
    if (l.pending != 0 || l.snapshot_at != kNoSnapshot) {
        uplink_run(l, -1);
        return kOk;
    }
    pump();
    const int16_t b = next_byte(l, rx_in_ring(*l.cfg));
    if (b >= 0) uplink_run(l, b);
    return kOk;
}

// Whether the link was begun: a generated program begins it before its main
// loop polls it (setup(), fsw_gen::begin); a hand-written one or a test
// may poll it before (fsw_app.h kAppBeginAgain).
inline __attribute__((always_inline)) bool begun(const Link& l) { return !app_has(kAppBeginAgain) || l.cfg != 0; }

bool link_busy(const Link& l_) {
    const Link& l = *by_pointer(&l_);
    return begun(l) && (l.pending != 0 || l.snapshot_at != kNoSnapshot ||
                        (pal::console_needs_poll() && pal::console_sending() != 0));
}

void link_poll(Link& l_) {
    Link& l = *by_pointer(&l_);
    if (!begun(l)) return;
    pump();
    if (l.pending == 0 && l.snapshot_at == kNoSnapshot) return;
    service(l, *l.cfg, true);
}

}  // namespace fsw
