// Scenario: the serial link on the native PSL: CRC-16 and COBS, telemetry
// frames (samples with batching, hello, health), the transmit path never
// blocking (a full UART drops frames and counts them), and the uplink:
// writable elements only, modes, replays, CRC errors, malformed, truncated
// and oversized frames refused and counted, never acted on.
#include "test_support.h"

#include "fsw_cobs.h"
#include "fsw_crc.h"
#include "psl_native.h"

using namespace fsw;

// sv: Sensors = U32 a @0, F32 b @4 (8 bytes); Cmd = U8 mode @8, bool flag @9,
// I16 level @10, F64 gain @12 (12 bytes); 20 bytes.
static uint8_t sv[20];
static uint8_t store0[8];
static LinkStreamState states[2];
static uint8_t tx[96];
static TaskStats stats[2];
static Executor ex;
static Link link;
static uint64_t clock_ms;

static uint64_t now_fn() { return clock_ms; }

static const Task kTasks[2] FSW_FLASH = {
    {link_uplink_task, 0, &link, 1, 0, kNoElement, kNoElement, kNoElement, kModeEnabled},
    {link_telemetry_task, 0, &link, 1, 0, 8, kNoElement, kNoElement, kModeEnabled},
};
static const ExecConfig kExecConfig FSW_FLASH = {kTasks, stats, sv, 10000, kNoElement, 2, false, 0};
static const LinkStream kStreams[2] FSW_FLASH = {
    {0, 8, 1, 2, store0},  // Sensors every run, 2 per frame
    {8, 12, 4, 1, 0},      // Cmd every 4th run
};
// writable: flag (element 3), level (4), gain (5); not a (0), b (1), mode (2)
static const LinkWritable kWritable[3] FSW_FLASH = {{3, 9, kBool}, {4, 10, kI16}, {5, 12, kF64}};
static const LinkConfig kConfig FSW_FLASH = {sv, kStreams, states, kWritable, &ex, now_fn, tx, 0xA5A55A5AUL,
                                             20, 96, 10, 20, 2, 3, 3, 0, false, 0, 0, 0, 0, 0, 0, 0, 0, 0xFF, 0, 0, 0, 0, 0, 0, 0};

static uint8_t out[8192];
static uint16_t out_len;

void setUp(void) {
    native::sim_reset();
    memset(sv, 0, sizeof sv);
    clock_ms = 1000;
    native::console_capture(out, sizeof out, &out_len);
    TEST_ASSERT_EQUAL(kOk, executor_begin(ex, &kExecConfig));
    pal::console_begin(115200UL);
    link_begin(link, &kConfig);
}
void tearDown(void) {}

// ---- a tiny ground: split the captured bytes into verified frames ------------
struct Frame {
    uint8_t body[128];
    int16_t len;  // body length without CRC; -1 bad
};
static Frame frames[64];
static uint8_t n_frames;

static void collect() {
    n_frames = 0;
    uint16_t start = 0;
    for (uint16_t i = 0; i < out_len && n_frames < 64; ++i) {
        if (out[i] != 0) continue;
        const uint16_t n = static_cast<uint16_t>(i - start);
        if (n == 0) {  // two delimiters in a row (the boot's first byte): no frame, as on the ground
            start = static_cast<uint16_t>(i + 1);
            continue;
        }
        Frame& f = frames[n_frames++];
        memcpy(f.body, out + start, n);
        int16_t d = cobs_decode(f.body, n);
        f.len = (d >= 8 && crc16(f.body, static_cast<uint16_t>(d)) == 0) ? static_cast<int16_t>(d - 2) : -1;
        start = static_cast<uint16_t>(i + 1);
    }
    out_len = 0;
}

static const Frame* find(uint8_t type, uint8_t nth = 0) {
    for (uint8_t i = 0; i < n_frames; ++i) {
        if (frames[i].len >= 0 && frames[i].body[0] == type && nth-- == 0) return &frames[i];
    }
    return 0;
}

static void run(uint16_t cycles) {
    for (uint16_t i = 0; i < cycles; ++i) {
        executor_run_cycle(ex);
        clock_ms += 10;
        link_poll(link);
    }
}

static void send_cmd(uint8_t op, uint16_t seq, const uint8_t* args, uint8_t n) {
    uint8_t raw[64];
    CobsEncoder e;
    cobs_begin(e, raw);
    cobs_put(e, op);
    cobs_put_u16(e, seq);
    cobs_put_bytes(e, args, n);
    const uint16_t len = cobs_end(e);
    native::console_feed(raw, len);
}

// The status of the last ack for command `seq`, or -1.
static int ack_status(uint16_t seq) {
    collect();
    int st = -1;
    for (uint8_t i = 0; i < n_frames; ++i) {
        const Frame& f = frames[i];
        if (f.len == 12 && f.body[0] == kFrameAck && (f.body[6] | (f.body[7] << 8)) == seq) st = f.body[9];
    }
    return st;
}

// ---- CRC and COBS ------------------------------------------------------------

static void test_crc_is_ccitt_false(void) {
    const uint8_t check[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
    TEST_ASSERT_EQUAL_HEX16(0x29B1, crc16(check, 9));  // binascii.crc_hqx(b"123456789", 0xFFFF)
}

static void test_cobs_roundtrip_and_limits(void) {
    static uint8_t raw[600], enc[700];
    uint32_t x = 12345;
    for (uint16_t n = 0; n < 600; n = static_cast<uint16_t>(n + 7)) {
        for (uint16_t i = 0; i < n; ++i) {
            x = x * 1103515245u + 12345u;
            raw[i] = (x >> 16) % 3 == 0 ? 0 : static_cast<uint8_t>(x >> 8);
        }
        CobsEncoder e;
        cobs_begin(e, enc);
        cobs_put_bytes(e, raw, n);
        const uint16_t len = cobs_end(e);
        TEST_ASSERT_TRUE(len <= cobs_max_encoded(static_cast<uint16_t>(n + 2)));
        TEST_ASSERT_EQUAL_UINT8(0, enc[len - 1]);
        for (uint16_t i = 0; i + 1 < len; ++i) TEST_ASSERT_NOT_EQUAL(0, enc[i]);
        const int16_t d = cobs_decode(enc, static_cast<uint16_t>(len - 1));
        TEST_ASSERT_EQUAL_INT16(n + 2, d);
        if (n != 0) TEST_ASSERT_EQUAL_MEMORY(raw, enc, n);
        TEST_ASSERT_EQUAL_UINT16(0, crc16(enc, static_cast<uint16_t>(d)));
    }
    uint8_t bad[] = {5, 1, 2};  // a block that runs past the end
    TEST_ASSERT_EQUAL_INT16(-1, cobs_decode(bad, 3));
    uint8_t zero[] = {3, 0, 1};
    TEST_ASSERT_EQUAL_INT16(-1, cobs_decode(zero, 3));
}

// The in-place framer (whole, and a part in place with the rest copied in)
// against the incremental encoder (the one the link used before, kept as
// the reference): the same bytes for random bodies of
// every length 0..600 (zeros often, runs of 254 and more non-zero bytes, a
// full block at the body's or the CRC's end), and the inline CRC step
// against crc16_update for every CRC value's high byte and every data byte.
static void test_framer_matches_the_incremental_encoder(void) {
    static uint8_t raw[600], enc[700], framed[700];
    uint32_t x = 777;
    for (uint16_t n = 0; n <= 600; ++n) {
        const uint8_t zeros = static_cast<uint8_t>(n % 4 == 0 ? 0 : n % 4 == 1 ? 2 : n % 4 == 2 ? 50 : 255);
        for (uint16_t i = 0; i < n; ++i) {
            x = x * 1103515245u + 12345u;
            const uint8_t b = static_cast<uint8_t>(x >> 16);
            raw[i] = static_cast<uint8_t>(x >> 24) < zeros ? 0 : (b == 0 ? 1 : b);
        }
        CobsEncoder e;
        cobs_begin(e, enc);
        cobs_put_bytes(e, raw, n);
        const uint16_t len = cobs_end(e);
        memset(framed, 0xEE, sizeof framed);
        memcpy(framed + 1, raw, n);
        const uint16_t flen = cobs_frame(framed, n);
        TEST_ASSERT_EQUAL_UINT16(len, flen);
        TEST_ASSERT_EQUAL_MEMORY(enc, framed, len);
        TEST_ASSERT_TRUE(flen <= cobs_max_encoded(static_cast<uint16_t>(n + 2)));
        TEST_ASSERT_EQUAL_HEX8(0xEE, framed[flen]);  // nothing written past the frame
        // a part framed in place, the rest copied in as it is framed
        const uint16_t split = static_cast<uint16_t>(n * 3u / 7u);
        memset(framed, 0xEE, sizeof framed);
        memcpy(framed + 1, raw, split);
        const uint16_t clen = cobs_frame(framed, split, raw + split, static_cast<uint16_t>(n - split));
        TEST_ASSERT_EQUAL_UINT16(len, clen);
        TEST_ASSERT_EQUAL_MEMORY(enc, framed, len);
        TEST_ASSERT_EQUAL_HEX8(0xEE, framed[clen]);
        // and the rest in two parts copied in (a sample frame's stored samples, its current region)
        const uint16_t split2 = static_cast<uint16_t>(split + (n - split) / 3u);
        memset(framed, 0xEE, sizeof framed);
        memcpy(framed + 1, raw, split);
        const uint16_t tlen = cobs_frame(framed, split, raw + split, static_cast<uint16_t>(split2 - split),
                                         raw + split2, static_cast<uint16_t>(n - split2));
        TEST_ASSERT_EQUAL_UINT16(len, tlen);
        TEST_ASSERT_EQUAL_MEMORY(enc, framed, len);
        TEST_ASSERT_EQUAL_HEX8(0xEE, framed[tlen]);
    }
    for (uint16_t hi = 0; hi < 256; ++hi) {
        for (uint16_t b = 0; b < 256; ++b) {
            const uint16_t crc = static_cast<uint16_t>(hi << 8 | (hi * 37u + b) % 256u);
            uint8_t h = static_cast<uint8_t>(crc >> 8), l = static_cast<uint8_t>(crc);
            crc16_step(h, l, static_cast<uint8_t>(b));
            TEST_ASSERT_EQUAL_HEX16(crc16_update(crc, static_cast<uint8_t>(b)), static_cast<uint16_t>(h << 8 | l));
        }
    }
}

// ---- telemetry -------------------------------------------------------------------

static void test_boot_hello_carries_the_schema(void) {
    run(1);
    collect();
    const Frame* h = find(kFrameHello);
    TEST_ASSERT_NOT_NULL(h);
    TEST_ASSERT_EQUAL_INT16(6 + 20, h->len);
    TEST_ASSERT_EQUAL_UINT8(kParamNone, h->body[6 + 19]);  // no parameter store
    TEST_ASSERT_EQUAL_UINT8(0, h->body[1]);  // the first frame
    TEST_ASSERT_EQUAL_UINT8(kLinkProtocol, h->body[6]);
    uint32_t schema;
    memcpy(&schema, h->body + 7, 4);
    TEST_ASSERT_EQUAL_HEX32(0xA5A55A5AUL, schema);
}

// The first byte after boot is a delimiter: a reset that cut a frame short
// leaves the ground mid-frame, and the boot hello must not be taken as the
// rest of it.
static void test_the_link_starts_with_a_delimiter(void) {
    TEST_ASSERT_EQUAL_UINT16(1, out_len);
    TEST_ASSERT_EQUAL_HEX8(0, out[0]);
    run(1);
    collect();
    TEST_ASSERT_NOT_NULL(find(kFrameHello));
}

static void test_samples_batch_with_time_and_sequence(void) {
    store<uint32_t>(sv + 0, 7);
    run(1);  // hello, and the first Sensors sample goes to the batch store
    store<uint32_t>(sv + 0, 8);
    run(1);  // second sample: a frame of two
    collect();
    const Frame* f = find(kFrameSample | 0);
    TEST_ASSERT_NOT_NULL(f);
    TEST_ASSERT_EQUAL_INT16(6 + 16, f->len);
    uint32_t t0;
    memcpy(&t0, f->body + 2, 4);
    TEST_ASSERT_EQUAL_UINT32(1000, t0);  // the first sample's time
    TEST_ASSERT_EQUAL_UINT32(7, load<uint32_t>(f->body + 6));
    TEST_ASSERT_EQUAL_UINT32(8, load<uint32_t>(f->body + 14));
    // sequence numbers count every frame sent
    for (uint8_t i = 0; i < n_frames; ++i) TEST_ASSERT_EQUAL_UINT8(i, frames[i].body[1]);
}

static void test_health_reports_tasks_and_counters(void) {
    run(10);
    collect();
    const Frame* h = find(kFrameHealth);
    TEST_ASSERT_NOT_NULL(h);
    TEST_ASSERT_EQUAL_INT16(6 + 34 + 6 * 2, h->len);
    // executor cycles so far: composed between cycles (link_poll), after the 10th
    TEST_ASSERT_EQUAL_UINT32(10, load<uint32_t>(h->body + 6 + 12));
    TEST_ASSERT_EQUAL_UINT8(kParamNone, h->body[6 + 33]);           // no parameter store
    TEST_ASSERT_EQUAL_UINT8(kModeEnabled, h->body[6 + 34]);         // task 0 mode
}

static void test_full_uart_drops_and_counts_never_blocks(void) {
    native::console_model_uart(9600, 16);  // a slow link with a tiny buffer
    run(200);
    TEST_ASSERT_EQUAL_UINT32(0, native::console_overruns());  // never wrote past the space
    TEST_ASSERT_TRUE(link.n.dropped > 0);
    native::console_model_uart(0, 0);
    // what was sent is a gap-free sequence of verified frames
    collect();
    for (uint8_t i = 1; i < n_frames; ++i) {
        if (frames[i].len < 0) continue;
        TEST_ASSERT_TRUE(frames[i].len >= 6);
    }
}

// A sample frame waits behind the unsent rest of the one before when the
// transmit buffer has room for it, instead of being dropped; a buffer of
// two frames (tx_size: a link near its line rate) always has, so a health
// frame no longer costs the next sample; the bytes on the wire are still a
// gap-free sequence of verified frames. Two streams of the whole state
// vector sampled every run (30 B encoded each), a health frame every 10th
// run (56 B) and a hello every 30th (30 B): about 67 B a cycle on a line
// that carries 75 B a cycle (75,000 baud) into a UART that holds 16 B, and
// a longest frame of 60 B.
static const LinkStream kStreams2[2] FSW_FLASH = {{0, 20, 1, 1, 0}, {0, 20, 1, 1, 0}};
static uint8_t tx2[120];
static const LinkConfig kConfig1 FSW_FLASH = {sv, kStreams2, states, kWritable, &ex, now_fn, tx2, 0xA5A55A5AUL,
                                              20, 60, 10, 20, 2, 3, 3, 0, false, 0, 0, 0, 0, 0, 0, 0, 0, 0xFF, 0, 0, 0, 0, 0, 0, 0};
static const LinkConfig kConfig2 FSW_FLASH = {sv, kStreams2, states, kWritable, &ex, now_fn, tx2, 0xA5A55A5AUL,
                                              20, 60, 10, 20, 2, 3, 3, 0, false, 0, 0, 0, 0, 0, 0, 0, 0, 0xFF, 120, 0, 0, 0, 0, 0, 0};
static_assert(link_stream_ok(0, 20, 1, 1, false, 20, 60) && link_config_ok(60, 20, 2, 2), "the tables are valid");

static uint32_t dropped_near_line_rate(const LinkConfig* cfg) {
    link_begin(link, cfg);
    native::console_model_uart(75000, 16);
    for (uint16_t i = 0; i < 300; ++i) {
        executor_run_cycle(ex);
        clock_ms += 10;
        for (uint8_t k = 0; k < 10; ++k) {  // loop() between cycles: the link polled every millisecond
            native::sim_advance_us(1000);
            link_poll(link);
        }
    }
    native::console_model_uart(0, 0);
    TEST_ASSERT_EQUAL_UINT32(0, native::console_overruns());
    return link.n.dropped;
}

static void test_second_frame_waits_behind_the_first(void) {
    const uint32_t one = dropped_near_line_rate(&kConfig1);
    TEST_ASSERT_TRUE(one >= 25);  // one frame's buffer: a sample after nearly every health frame
    out_len = 0;
    TEST_ASSERT_EQUAL_UINT32(0, dropped_near_line_rate(&kConfig2));
    collect();
    uint16_t samples = 0;
    for (uint8_t i = 0; i < n_frames; ++i) {
        TEST_ASSERT_TRUE(frames[i].len >= 6);
        if (i != 0) TEST_ASSERT_EQUAL_UINT8(static_cast<uint8_t>(frames[i - 1].body[1] + 1), frames[i].body[1]);
        if (frames[i].body[0] & kFrameSample) ++samples;
    }
    TEST_ASSERT_TRUE(n_frames >= 60);  // collect() keeps 64 frames
    TEST_ASSERT_TRUE(samples > 40);
}

// ---- uplink --------------------------------------------------------------------

static void test_writable_element_is_written(void) {
    run(1);
    const uint8_t args[] = {4, 0, 0x34, 0x12};  // level = 0x1234
    send_cmd(kOpSet, 1, args, 4);
    run(1);
    TEST_ASSERT_EQUAL(kAckOk, ack_status(1));
    TEST_ASSERT_EQUAL_INT16(0x1234, load<int16_t>(sv + 10));
    const uint8_t b[] = {3, 0, 7};  // bool stored as 1
    send_cmd(kOpSet, 2, b, 3);
    run(1);
    TEST_ASSERT_EQUAL(kAckOk, ack_status(2));
    TEST_ASSERT_EQUAL_UINT8(1, sv[9]);
    TEST_ASSERT_EQUAL_UINT16(2, link.n.rx_ok);
}

static void test_every_other_element_is_refused(void) {
    run(1);
    uint16_t seq = 1;
    for (uint16_t idx = 0; idx < 300; ++idx) {
        if (idx == 3 || idx == 4 || idx == 5) continue;
        const uint8_t args[] = {static_cast<uint8_t>(idx), static_cast<uint8_t>(idx >> 8), 1, 2, 3, 4};
        memset(sv, 0, sizeof sv);
        send_cmd(kOpSet, seq, args, 6);
        run(1);
        TEST_ASSERT_EQUAL(kAckNotWritable, ack_status(seq));
        for (uint8_t i = 0; i < sizeof sv; ++i) {
            if (i != 8) TEST_ASSERT_EQUAL_UINT8(0, sv[i]);  // 8: the telemetry task's mode
        }
        ++seq;
    }
    TEST_ASSERT_EQUAL_UINT16(0, link.n.rx_ok);
}

static void test_wrong_length_is_refused(void) {
    run(1);
    const uint8_t args[] = {5, 0, 1, 2, 3};  // gain is F64: 8 bytes, not 3
    send_cmd(kOpSet, 1, args, 5);
    run(1);
    TEST_ASSERT_EQUAL(kAckBadLength, ack_status(1));
    TEST_ASSERT_EQUAL_UINT16(1, link.n.rx_malformed);
}

static void test_replayed_frame_is_refused(void) {
    run(1);
    const uint8_t args[] = {4, 0, 1, 0};
    send_cmd(kOpSet, 5, args, 4);
    run(1);
    TEST_ASSERT_EQUAL(kAckOk, ack_status(5));
    sv[10] = 0;
    send_cmd(kOpSet, 5, args, 4);  // the same frame again
    run(1);
    TEST_ASSERT_EQUAL(kAckReplay, ack_status(5));
    send_cmd(kOpSet, 3, args, 4);  // an older one
    run(1);
    TEST_ASSERT_EQUAL(kAckReplay, ack_status(3));
    TEST_ASSERT_EQUAL_UINT8(0, sv[10]);
    TEST_ASSERT_EQUAL_UINT16(2, link.n.rx_replayed);
}

static void test_mode_commands(void) {
    run(1);
    const uint8_t safe[] = {1, kModeSafed};
    send_cmd(kOpMode, 1, safe, 2);
    run(1);
    TEST_ASSERT_EQUAL(kAckOk, ack_status(1));
    TEST_ASSERT_EQUAL_UINT8(kModeSafed, sv[8]);  // the telemetry task's mode element
    const uint8_t lock[] = {0, kModeDisabled};  // the uplink task itself
    send_cmd(kOpMode, 2, lock, 2);
    run(1);
    TEST_ASSERT_EQUAL(kAckLocked, ack_status(2));
    const uint8_t bad_task[] = {2, kModeEnabled};
    send_cmd(kOpMode, 3, bad_task, 2);
    run(1);
    TEST_ASSERT_EQUAL(kAckBadTask, ack_status(3));
    const uint8_t bad_mode[] = {1, 3};
    send_cmd(kOpMode, 4, bad_mode, 2);
    run(1);
    TEST_ASSERT_EQUAL(kAckBadMode, ack_status(4));
    TEST_ASSERT_EQUAL_UINT8(kModeSafed, sv[8]);
    TEST_ASSERT_EQUAL_UINT8(kModeEnabled, executor_task_mode(ex, 0));
}

// A writable table that lists the telemetry task's mode element (a
// hand-written one; the generator never emits it): SET is LOCKED, the mode
// changes only by MODE.
static const LinkWritable kWritableMode[2] FSW_FLASH = {{2, 8, kU8}, {4, 10, kI16}};
static const LinkConfig kConfigMode FSW_FLASH = {sv, kStreams, states, kWritableMode, &ex, now_fn, tx, 0xA5A55A5AUL,
                                                 20, 96, 10, 20, 2, 2, 3, 0, false, 0, 0, 0, 0, 0, 0, 0, 0, 0xFF, 0, 0, 0, 0, 0, 0, 0};

// Task 1 stands for the outputs task that ends the pyro pulses: it runs
// always, as the uplink task does (docs/safety.md).
static const LinkConfig kConfigPyro FSW_FLASH = {sv, kStreams, states, kWritable, &ex, now_fn, tx, 0xA5A55A5AUL,
                                                 20, 96, 10, 20, 2, 3, 3, 0, false, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0};

static void test_the_pyro_task_mode_is_locked(void) {
    link_begin(link, &kConfigPyro);
    run(1);
    const uint8_t off[] = {1, kModeDisabled};
    send_cmd(kOpMode, 1, off, 2);
    run(1);
    TEST_ASSERT_EQUAL(kAckLocked, ack_status(1));
    const uint8_t safe[] = {1, kModeSafed};
    send_cmd(kOpMode, 2, safe, 2);
    run(1);
    TEST_ASSERT_EQUAL(kAckLocked, ack_status(2));
    const uint8_t on[] = {1, kModeEnabled};
    send_cmd(kOpMode, 3, on, 2);
    run(1);
    TEST_ASSERT_EQUAL(kAckOk, ack_status(3));
    TEST_ASSERT_EQUAL_UINT8(kModeEnabled, executor_task_mode(ex, 1));
}

static void test_set_of_a_mode_element_is_locked(void) {
    link_begin(link, &kConfigMode);
    run(1);
    const uint8_t off[] = {2, 0, kModeDisabled};
    send_cmd(kOpSet, 1, off, 3);
    run(1);
    TEST_ASSERT_EQUAL(kAckLocked, ack_status(1));
    TEST_ASSERT_EQUAL_UINT8(kModeEnabled, sv[8]);
    const uint8_t level[] = {4, 0, 0x34, 0x12};  // its neighbour still writable
    send_cmd(kOpSet, 2, level, 4);
    run(1);
    TEST_ASSERT_EQUAL(kAckOk, ack_status(2));
    TEST_ASSERT_EQUAL_INT16(0x1234, load<int16_t>(sv + 10));
    TEST_ASSERT_EQUAL_UINT8(kModeEnabled, sv[8]);
    TEST_ASSERT_EQUAL_UINT16(1, link.n.rx_refused);
}

// The same link with a receive buffer of its own (fsw_app.h kAppRxBuffer:
// a ground that pipelines its commands), the ring emptied into it each run;
// kConfig reads a command where the console's ring holds it (kAppRxRing).
static uint8_t rx_buf[FSW_LINK_RX_CAP];
static const LinkConfig kConfigBuf FSW_FLASH = {sv, kStreams, states, kWritable, &ex, now_fn, tx, 0xA5A55A5AUL,
                                                20, 96, 10, 20, 2, 3, 3, 0, false, 0, 0, 0, 0, 0, 0, 0, 0, 0xFF, 0, 0, 0, 0,
                                                rx_buf, 0, 0};

static void corrupt_truncated_oversized_frames_are_counted_not_acted_on(void) {
    run(1);
    // CRC error: a valid SET with one bit flipped
    uint8_t raw[64];
    CobsEncoder e;
    cobs_begin(e, raw);
    cobs_put(e, kOpSet);
    cobs_put_u16(e, 1);
    const uint8_t args[] = {4, 0, 9, 9};
    cobs_put_bytes(e, args, 4);
    uint16_t len = cobs_end(e);
    raw[2] ^= 0x10;  // the sequence number's low byte
    native::console_feed(raw, len);
    // truncated: the first half of a frame, then a delimiter
    send_cmd(kOpSet, 2, args, 4);  // a good frame between the bad ones
    uint8_t cut[] = {0x05, 0x04, 0x02, 0x00};
    native::console_feed(cut, 4);
    // oversized: 40 non-zero bytes then a delimiter
    uint8_t big[41];
    memset(big, 0x11, 40);
    big[40] = 0;
    native::console_feed(big, 41);
    // garbage: zeros and noise
    const uint8_t noise[] = {0, 0, 0x80, 0xFF, 0x01, 0};
    native::console_feed(noise, sizeof noise);
    run(3);
    TEST_ASSERT_EQUAL_UINT16(1, link.n.rx_crc);
    TEST_ASSERT_EQUAL_UINT16(1, link.n.rx_oversized);
    TEST_ASSERT_TRUE(link.n.rx_malformed >= 2);
    TEST_ASSERT_EQUAL_UINT16(1, link.n.rx_ok);  // only the well-formed SET of seq 2
    TEST_ASSERT_EQUAL_INT16(0x0909, load<int16_t>(sv + 10));
}

static void test_corrupt_truncated_oversized_frames_are_counted_not_acted_on(void) {
    corrupt_truncated_oversized_frames_are_counted_not_acted_on();
    TEST_ASSERT_EQUAL_INT16(-1, pal::console_peek(0));  // every byte taken off the ring
}

static void test_a_link_with_a_receive_buffer_counts_them_alike(void) {
    link_begin(link, &kConfigBuf);
    corrupt_truncated_oversized_frames_are_counted_not_acted_on();
    TEST_ASSERT_EQUAL_INT16(-1, pal::console_peek(0));
}

// The uplink decodes a frame's COBS and checks its CRC in one pass of its
// own (fsw_link.cpp decode_frame): each frame is classified as the
// library's cobs_decode and crc16 (the reference) classify it, malformed (a
// block past its end, fewer than 5 bytes), a CRC error, or handled (its op
// and sequence number acknowledged, one of the counters of a handled
// command moved): random frames of 1..FSW_LINK_RX_CAP bytes, PINGs and an
// unknown opcode with zeros in their sequence numbers and arguments, as
// they were encoded, with a byte changed, cut short, or noise; read where
// the ring holds them and with the receive buffer alike.
static void frames_are_classified_as_the_reference_does(const LinkConfig* cfg) {
    link_begin(link, cfg);
    run(1);
    uint32_t x = 4242;
    uint16_t seq = 1;
    uint16_t handled = 0, malformed = 0, crc_errors = 0;
    for (uint16_t trial = 0; trial < 4000; ++trial) {
        uint8_t raw[64];
        uint16_t len;
        x = x * 1103515245u + 12345u;
        const uint8_t kind = static_cast<uint8_t>(x >> 28);  // 0..15
        if (kind < 3) {  // noise: non-zero bytes
            len = static_cast<uint16_t>(1u + (x >> 8) % FSW_LINK_RX_CAP);
            for (uint16_t i = 0; i < len; ++i) {
                x = x * 1103515245u + 12345u;
                raw[i] = static_cast<uint8_t>(1u + (x >> 16) % 255u);
            }
        } else {
            CobsEncoder e;
            cobs_begin(e, raw);
            cobs_put(e, (x >> 8 & 1) != 0 ? kOpPing : 0x30);
            cobs_put_u16(e, (x >> 9 & 7) != 0 ? seq++ : static_cast<uint16_t>(x >> 12 & 0x0F00));  // 0: a replay
            const uint8_t n_args = static_cast<uint8_t>(x >> 16 & 3) == 0 ? static_cast<uint8_t>(x >> 18 & 15) : 0;
            for (uint8_t k = 0; k < n_args; ++k) {
                x = x * 1103515245u + 12345u;
                cobs_put(e, static_cast<uint8_t>(x >> 24) < 64 ? 0 : static_cast<uint8_t>(x >> 16));
            }
            len = static_cast<uint16_t>(cobs_end(e) - 1u);  // without its delimiter
            x = x * 1103515245u + 12345u;
            if (kind < 7) {  // a byte changed (never to zero: that would end the frame)
                const uint16_t i = static_cast<uint16_t>((x >> 8) % len);
                raw[i] = static_cast<uint8_t>(raw[i] ^ (1u + (x >> 16) % 255u));
                if (raw[i] == 0) raw[i] = 1;
            } else if (kind < 10) {  // cut short
                len = static_cast<uint16_t>(1u + (x >> 8) % len);
            }
        }
        uint8_t ref[64];
        memcpy(ref, raw, len);
        const int16_t d = cobs_decode(ref, len);
        const bool bad = d < 5, crc_bad = !bad && crc16(ref, static_cast<uint16_t>(d)) != 0;
        const LinkCounters n0 = link.n;
        raw[len] = 0;
        native::console_feed(raw, static_cast<uint16_t>(len + 1u));
        run(2);
        out_len = 0;
        const LinkCounters& n = link.n;
        TEST_ASSERT_EQUAL_UINT16(n0.rx_oversized, n.rx_oversized);
        TEST_ASSERT_EQUAL_UINT16(n0.rx_crc + (crc_bad ? 1 : 0), n.rx_crc);
        const uint16_t moved = static_cast<uint16_t>(n.rx_ok + n.rx_malformed + n.rx_replayed + n.rx_refused -
                                                     (n0.rx_ok + n0.rx_malformed + n0.rx_replayed + n0.rx_refused));
        if (bad) {
            ++malformed;
            TEST_ASSERT_EQUAL_UINT16(n0.rx_malformed + 1, n.rx_malformed);
            TEST_ASSERT_EQUAL_UINT16(1, moved);
        } else if (crc_bad) {
            ++crc_errors;
            TEST_ASSERT_EQUAL_UINT16(0, moved);
        } else {
            ++handled;
            TEST_ASSERT_EQUAL_UINT16(1, moved);
            TEST_ASSERT_EQUAL_HEX8(ref[0], link.ack_op);
            TEST_ASSERT_EQUAL_HEX16(load<uint16_t>(ref + 1), link.ack_seq);
        }
    }
    TEST_ASSERT_TRUE(handled > 1000 && malformed > 500 && crc_errors > 500);
    TEST_ASSERT_EQUAL_INT16(-1, pal::console_peek(0));  // every byte taken off the ring
}

static void test_frames_are_classified_as_the_reference_does_in_the_ring(void) {
    frames_are_classified_as_the_reference_does(&kConfig);
}

static void test_frames_are_classified_as_the_reference_does_in_the_buffer(void) {
    frames_are_classified_as_the_reference_does(&kConfigBuf);
}

// Commands whose bytes come a few at a time, over several runs of the
// uplink task, and commands that lie across the end of the ring (256 bytes
// here: bytes fed while others wait go round it), read where the ring holds
// them and with the receive buffer alike: each answered, in order, and the
// ring empty after.
static void commands_in_pieces_and_round_the_ring(const LinkConfig* cfg) {
    link_begin(link, cfg);
    run(1);
    collect();
    uint16_t seq = 1;
    for (uint8_t round = 0; round < 6; ++round) {
        // a SET of `level` (7 + 2 encoded bytes, two delimiters) in three pieces a run apart
        uint8_t raw[32];
        CobsEncoder e;
        cobs_begin(e, raw);
        cobs_put(e, kOpSet);
        cobs_put_u16(e, seq);
        const uint8_t level[] = {4, 0, static_cast<uint8_t>(round + 1), 0x12};
        cobs_put_bytes(e, level, 4);
        const uint16_t len = cobs_end(e);
        native::console_feed(raw, 3);
        run(1);
        native::console_feed(raw + 3, 4);
        run(1);
        native::console_feed(raw + 7, static_cast<uint16_t>(len - 7));
        run(1);
        TEST_ASSERT_EQUAL(kAckOk, ack_status(seq));
        TEST_ASSERT_EQUAL_INT16(0x1200 | (round + 1), load<int16_t>(sv + 10));
        ++seq;
        // then 20 PINGs at once (7 bytes each), and 20 more once a run took the first 64 bytes: the
        // ring (emptied, it starts from its front) holds the second 20 from byte 140 on, round its
        // end at 256
        for (uint8_t k = 0; k < 20; ++k) send_cmd(kOpPing, static_cast<uint16_t>(seq + k), 0, 0);
        run(1);
        for (uint8_t k = 20; k < 40; ++k) send_cmd(kOpPing, static_cast<uint16_t>(seq + k), 0, 0);
        run(40);
        collect();
        uint8_t acks = 0;
        for (uint8_t i = 0; i < n_frames; ++i) {
            const Frame& f = frames[i];
            if (f.len == 12 && f.body[0] == kFrameAck && f.body[9] == kAckOk &&
                (f.body[6] | (f.body[7] << 8)) == seq + acks) {
                ++acks;
            }
        }
        TEST_ASSERT_EQUAL_UINT8(40, acks);
        seq = static_cast<uint16_t>(seq + 40);
    }
    TEST_ASSERT_EQUAL_UINT16(6 * 41, link.n.rx_ok);
    TEST_ASSERT_EQUAL_UINT16(0, link.n.rx_crc + link.n.rx_malformed + link.n.rx_oversized);
    TEST_ASSERT_EQUAL_INT16(-1, pal::console_peek(0));
}

static void test_commands_in_pieces_and_round_the_ring_are_read_in_the_ring(void) {
    commands_in_pieces_and_round_the_ring(&kConfig);
}

static void test_commands_in_pieces_and_round_the_ring_are_read_into_the_buffer(void) {
    commands_in_pieces_and_round_the_ring(&kConfigBuf);
}

// Every third health frame brings a hello (hello_every 3): the two long
// frames never go out in the same cycle or the gap after it, so no step
// composes both.
static void test_hello_and_health_never_share_a_cycle(void) {
    uint8_t hellos = 0, healths = 0, both = 0;
    for (uint8_t k = 0; k < 100; ++k) {
        run(1);
        collect();
        uint8_t he = 0, hl = 0;
        for (uint8_t i = 0; i < n_frames; ++i) {
            if (frames[i].len < 0) continue;
            if (frames[i].body[0] == kFrameHello) ++he;
            if (frames[i].body[0] == kFrameHealth) ++hl;
        }
        if (he != 0 && hl != 0) ++both;
        hellos = static_cast<uint8_t>(hellos + he);
        healths = static_cast<uint8_t>(healths + hl);
    }
    TEST_ASSERT_EQUAL_UINT8(0, both);
    TEST_ASSERT_EQUAL_UINT8(10, healths);
    TEST_ASSERT_EQUAL_UINT8(1 + 3, hellos);  // at boot, then with every third health frame
}

static void test_ping_hello_snapshot(void) {
    run(1);
    collect();
    send_cmd(kOpPing, 1, 0, 0);
    send_cmd(kOpHello, 2, 0, 0);
    send_cmd(kOpSnapshot, 3, 0, 0);
    run(2);
    collect();
    uint8_t acks = 0, hellos = 0;
    uint16_t covered = 0;
    for (uint8_t i = 0; i < n_frames; ++i) {
        if (frames[i].len < 0) continue;
        if (frames[i].body[0] == kFrameAck) ++acks;
        if (frames[i].body[0] == kFrameHello) ++hellos;
        if (frames[i].body[0] == kFrameSnapshot) {
            TEST_ASSERT_EQUAL_UINT16(covered, load<uint16_t>(frames[i].body + 6));
            covered = static_cast<uint16_t>(covered + frames[i].len - 8);
        }
    }
    TEST_ASSERT_EQUAL_UINT8(3, acks);
    TEST_ASSERT_EQUAL_UINT8(1, hellos);
    TEST_ASSERT_EQUAL_UINT16(20, covered);
}

// The tables are checked when they are compiled: the checks the generator
// emits as static_asserts, at both sides of each boundary.
static_assert(link_stream_ok(0, 8, 1, 2, true, 20, 96) && link_stream_ok(8, 12, 4, 1, false, 20, 96),
              "this suite's streams");
static_assert(link_writable_ok(12, kF64, 20) && link_config_ok(96, 20, 2, 2), "this suite's tables");
static_assert(!link_stream_ok(16, 8, 1, 1, false, 20, 96), "a region past the state vector is refused");

static void test_bad_tables_do_not_pass_the_compile_time_checks(void) {
    // a stream: the region ends at the state vector's end / one byte past it
    TEST_ASSERT_TRUE(link_stream_ok(12, 8, 1, 1, false, 20, 96));
    TEST_ASSERT_FALSE(link_stream_ok(13, 8, 1, 1, false, 20, 96));
    TEST_ASSERT_FALSE(link_stream_ok(0xFFFF, 2, 1, 1, false, 0xFFFF, 96));  // no 16-bit wrap
    // its longest frame: 6 + 8 x 10 + 2 bytes encode into 90, not 89
    TEST_ASSERT_TRUE(link_stream_ok(0, 10, 1, 8, true, 80, 90));
    TEST_ASSERT_FALSE(link_stream_ok(0, 10, 1, 8, true, 80, 89));
    TEST_ASSERT_FALSE(link_stream_ok(0, 8, 0, 1, false, 20, 96));   // every 0
    TEST_ASSERT_FALSE(link_stream_ok(0, 8, 1, 0, false, 20, 96));   // batch 0
    TEST_ASSERT_FALSE(link_stream_ok(0, 8, 1, 2, false, 20, 96));   // a batch without its store
    // a writable element: an F64 at the end / one byte past it; an unknown type
    TEST_ASSERT_TRUE(link_writable_ok(12, kF64, 20));
    TEST_ASSERT_FALSE(link_writable_ok(13, kF64, 20));
    TEST_ASSERT_FALSE(link_writable_ok(0, 11, 20));
    // control frames: a health frame of 2 tasks is 6 + 34 + 12 + 2 bytes, 56 encoded
    TEST_ASSERT_TRUE(link_config_ok(56, 20, 2, 2));
    TEST_ASSERT_FALSE(link_config_ok(55, 20, 2, 2));
    TEST_ASSERT_FALSE(link_config_ok(56, 46, 2, 2));  // a snapshot chunk of 46 needs 58
    TEST_ASSERT_FALSE(link_config_ok(96, 0, 2, 2));   // chunks of no byte
    TEST_ASSERT_FALSE(link_config_ok(96, 20, 129, 2));
    TEST_ASSERT_EQUAL_UINT32(cobs_max_encoded(90), link_encoded_max(88));
}

static void run_all(void) {
    UNITY_BEGIN();
    RUN_TEST(test_crc_is_ccitt_false);
    RUN_TEST(test_cobs_roundtrip_and_limits);
    RUN_TEST(test_framer_matches_the_incremental_encoder);
    RUN_TEST(test_boot_hello_carries_the_schema);
    RUN_TEST(test_the_link_starts_with_a_delimiter);
    RUN_TEST(test_samples_batch_with_time_and_sequence);
    RUN_TEST(test_health_reports_tasks_and_counters);
    RUN_TEST(test_full_uart_drops_and_counts_never_blocks);
    RUN_TEST(test_second_frame_waits_behind_the_first);
    RUN_TEST(test_writable_element_is_written);
    RUN_TEST(test_every_other_element_is_refused);
    RUN_TEST(test_wrong_length_is_refused);
    RUN_TEST(test_replayed_frame_is_refused);
    RUN_TEST(test_mode_commands);
    RUN_TEST(test_set_of_a_mode_element_is_locked);
    RUN_TEST(test_the_pyro_task_mode_is_locked);
    RUN_TEST(test_corrupt_truncated_oversized_frames_are_counted_not_acted_on);
    RUN_TEST(test_a_link_with_a_receive_buffer_counts_them_alike);
    RUN_TEST(test_frames_are_classified_as_the_reference_does_in_the_ring);
    RUN_TEST(test_frames_are_classified_as_the_reference_does_in_the_buffer);
    RUN_TEST(test_commands_in_pieces_and_round_the_ring_are_read_in_the_ring);
    RUN_TEST(test_commands_in_pieces_and_round_the_ring_are_read_into_the_buffer);
    RUN_TEST(test_hello_and_health_never_share_a_cycle);
    RUN_TEST(test_ping_hello_snapshot);
    RUN_TEST(test_bad_tables_do_not_pass_the_compile_time_checks);
}

FSW_TEST_MAIN(run_all)
