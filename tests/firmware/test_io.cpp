// Scenario: analog and digital I/O tables as executor task steps: ADC counts
// to volts to engineering units, PWM duty from volts, digital mirrors, pin
// modes, table validation. Pins are simulated on the host.
#include "test_support.h"

#if FSW_PLATFORM_NATIVE
#include "psl_native.h"
#endif

using namespace fsw;

void setUp(void) {
#if FSW_PLATFORM_NATIVE
    native::sim_reset();
#endif
}
void tearDown(void) {}

// count * gain + offset, the product rounded to R before the sum; the
// gains below are those the generator computes (iotables.analog_gain) for
// rocket.aio on an Uno: 6250 and 8 per volt, 5 V over 1023 counts.
static void test_analog_conversion_formula(void) {
    ASSERT_REAL_SAME(Real(5), analog_value(1023, Real(5) / Real(1023), 0));
    ASSERT_REAL_SAME(Real(0), analog_value(0, Real(5) / Real(1023), 0));
    ASSERT_REAL_SAME(Real(-3), analog_value(0, Real(2), Real(-3)));
    const Real gain = Real(250);
    ASSERT_REAL_SAME(Real(512) * gain + Real(-125), analog_value(512, gain, Real(-125)));
    ASSERT_REAL_SAME(Real(255625), analog_value(1023, gain, Real(-125)));  // 1023 * 250 - 125
    volatile Real big = Real(65535);  // the widest count
    ASSERT_REAL_SAME(big * Real(0.5), analog_value(65535, Real(0.5), 0));
}

// Every count converts exactly, as the cast does (on AVR real_from_count
// puts the float's bits together in assembly).
static void test_every_count_converts_as_the_cast(void) {
    for (uint32_t n = 0; n <= 0xFFFFu; ++n) {
        volatile uint16_t count = static_cast<uint16_t>(n);  // no constant folding
        const Real got = real_from_count(count);
        const Real want = static_cast<Real>(static_cast<uint16_t>(count));
        if (memcmp(&got, &want, sizeof got) != 0) {
            TEST_ASSERT_EQUAL_UINT32(n, 0x10000UL);  // reports the first count that differs
        }
    }
}

// A generated inputs task converts a count through its input's memo: the
// value is analog_value's, bit for bit, whatever came before (the same
// count again, another, the first run, the count 0xFFFF), and a count that
// did not change is not converted again.
static void test_the_memo_gives_analog_values_bit_for_bit(void) {
    static AnalogMemo m;  // zero, as a generated task's before its first run
    static const uint16_t counts[] = {0, 0, 1, 1023, 1023, 0xFFFF, 0xFFFF, 0, 512, 511, 512, 0xFFFE, 0xFFFF, 7};
    const Real gains[] = {Real(30.54741), Real(-0.5), Real(5) / Real(1023)};
    const Real offsets[] = {Real(76875), Real(0), Real(-20)};
    for (uint8_t g = 0; g < 3; ++g) {
        memset(&m, 0, sizeof m);
        for (uint8_t i = 0; i < sizeof counts / sizeof counts[0]; ++i) {
            const Real want = analog_value(counts[i], gains[g], offsets[g]);
            const Real got = analog_value_memo(m, counts[i], gains[g], offsets[g]);
            ASSERT_REAL_SAME(want, got);
        }
    }
    // a literal +0 offset: -0 (a count of 0 times a negative gain) turns +0, as without the memo
    memset(&m, 0, sizeof m);
    ASSERT_REAL_SAME(analog_value(0, Real(-2), 0), analog_value_memo(m, 0, Real(-2), 0));
    // the same count again is the value kept, not converted again
    memset(&m, 0, sizeof m);
    (void)analog_value_memo(m, 100, Real(2), Real(1));
    const Real planted = Real(12345);
    m.value = planted;
    ASSERT_REAL_SAME(planted, analog_value_memo(m, 100, Real(2), Real(1)));
    ASSERT_REAL_SAME(Real(203), analog_value_memo(m, 101, Real(2), Real(1)));  // another count: converted
}

// Three inputs' rows (gain, offset, element offset; the second's offset +0)
// and the counts of seven runs, for the two inputs loops below.
static const AnalogInput kRows[3] FSW_FLASH = {
    {Real(30.54741), Real(76875), 2}, {Real(-0.5), Real(0), 10}, {Real(5) / Real(1023), Real(-20), 6}};
static const uint16_t kCounts[][3] = {{0, 0, 0}, {0, 0, 0}, {1, 0, 1023}, {1023, 7, 1023}, {0xFFFF, 0xFFFF, 1},
                                      {0xFFFF, 0xFFFF, 1}, {512, 0, 511}};
static const uint8_t kRuns = sizeof kCounts / sizeof kCounts[0];

// A generated inputs task with two analog inputs or more converts them in
// one loop over a flash table (io_analog_inputs): each element takes the
// value a call of its own with its constants inline gives, bit for bit
// (the +0 offset's -0 included), run after run, through the same memo.
static void test_the_inputs_loop_gives_what_each_call_gives(void) {
    static AnalogMemo memo[3], each[3];
    static volatile uint16_t raw[3];
    uint8_t sv[16], want[16];
    memset(sv, 0xA5, sizeof sv);
    memset(want, 0xA5, sizeof want);
    for (uint8_t r = 0; r < kRuns; ++r) {
        for (uint8_t i = 0; i < 3; ++i) raw[i] = kCounts[r][i];
        io_analog_inputs(kRows, 3, memo, raw, sv);
        write_F32(want + 2, analog_value_memo(each[0], kCounts[r][0], Real(30.54741), Real(76875)));
        write_F32(want + 10, analog_value_memo(each[1], kCounts[r][1], Real(-0.5), 0));
        write_F32(want + 6, analog_value_memo(each[2], kCounts[r][2], Real(5) / Real(1023), Real(-20)));
        TEST_ASSERT_EQUAL_MEMORY(want, sv, sizeof sv);
    }
    // a count that did not change is the value kept, not converted again
    memo[1].value = Real(12345);
    io_analog_inputs(kRows, 3, memo, raw, sv);
    TEST_ASSERT_EQUAL_MEMORY(want + 2, sv + 2, 4);
    TEST_ASSERT_TRUE(read_F32(sv + 10) == Real(12345));
}

// An application whose input elements have no other writer keeps a key per
// input, not its value (io_analog_inputs_kept, analog_count_new): each
// element holds, run after run, the bytes the memo's loop writes, and one
// whose count did not change is neither converted nor written (the count
// 0xFFFF, key 0, is new at every run).
static void test_the_kept_inputs_loop_writes_what_the_memo_gives(void) {
    static AnalogMemo memo[3];
    static uint16_t keys[3];  // zero, as a generated task's before its first run
    static volatile uint16_t raw[3];
    uint8_t sv[16], want[16];
    memset(sv, 0xA5, sizeof sv);
    memset(want, 0xA5, sizeof want);
    for (uint8_t r = 0; r < kRuns; ++r) {
        for (uint8_t i = 0; i < 3; ++i) raw[i] = kCounts[r][i];
        io_analog_inputs_kept(kRows, 3, keys, raw, sv);
        io_analog_inputs(kRows, 3, memo, raw, want);
        TEST_ASSERT_EQUAL_MEMORY(want, sv, sizeof sv);
    }
    // the same counts again: nothing written (a byte planted in an element stays) ...
    write_F32(sv + 6, Real(12345));
    io_analog_inputs_kept(kRows, 3, keys, raw, sv);
    TEST_ASSERT_TRUE(read_F32(sv + 6) == Real(12345));
    // ... but a new count is converted and written
    raw[2] = 510;
    io_analog_inputs_kept(kRows, 3, keys, raw, sv);
    write_F32(want + 6, analog_value(510, Real(5) / Real(1023), Real(-20)));
    TEST_ASSERT_EQUAL_MEMORY(want + 6, sv + 6, 4);
    // the count 0xFFFF is new at every run
    uint16_t key = 0;
    TEST_ASSERT_TRUE(analog_count_new(key, 0xFFFF));
    TEST_ASSERT_TRUE(analog_count_new(key, 0xFFFF));
    TEST_ASSERT_TRUE(analog_count_new(key, 3));
    TEST_ASSERT_FALSE(analog_count_new(key, 3));
}

#if FSW_REAL_IS_FLOAT
// Bit patterns of analog_value for rocket.aio's two calibrations, as the
// host computes them (fswkit.autocode.iotables.analog_value; the host test
// tests/autocode/check/test_calibration_agreement.py checks this table
// against it): native and AVR builds agree bit for bit.
struct CalCase {
    uint16_t count;
    uint32_t gain, offset, value;
};
static const CalCase kCalCases[] FSW_FLASH = {
#include "calibration_cases.inc"
};

static void test_analog_conversion_matches_the_host_bit_for_bit(void) {
    for (uint16_t i = 0; i < sizeof kCalCases / sizeof kCalCases[0]; ++i) {
        CalCase c;
        flash_read(&c, &kCalCases[i], sizeof c);
        float gain, offset;
        memcpy(&gain, &c.gain, 4);
        memcpy(&offset, &c.offset, 4);
        const float v = analog_value(c.count, gain, offset);
        uint32_t bits;
        memcpy(&bits, &v, 4);
        TEST_ASSERT_EQUAL_HEX32(c.value, bits);
    }
}
#endif

static void test_pwm_duty_from_volts(void) {
    TEST_ASSERT_EQUAL_UINT8(0, pwm_duty_from_volts(0, 5));
    TEST_ASSERT_EQUAL_UINT8(255, pwm_duty_from_volts(5, 5));
    TEST_ASSERT_EQUAL_UINT8(128, pwm_duty_from_volts(Real(2.5), 5));  // 127.5 rounds up
    TEST_ASSERT_EQUAL_UINT8(255, pwm_duty_from_volts(12, 5));
    TEST_ASSERT_EQUAL_UINT8(0, pwm_duty_from_volts(-1, 5));
    volatile Real z = 0;
    TEST_ASSERT_EQUAL_UINT8(0, pwm_duty_from_volts(z / z, 5));
}

#if FSW_PLATFORM_NATIVE
// sv: F32 pressure @0, F64 heater volts @4, bool limit @12, bool valve @13.
static uint8_t sv[14];
static const AnalogChannel kAnalog[2] FSW_FLASH = {
    {Real(250), Real(-125), 0, 14, kIoIn, kF32},  // 250 per count
    {Real(1), Real(0), 4, 9, kIoOut, kF64},
};
static const AnalogTable kAnalogTable FSW_FLASH = {kAnalog, sv, Real(5), 2, 10, false, 0};
static const DigitalChannel kDigital[2] FSW_FLASH = {{12, 2, kIoInPullup}, {13, 4, kIoOut}};
static const DigitalTable kDigitalTable FSW_FLASH = {kDigital, sv, 2, true};

static void test_analog_task_reads_and_writes(void) {
    TEST_ASSERT_EQUAL(kOk, io_analog_begin(&kAnalogTable));
    TEST_ASSERT_EQUAL_UINT8(pal::kOutput, native::sim_pin_mode(9));
    TEST_ASSERT_EQUAL_UINT8(0xFF, native::sim_pin_mode(14));  // analog inputs untouched
    native::sim_set_analog(14, 1023);
    write_F64(sv + 4, Real(2.5));
    TEST_ASSERT_EQUAL(kOk, io_analog_task(const_cast<AnalogTable*>(&kAnalogTable)));
    ASSERT_REAL_SAME(Real(255625), read_F32(sv + 0));  // 1023 * 250 - 125
    TEST_ASSERT_EQUAL_UINT8(128, native::sim_pwm(9));
    native::sim_set_analog(14, 0);
    TEST_ASSERT_EQUAL(kOk, io_analog_task(const_cast<AnalogTable*>(&kAnalogTable)));
    ASSERT_REAL_SAME(Real(-125), read_F32(sv + 0));
}

// An all-F32 table through the task that links no binary64 code: the same
// values as the general task; an F64 row is refused, not written as F32.
static const AnalogChannel kAnalogF32[2] FSW_FLASH = {
    {Real(250), Real(-125), 0, 14, kIoIn, kF32},
    {Real(8), Real(-20), 4, 15, kIoIn, kF32},
};
static const AnalogTable kAnalogF32Table FSW_FLASH = {kAnalogF32, sv, Real(5), 2, 10, false, 0};

static void test_analog_f32_task_matches_the_general_task(void) {
    TEST_ASSERT_EQUAL(kOk, io_analog_begin(&kAnalogF32Table));
    for (uint16_t raw = 0; raw <= 1023; raw += 31) {
        native::sim_set_analog(14, raw);
        native::sim_set_analog(15, static_cast<uint16_t>(1023 - raw));
        TEST_ASSERT_EQUAL(kOk, io_analog_task(const_cast<AnalogTable*>(&kAnalogF32Table)));
        const Real a = read_F32(sv + 0), b = read_F32(sv + 4);
        write_F32(sv + 0, Real(-1));
        write_F32(sv + 4, Real(-1));
        TEST_ASSERT_EQUAL(kOk, io_analog_task_f32(const_cast<AnalogTable*>(&kAnalogF32Table)));
        ASSERT_REAL_SAME(a, read_F32(sv + 0));
        ASSERT_REAL_SAME(b, read_F32(sv + 4));
        uint8_t expect[4];
        write_F32(expect, analog_value(raw, 250, -125));  // rounded to binary32
        ASSERT_REAL_SAME(read_F32(expect), a);
    }
    uint8_t before[sizeof sv];
    memcpy(before, sv, sizeof sv);
    TEST_ASSERT_EQUAL(kErrConfig, io_analog_task_f32(const_cast<AnalogTable*>(&kAnalogTable)));
    TEST_ASSERT_EQUAL_MEMORY(before + 4, sv + 4, 8);  // the F64 row was not touched
}

// An input-only F32 table through the task that links no PWM output: the
// same values as the general task; a table with an output row is refused.
static void test_analog_in_task_matches_the_general_task(void) {
    native::sim_set_analog(14, 700);
    native::sim_set_analog(15, 300);
    TEST_ASSERT_EQUAL(kOk, io_analog_task(const_cast<AnalogTable*>(&kAnalogF32Table)));
    const Real a = read_F32(sv + 0), b = read_F32(sv + 4);
    write_F32(sv + 0, Real(-1));
    write_F32(sv + 4, Real(-1));
    TEST_ASSERT_EQUAL(kOk, io_analog_in_task_f32(const_cast<AnalogTable*>(&kAnalogF32Table)));
    ASSERT_REAL_SAME(a, read_F32(sv + 0));
    ASSERT_REAL_SAME(b, read_F32(sv + 4));
    static const AnalogChannel kOut[1] FSW_FLASH = {{Real(1), Real(0), 0, 9, kIoOut, kF32}};
    static const AnalogTable kOutTable FSW_FLASH = {kOut, sv, Real(5), 1, 10, false, 0};
    native::sim_set_analog(9, 0);
    TEST_ASSERT_EQUAL(kErrConfig, io_analog_in_task_f32(const_cast<AnalogTable*>(&kOutTable)));
    TEST_ASSERT_EQUAL_UINT8(0, native::sim_pwm(9));  // nothing driven
}

static void test_digital_task_mirrors_pins(void) {
    TEST_ASSERT_EQUAL(kOk, io_digital_begin(&kDigitalTable));
    TEST_ASSERT_EQUAL_UINT8(pal::kInputPullup, native::sim_pin_mode(2));
    TEST_ASSERT_EQUAL_UINT8(pal::kOutput, native::sim_pin_mode(4));
    native::sim_set_digital(2, true);
    sv[13] = 1;
    TEST_ASSERT_EQUAL(kOk, io_digital_task(const_cast<DigitalTable*>(&kDigitalTable)));
    TEST_ASSERT_EQUAL_UINT8(1, sv[12]);
    TEST_ASSERT_TRUE(native::sim_digital(4));
    native::sim_set_digital(2, false);
    sv[13] = 0;
    TEST_ASSERT_EQUAL(kOk, io_digital_task(const_cast<DigitalTable*>(&kDigitalTable)));
    TEST_ASSERT_EQUAL_UINT8(0, sv[12]);
    TEST_ASSERT_FALSE(native::sim_digital(4));
}

// A table sampled in the background: begin converts once (the first run
// reads the pins as they were at boot); each run converts the counts of
// the previous run's scan and starts the next: one run of latency.
static volatile uint16_t scan_raw[2];
static const AnalogTable kScanTable FSW_FLASH = {kAnalogF32, sv, Real(5), 2, 10, false, scan_raw};

static void test_background_scan_reads_one_run_late(void) {
    native::sim_set_analog(14, 100);
    native::sim_set_analog(15, 200);
    TEST_ASSERT_EQUAL(kOk, io_analog_begin(&kScanTable));
    TEST_ASSERT_EQUAL_UINT16(100, scan_raw[0]);
    TEST_ASSERT_EQUAL_UINT16(200, scan_raw[1]);
    native::sim_set_analog(14, 300);
    native::sim_set_analog(15, 400);
    TEST_ASSERT_EQUAL(kOk, io_analog_in_task_f32(const_cast<AnalogTable*>(&kScanTable)));
    ASSERT_REAL_SAME(analog_value(100, 250, -125), read_F32(sv + 0));  // boot's counts
    ASSERT_REAL_SAME(analog_value(200, 8, -20), read_F32(sv + 4));
    TEST_ASSERT_EQUAL_UINT16(300, scan_raw[0]);  // the next run's, converted meanwhile
    TEST_ASSERT_EQUAL(kOk, io_analog_task_f32(const_cast<AnalogTable*>(&kScanTable)));
    ASSERT_REAL_SAME(analog_value(300, 250, -125), read_F32(sv + 0));
    ASSERT_REAL_SAME(analog_value(400, 8, -20), read_F32(sv + 4));

    TEST_ASSERT_FALSE(pal::adc_scan_busy());
}

// The scan walks the rows' pins in flash with the table's stride.
static void test_scan_walks_the_pins_of_the_rows(void) {
    uint16_t raw[2] = {0, 0};
    native::sim_set_analog(14, 11);
    native::sim_set_analog(15, 22);
    TEST_ASSERT_TRUE(pal::adc_scan_start(&kAnalogF32[0].pin, sizeof(AnalogChannel), 2, raw));
    TEST_ASSERT_EQUAL_UINT16(11, raw[0]);
    TEST_ASSERT_EQUAL_UINT16(22, raw[1]);
    TEST_ASSERT_TRUE(pal::adc_scan_start(&kAnalogF32[1].pin, sizeof(AnalogChannel), 1, raw));
    TEST_ASSERT_EQUAL_UINT16(22, raw[0]);
}

// Generated inputs tasks: one call per channel on the counts of a scan of a
// flash list of pins, and the next scan started: one run of latency.
static const uint8_t kScanPins[2] FSW_FLASH = {15, 14};

static void test_one_call_inputs_read_the_previous_scan(void) {
    static volatile uint16_t raw[2];
    native::sim_set_analog(14, 7);
    native::sim_set_analog(15, 9);
    io_analog_scan_begin(kScanPins, 2, raw);
    TEST_ASSERT_EQUAL_UINT16(9, io_analog_count(raw, 0));
    TEST_ASSERT_EQUAL_UINT16(7, io_analog_count(raw, 1));
    native::sim_set_analog(15, 1023);
    write_F32(sv, analog_value(io_analog_count(raw, 0), 8, -20));  // as a generated task does
    io_analog_scan(kScanPins, 2, raw);
    ASSERT_REAL_SAME(Real(9) * Real(8) + Real(-20), read_F32(sv));  // the boot scan's count
    TEST_ASSERT_EQUAL_UINT16(1023, io_analog_count(raw, 0));         // the next run's
}

// A scan converts every row: a table with an output row cannot sample in
// the background.
static const AnalogTable kScanMixedTable FSW_FLASH = {kAnalog, sv, Real(5), 2, 10, false, scan_raw};

static const AnalogChannel kBadType[1] FSW_FLASH = {{1, 0, 0, 14, kIoIn, kU8}};
static const AnalogTable kBadTypeTable FSW_FLASH = {kBadType, sv, Real(5), 1, 10, false, 0};
static const AnalogTable kBadBitsTable FSW_FLASH = {kAnalog, sv, Real(5), 2, 0, false, 0};
static const DigitalChannel kBadDir[1] FSW_FLASH = {{12, 2, 9}};
static const DigitalTable kBadDirTable FSW_FLASH = {kBadDir, sv, 1, false};

static void test_begin_refuses_bad_tables(void) {
    TEST_ASSERT_EQUAL(kErrConfig, io_analog_begin(&kBadTypeTable));
    TEST_ASSERT_EQUAL(kErrConfig, io_analog_begin(&kBadBitsTable));
    TEST_ASSERT_EQUAL(kErrConfig, io_analog_begin(&kScanMixedTable));
    TEST_ASSERT_EQUAL(kErrConfig, io_digital_begin(&kBadDirTable));
}
#endif

// Generated tasks drive each digital channel with one call on a pin the
// generator resolved (FSW_PIN): pin numbers through the PAL on the host,
// the port registers on AVR.
static void test_resolved_pins_drive_and_read(void) {
    uint8_t elems[2] = {1, 0};
    io_pin_begin(FSW_PIN(13, B, 5), kIoOut);
    io_pin_begin(FSW_PIN(2, D, 2), kIoInPullup);
    io_pin_begin(FSW_PIN(3, D, 3), kIoIn);
#if FSW_AVR_PORTS
    TEST_ASSERT_TRUE(DDRB & _BV(5));
    TEST_ASSERT_FALSE(DDRD & _BV(2));
    TEST_ASSERT_TRUE(PORTD & _BV(2));  // pull-up on
    TEST_ASSERT_FALSE(DDRD & _BV(3));
    TEST_ASSERT_FALSE(PORTD & _BV(3));  // pull-up off
    io_digital_out(FSW_PIN(13, B, 5), &elems[0]);
    TEST_ASSERT_TRUE(PORTB & _BV(5));
    io_digital_out(FSW_PIN(13, B, 5), &elems[1]);
    TEST_ASSERT_FALSE(PORTB & _BV(5));
    elems[0] = 0x80;  // any non-zero byte is true
    io_digital_out(FSW_PIN(13, B, 5), &elems[0]);
    TEST_ASSERT_TRUE(PORTB & _BV(5));
    TEST_ASSERT_FALSE(PORTB & _BV(4));  // the neighbours are untouched
    io_digital_in(FSW_PIN(2, D, 2), &elems[1]);
    TEST_ASSERT_EQUAL_UINT8((PIND & _BV(2)) ? 1 : 0, elems[1]);
#else
    TEST_ASSERT_EQUAL_UINT8(pal::kOutput, native::sim_pin_mode(13));
    TEST_ASSERT_EQUAL_UINT8(pal::kInputPullup, native::sim_pin_mode(2));
    TEST_ASSERT_EQUAL_UINT8(pal::kInput, native::sim_pin_mode(3));
    io_digital_out(FSW_PIN(13, B, 5), &elems[0]);
    TEST_ASSERT_TRUE(native::sim_digital(13));
    io_digital_out(FSW_PIN(13, B, 5), &elems[1]);
    TEST_ASSERT_FALSE(native::sim_digital(13));
    elems[0] = 0x80;
    io_digital_out(FSW_PIN(13, B, 5), &elems[0]);
    TEST_ASSERT_TRUE(native::sim_digital(13));
    native::sim_set_digital(2, true);
    io_digital_in(FSW_PIN(2, D, 2), &elems[1]);
    TEST_ASSERT_EQUAL_UINT8(1, elems[1]);
    native::sim_set_digital(2, false);
    io_digital_in(FSW_PIN(2, D, 2), &elems[1]);
    TEST_ASSERT_EQUAL_UINT8(0, elems[1]);
#endif
}

static void run(void) {
    UNITY_BEGIN();
    RUN_TEST(test_analog_conversion_formula);
    RUN_TEST(test_every_count_converts_as_the_cast);
    RUN_TEST(test_the_memo_gives_analog_values_bit_for_bit);
    RUN_TEST(test_the_inputs_loop_gives_what_each_call_gives);
    RUN_TEST(test_the_kept_inputs_loop_writes_what_the_memo_gives);
    RUN_TEST(test_pwm_duty_from_volts);
#if FSW_REAL_IS_FLOAT
    RUN_TEST(test_analog_conversion_matches_the_host_bit_for_bit);
#endif
    RUN_TEST(test_resolved_pins_drive_and_read);
#if FSW_PLATFORM_NATIVE
    RUN_TEST(test_analog_task_reads_and_writes);
    RUN_TEST(test_analog_f32_task_matches_the_general_task);
    RUN_TEST(test_analog_in_task_matches_the_general_task);
    RUN_TEST(test_digital_task_mirrors_pins);
    RUN_TEST(test_background_scan_reads_one_run_late);
    RUN_TEST(test_scan_walks_the_pins_of_the_rows);
    RUN_TEST(test_one_call_inputs_read_the_previous_scan);
    RUN_TEST(test_begin_refuses_bad_tables);
#endif
    (void)UNITY_END();
}

FSW_TEST_MAIN(run)
