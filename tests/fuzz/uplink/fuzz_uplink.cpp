// libFuzzer target: the firmware's uplink parser and link tasks, compiled
// natively with ASan and UBSan. Any byte stream on the uplink must leave
// the invariants of docs/security.md intact:
//   1. only elements of the writable table change, and only by an applied SET;
//   2. task modes change only by an applied MODE, and the uplink task stays enabled;
//   3. the console is never written past its free space (the executor never blocks);
//   4. every frame the target sends decodes and verifies;
//   5. no out-of-bounds access, no undefined behaviour (the sanitizers);
//   6. parameters (docs/parameters.md) hold values in their ranges only, and
//      change only by an applied parameter command.
#include <stdio.h>
#include <stdlib.h>

#include "fsw_cobs.h"
#include "fsw_crc.h"
#include "fswkit.h"
#include "psl_native.h"

using namespace fsw;

namespace {

// sv: U32 a @0, F32 b @4 | U8 mode0 @8, U8 mode1 @9, bool flag @10, I16 level @11, F64 gain @13 | 21 bytes
uint8_t sv[21];
uint8_t store0[8];
LinkStreamState states[2];
uint8_t tx[96];
TaskStats stats[3];
uint16_t countdowns[3];  // the second task runs every other cycle
Executor ex;
Link link;
uint64_t clock_ms;
uint64_t now_fn() { return clock_ms; }
Result step_ok(void*) { return kOk; }

const Task kTasks[3] = {
    {link_uplink_task, 0, &link, 1, 0, 8, kNoElement, kNoElement, kModeEnabled},
    {step_ok, 0, 0, 2, 1, 9, kNoElement, kNoElement, kModeEnabled},
    {link_telemetry_task, 0, &link, 1, 0, kNoElement, kNoElement, kNoElement, kModeEnabled},
};
const LinkStream kStreams[2] = {{0, 8, 1, 2, store0}, {8, 13, 3, 1, 0}};
// The two mode elements are listed too, as no generated table lists them:
// the target must refuse their SET (LOCKED) whatever the table says.
const LinkWritable kWritable[5] = {{2, 8, kU8}, {3, 9, kU8}, {4, 10, kBool}, {5, 11, kI16}, {6, 13, kF64}};
// Parameters: F32 gainP [-10, 10] and U8 level [0, 5] in state 1, bool beep
// in states 1 and 2; the declaring machine's state is pstate (state 1).
uint8_t prm[6];
uint8_t pstate[4] = {1, 0, 0, 0};
uint8_t pstaged[1];
ParamStore params;
const ParamDef kParamDefs[3] = {{prm, 0, 0, kF32, 0}, {prm + 4, 4, 8, kU8, 0}, {prm + 5, 5, 0, kBool, 1}};
const ParamWhen kParamWhens[2] = {{0, 10, 1}, {0, 11, 1}};
const uint8_t kParamPool[12] = {0x00, 0x00, 0x20, 0xc1, 0x00, 0x00, 0x20, 0x41, 0, 5, 0x01, 0x03};
const uint8_t kParamDefaults[6] = {0, 0, 0x80, 0x3f, 2, 1};  // 1.0f, 2, true
const ParamConfig kParamConfig = {kParamDefs, kParamWhens, kParamPool, kParamDefaults, pstaged, pstate,
                                  0x5A5A0001UL, 6, 0, 3, false};

const LinkConfig kConfig = {sv, kStreams, states, kWritable, &ex, now_fn, tx, 0x12345678UL, 21, 96, 5,
                            21, 2, 5, 2, 0, false, &params, link_param_apply, link_param_ack,
                            0, 0, 0, 0, 0, 0xFF};


static_assert(link_stream_ok(0, 8, 1, 2, true, 21, 96) && link_stream_ok(8, 13, 3, 1, false, 21, 96) &&
                  link_writable_ok(13, kF64, 21) && link_config_ok(96, 21, 2, 3),
              "the tables are valid");

uint8_t out[8192];
uint16_t out_len;

void fail(const char* what) {
    fprintf(stderr, "invariant broken: %s\n", what);
    abort();
}

// invariant 6: every parameter within its range
void check_params(const uint8_t* before_prm, bool applied) {
    float g;
    memcpy(&g, prm, 4);
    if (!(g >= -10.0f && g <= 10.0f)) fail("a parameter out of its range");
    if (prm[4] > 5 || prm[5] > 1) fail("a parameter out of its range");
    if (!applied && memcmp(before_prm, prm, sizeof prm) != 0) fail("a parameter changed without an applied command");
}

// Every frame the target sent decodes and verifies (invariant 4).
void check_output() {
    uint16_t start = 0;
    static uint8_t body[256];
    for (uint16_t i = 0; i < out_len; ++i) {
        if (out[i] != 0) continue;
        const uint16_t n = static_cast<uint16_t>(i - start);
        if (n == 0 || n > sizeof body) fail("empty or oversized frame sent");
        memcpy(body, out + start, n);
        const int16_t d = cobs_decode(body, n);
        if (d < 8 || crc16(body, static_cast<uint16_t>(d)) != 0) fail("a frame sent does not verify");
        start = static_cast<uint16_t>(i + 1);
    }
    // a frame still being handed to a slow UART: keep its first bytes
    memmove(out, out + start, out_len - start);
    out_len = static_cast<uint16_t>(out_len - start);
}

// Framed mode (data[0] bit 1): the rest of the input is (length, body)...,
// each body sent as a whole uplink frame with its CRC and COBS, so that the
// fuzzer explores the command parsers behind the CRC (opcodes, arguments,
// sequence numbers) instead of the CRC itself.
uint8_t wire_buf[32768];

size_t frame_input(const uint8_t* data, size_t size) {
    size_t out = 0, i = 1;
    static uint8_t body[64];
    while (i < size && out + 2 * sizeof body < sizeof wire_buf) {
        const size_t n = data[i++] % 40u;
        const size_t take = n < size - i ? n : size - i;
        memcpy(body, data + i, take);
        i += take;
        const uint16_t crc = crc16(body, static_cast<uint16_t>(take));
        body[take] = static_cast<uint8_t>(crc >> 8);
        body[take + 1] = static_cast<uint8_t>(crc);
        CobsEncoder e;
        cobs_begin(e, wire_buf + out);
        cobs_put_bytes(e, body, static_cast<uint16_t>(take + 2));
        out += cobs_end(e);
        if (wire_buf[out - 1] != 0) wire_buf[out++] = 0;
    }
    return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size > 0 && (data[0] & 2)) {  // framed: CRC and COBS done here
        size = frame_input(data, size);
        data = wire_buf;
    }
    native::sim_reset();
    memset(sv, 0, sizeof sv);
    for (uint8_t i = 0; i < sizeof sv; ++i) sv[i] = static_cast<uint8_t>(0xA0 + i);
    clock_ms = 0;
    out_len = 0;
    native::console_capture(out, sizeof out, &out_len);
    const bool slow = size > 0 && (data[0] & 1);
    if (slow) native::console_model_uart(115200, 64);
    static const ExecConfig cfg = {kTasks, stats, sv, 10000, kNoElement, 3, false, countdowns};
    if (executor_begin(ex, &cfg) != kOk) fail("begin");
    pal::console_begin(115200UL);
    native::sim_eeprom_erase();
    param_begin(params, &kParamConfig);
    link_begin(link, &kConfig);
    // the boot's lone delimiter (it ends a frame a reset cut short), then frames only
    if (out_len != 1 || out[0] != 0) fail("the link did not start with a delimiter");
    out_len = 0;
    uint8_t before[sizeof sv];
    memcpy(before, sv, sizeof sv);
    uint8_t before_prm[sizeof prm];
    memcpy(before_prm, prm, sizeof prm);

    size_t at = 0;
    for (int cycle = 0; cycle < 4000 && (at < size || cycle < 2); ++cycle) {
        const size_t n = size - at < 24 ? size - at : 24;
        native::console_feed(data + at, static_cast<uint16_t>(n));
        at += n;
        const uint16_t ok_before = link.n.rx_ok;
        executor_run_cycle(ex);
        for (int k = 0; k < 2; ++k) {  // loop() between cycles
            clock_ms += 5;
            native::sim_advance_us(5000);
            link_poll(link);
            param_poll(params);
        }
        // invariants 1 and 2: compare against the last state
        const bool applied = link.n.rx_ok != ok_before;
        for (uint8_t i = 0; i < sizeof sv; ++i) {
            if (sv[i] == before[i]) continue;
            const bool writable = i >= 10;
            const bool mode1 = i == 9;
            if (!applied || !(writable || mode1)) fail("state vector changed without an applied command");
            if (i == 10 && sv[i] > 1) fail("bool stored as other than 0 or 1");
            if (mode1 && sv[i] > kModeEnabled) fail("mode out of range");
        }
        if (sv[8] != kModeEnabled) fail("the uplink task left enabled mode");
        check_params(before_prm, applied);
        memcpy(before_prm, prm, sizeof prm);
        memcpy(before, sv, sizeof sv);
        if (native::console_overruns() != 0) fail("changed bytes the UART had not sent, or handed a third run");
        check_output();
    }
    if (!slow && out_len != 0) fail("a frame sent is incomplete");
    return 0;
}
