// The serial link (docs/telemetry.md): the telemetry task streams regions,
// health and hello frames without ever blocking; the uplink task parses,
// verifies and applies ground commands between tasks. COBS frames with a
// CRC-16; constant tables generated from the application config.
#ifndef FSW_LINK_H
#define FSW_LINK_H

#include "fsw_executor.h"
#include "fsw_io.h"
#include "fsw_log.h"
#include "fsw_param.h"
#include "fsw_reload.h"
#include "fsw_types.h"

namespace fsw {

static const uint8_t kLinkProtocol = 2;

// Downlink frame types (target -> ground). A sample frame's type is
// kFrameSample | stream index (streams 0..127).
enum LinkFrame : uint8_t {
    kFrameHello = 0x01,
    kFrameHealth = 0x02,
    kFrameAck = 0x03,
    kFrameSnapshot = 0x04,
    kFrameSample = 0x80,
};

// Uplink opcodes (ground -> target).
enum LinkOp : uint8_t {
    kOpPing = 0x01,      // no arguments: acknowledged
    kOpHello = 0x02,     // no arguments: a hello frame follows the ack
    kOpSnapshot = 0x03,  // no arguments: the whole state vector follows
    kOpSet = 0x04,       // element index (u16), value (the element's bytes)
    kOpMode = 0x05,      // task index (u8), mode (u8: 0 disabled, 1 safed, 2 enabled)
    // parameters (docs/parameters.md); without a parameter store: UNKNOWN_OP
    kOpParamGet = 0x06,     // first id (u8), count (u8): the ack carries first, count, values
    kOpParamSet = 0x07,     // (id u8, value)...: all or none, live (not saved)
    kOpParamSave = 0x08,    // no arguments: write the live values to the other bank
    kOpParamBegin = 0x09,   // no arguments: open a load (staged into the other bank)
    kOpParamStage = 0x0A,   // (id u8, value)...
    kOpParamCommit = 0x0B,  // CRC-16 (u16) of the value block the load makes
    kOpParamInfo = 0x0C,    // no arguments: the ack carries the store's state
    // the flight recorder (docs/recorder.md); without one: UNKNOWN_OP
    kOpLogInfo = 0x0D,   // no arguments: the ack carries the recorder's state
    kOpLogRead = 0x0E,   // record (u16), offset (u8), count (u8): the ack carries the bytes
    kOpLogErase = 0x0F,  // no arguments: erase every record (only in the states `[log] erase` names)
    // machines replaced at run time (docs/reload.md); without `[reload]`: UNKNOWN_OP
    kOpMachineInfo = 0x10,      // no arguments: the ack carries the slots and the upload's state
    kOpMachineBegin = 0x11,     // image bytes (u16), mask bytes (u8), CRC-16 of both (u16)
    kOpMachineWrite = 0x12,     // offset (u16), bytes (1..FSW_RELOAD_QUEUE)
    kOpMachineCommit = 0x13,    // no arguments: the CRC and the verifier; BAD_IMAGE carries the reason
    kOpMachineActivate = 0x14,  // 0 the generated machine, 1 or 2 a slot: at the next allowed step
};

// Acknowledgement status: 0 applied, anything else refused (a NACK).
enum LinkStatus : uint8_t {
    kAckOk = 0,
    kAckReplay = 1,       // sequence number not newer than the last accepted one
    kAckUnknownOp = 2,
    kAckBadLength = 3,    // arguments of the wrong length for the opcode / element
    kAckNotWritable = 4,  // the element is not in the application's [uplink] list
    kAckBadTask = 5,      // no such task
    kAckBadMode = 6,      // mode not 0, 1 or 2
    kAckLocked = 7,       // the executor's: the uplink task's mode, the mode of the task that ends
                          // the pyro pulses, or a SET of a task's mode, overruns or worst_us element
                          // or of the reset cause
    // the parameter store's (ParamStatus, fsw_param.h)
    kAckNoParam = 8,      // no such parameter
    kAckOutOfRange = 9,   // a value outside its range
    kAckWrongState = 10,  // the declaring machine is not in a state that allows a change
    kAckBusy = 11,        // a bank is being written, or the stage queue is full
    kAckNoLoad = 12,      // STAGE or COMMIT without BEGIN
    kAckMismatch = 13,    // the staged set's CRC is not the committed one
    // the reload store's (ReloadStatus, fsw_reload.h)
    kAckTooBig = 14,      // the image does not fit a slot
    kAckBadImage = 15,    // the verifier refused the image (its reason follows in the ack)
    kAckNoImage = 16,     // no committed image in that slot
};

static const uint8_t kLinkHeader = 6;  // type, sequence number, time (low 32 bits)
// FSW_LINK_RX_CAP and FSW_LINK_RX_PER_RUN: fsw_config.h.

// One telemetry stream (FSW_FLASH table row).
struct LinkStream {
    uint16_t off;    // region offset in the state vector
    uint16_t size;   // region size, bytes
    uint16_t every;  // telemetry-task runs between two samples, >= 1
    uint8_t batch;   // samples per frame, >= 1
    uint8_t* store;  // RAM for the first batch - 1 samples (null when batch is 1)
};

// A stream's run-time record (RAM, zero-initialised).
struct LinkStreamState {
    uint32_t t0;         // time of the first sample of the open batch
    uint16_t countdown;  // telemetry runs until the next sample
    uint16_t skipped0;   // executor `skipped` count when the batch opened
    uint8_t count;       // samples in the open batch
};

// An element the ground may write (FSW_FLASH table row, sorted by index).
struct LinkWritable {
    uint16_t index;  // the element's position in the state vector layout
    uint16_t off;    // its offset
    uint8_t type;    // ElemType
};

typedef uint64_t (*LinkClockFn)();

struct Link;
// The parameter commands (docs/parameters.md), reached through the
// configuration so that a link without parameters links none of their code:
// generated code passes link_param_apply and link_param_ack (below).
typedef uint8_t (*LinkParamApplyFn)(Link& link, ParamStore& store, uint8_t op, const uint8_t* args, uint8_t len);
typedef void (*LinkParamAckFn)(Link& link, const ParamStore& store);
// The recorder's commands, likewise: generated code passes link_log_apply and link_log_ack.
typedef uint8_t (*LinkLogApplyFn)(Link& link, Recorder& rec, uint8_t op, const uint8_t* args, uint8_t len);
typedef void (*LinkLogAckFn)(Link& link, const Recorder& rec);
// The reload commands, likewise: generated code passes link_reload_apply and link_reload_ack.
typedef uint8_t (*LinkReloadApplyFn)(Link& link, ReloadStore& store, uint8_t op, const uint8_t* args, uint8_t len);
typedef void (*LinkReloadAckFn)(Link& link, const ReloadStore& store);

// The link's configuration: constant data generated from the application
// config (FSW_FLASH), pointing at the RAM it works in.
struct LinkConfig {
    uint8_t* sv;
    const LinkStream* streams;        // n_streams rows
    LinkStreamState* stream_state;    // n_streams records
    const LinkWritable* writable;     // n_writable rows
    Executor* ex;                     // task health and modes (required)
    LinkClockFn now;                  // the time `G` is written from
    uint8_t* tx;                      // transmit buffer of max(tx_cap, tx_size) bytes
    uint32_t schema;                  // schema hash of layout + link configuration
    uint16_t sv_size;
    uint16_t tx_cap;                  // >= the longest encoded frame
    uint16_t health_every;            // telemetry runs between health frames (0: none)
    uint16_t snapshot_chunk;          // state vector bytes per snapshot frame
    uint8_t n_streams;
    uint8_t n_writable;
    uint8_t hello_every;              // health frames between hellos (0: only on request)
    uint8_t uplink_task;              // index of the uplink task (0xFF: none)
    bool lock;                        // state vector `lock` option
    ParamStore* params;               // the parameter store (null: no parameters; docs/parameters.md)
    LinkParamApplyFn param_apply;     // link_param_apply, with a store
    LinkParamAckFn param_ack;         // link_param_ack, with a store
    Recorder* log;                    // the flight recorder (null: none; docs/recorder.md)
    LinkLogApplyFn log_apply;         // link_log_apply, with a recorder
    LinkLogAckFn log_ack;             // link_log_ack, with a recorder
    const PyroGate* pyro;             // the pyro channels' gates: a status byte each in health frames
    uint8_t n_pyro;
    uint8_t pyro_task;                // index of the outputs task that ends their pulses (0xFF: none)
    uint16_t tx_size;                 // bytes of `tx` (0: tx_cap). Above tx_cap, a frame may wait behind
                                      // the unsent rest of the one before (a link near its line rate)
    ReloadStore* reload;              // machines replaced at run time (null: none; docs/reload.md)
    LinkReloadApplyFn reload_apply;   // link_reload_apply, with a store
    LinkReloadAckFn reload_ack;       // link_reload_ack, with a store
    uint8_t* rx;                      // the receive buffer, FSW_LINK_RX_CAP bytes, a command's bytes are
                                      // taken into off the console's ring (fsw_app.h kAppRxBuffer); null:
                                      // a command is decoded where the ring holds it (kAppRxRing)
    const uint8_t* sensors;           // the sensor parts' health codes (fsw_sensor.h kSensor*), in table
                                      // order, RAM the inputs task keeps current: a byte each in health
                                      // frames, after the pyro status bytes (docs/sensor-table.md)
    uint8_t n_sensors;                // how many (0: none)
};

// Counters reported in health frames (saturating where 16-bit). Health
// frames send frames..dropped and rx_ok..last_seq as they lie in memory.
struct LinkCounters {
    uint32_t frames;        // frames sent: the next frame's full sequence number
    uint32_t dropped;       // frames not sent because the transmit buffer was busy
    uint16_t rx_ok;         // commands applied
    uint16_t rx_crc;        // uplink frames with a CRC mismatch
    uint16_t rx_malformed;  // bad COBS, too short, unknown opcode, wrong argument length
    uint16_t rx_oversized;  // longer than FSW_LINK_RX_CAP encoded bytes
    uint16_t rx_replayed;   // sequence number not newer than the last accepted one
    uint16_t rx_refused;    // well-formed but refused (not writable, bad task or mode, locked)
    uint16_t last_seq;      // sequence number of the last accepted command
};

// (The transmit buffer's address and size are read out of the configuration
// where used: no copy of them here.)
struct Link {
    const LinkConfig* cfg;  // FSW_FLASH
    uint16_t tx_len;        // where the next frame goes in the transmit buffer: the end of the run of
                            // frames handed last (the UART sends them from there: pal::console_send)
    LinkCounters n;
    uint16_t health_countdown;
    uint16_t snapshot_at;   // next snapshot offset (0xFFFF: no snapshot under way)
    uint16_t ack_seq;
    uint8_t ack_op;
    uint8_t ack_status;
    uint8_t ack_x;          // parameter commands: the first id asked for (GET), the id refused
    uint8_t ack_y;          // GET: how many values were asked for
    uint8_t pending;        // control frames waiting for the transmit buffer
    uint8_t hello_countdown;
    uint8_t big_cycle;      // low byte of the executor cycle count at the last hello or health frame
    uint8_t rx_len;         // bytes of the command being received (in the receive buffer, or the
                            // first bytes waiting in the console's ring: LinkConfig rx)
    bool rx_over;           // it is longer than FSW_LINK_RX_CAP: its bytes are dropped
};

// Starts the link: zeroes its records (generated code, which begins it once,
// right after the reset, finds them zero: fsw_app.h kAppBeginAgain) and
// queues the boot hello. The caller opens the console first
// (pal::console_begin: generated code passes the baud rate as a constant,
// so the divisor is computed when compiling). `cfg` points at an FSW_FLASH
// object whose tables were checked when they were compiled (link_*_ok
// below): nothing is checked at run time.
void link_begin(Link& link, const LinkConfig* cfg);
// Executor task steps (ctx = the Link): never block, never fault.
Result link_telemetry_task(void* link);
Result link_uplink_task(void* link);
// From loop(), between cycles: sends waiting control frames (hello and
// health frames only here, never in a task's step) (and, where the console
// is the core's Serial, feeds it the frames as its buffer drains). Before
// link_begin it does nothing, and link_busy is false, in a program with
// kAppBeginAgain (fsw_app.h; generated code begins the link first).
void link_poll(Link& link);
// Whether link_poll has work: control frames or a snapshot waiting, or
// frames the core's Serial has still to take (the sleeping executor wakes
// the main loop for it; the kit's UART driver sends the frames by itself).
bool link_busy(const Link& link);
// The body of the frame being composed, a byte or `n` bytes more: what a
// store's ack function (below) adds after the acknowledgement's 6 bytes.
void link_put(uint8_t b);
void link_put_bytes(const void* p, uint16_t n);
// A parameter command (kOpParamGet..kOpParamInfo) on the store, and what its
// acknowledgement carries after its 6 bytes (GET's values, INFO's state,
// the id a refusal stopped at).
uint8_t link_param_apply(Link& link, ParamStore& store, uint8_t op, const uint8_t* args, uint8_t len);
void link_param_ack(Link& link, const ParamStore& store);
// A recorder command (kOpLogInfo..kOpLogErase), and what its ack carries.
uint8_t link_log_apply(Link& link, Recorder& rec, uint8_t op, const uint8_t* args, uint8_t len);
void link_log_ack(Link& link, const Recorder& rec);
// A reload command (kOpMachineInfo..kOpMachineActivate), and what its ack carries.
uint8_t link_reload_apply(Link& link, ReloadStore& store, uint8_t op, const uint8_t* args, uint8_t len);
void link_reload_ack(Link& link, const ReloadStore& store);
// (The six in fsw_link_stores.cpp.)

// ---- compile-time checks of the tables -------------------------------------
// The generator emits a static_assert of each for its tables; a hand-written
// configuration should do the same. Sizes are computed in 32 bits.

// Encoded size bound of a frame whose body is `body` bytes (COBS of body +
// CRC, delimiter included): cobs_max_encoded without its 16-bit limit.
constexpr uint32_t link_encoded_max(uint32_t body) { return body + 2u + (body + 2u) / 254u + 2u; }

// A stream: sampled at least every run, at least one sample per frame, a
// batch store when it batches, a region inside the state vector, and its
// longest frame fits the transmit buffer.
constexpr bool link_stream_ok(uint16_t off, uint16_t size, uint16_t every, uint8_t batch, bool has_store,
                              uint16_t sv_size, uint16_t tx_cap) {
    return every != 0 && batch != 0 && (batch == 1 || has_store) && static_cast<uint32_t>(off) + size <= sv_size &&
           link_encoded_max(kLinkHeader + static_cast<uint32_t>(batch) * size) <= tx_cap;
}

// A writable element: a known type, inside the state vector.
constexpr bool link_writable_ok(uint16_t off, uint8_t type, uint16_t sv_size) {
    return elem_size(type) != 0 && static_cast<uint32_t>(off) + elem_size(type) <= sv_size;
}

// The rest: at most 128 streams, snapshot chunks of at least one byte, and a
// transmit buffer that holds a hello (the longest control frame but
// health; a PARAM_INFO ack is shorter), a health frame for `n_tasks` tasks and a snapshot chunk.
// `n_pyro`: the health frame's trailing bytes, a pyro status per channel and a
// sensor health code per part (LinkConfig sensors).
constexpr bool link_config_ok(uint16_t tx_cap, uint16_t snapshot_chunk, uint8_t n_streams, uint8_t n_tasks,
                              uint8_t n_pyro = 0) {
    return n_streams <= 128 && snapshot_chunk != 0 && link_encoded_max(kLinkHeader + 20u) <= tx_cap &&
           link_encoded_max(kLinkHeader + 34u + 6u * n_tasks + n_pyro) <= tx_cap &&
           link_encoded_max(kLinkHeader + 2u + snapshot_chunk) <= tx_cap;
}

}  // namespace fsw

#endif  // FSW_LINK_H
