// Scenario: the thesis's tank example end to end through the runtime API,
// with its state scripts (examples/tank/*.ss) played by hand; the expected
// figures are those of examples/tank/expected.md.
#include "test_support.h"

using namespace fsw;

#include "tank_hand.inc"

void setUp(void) {}
void tearDown(void) {}

struct ScriptResult {
    uint16_t steps;
    uint16_t asserts_passed;
    bool failed;
};

// tank.ss and its variants: start pressure, and whether the counter assert
// of tank_counter.ss replaces the valve assert.
static ScriptResult run_script(Real start_pressure, bool counter_assert) {
    tank_init(kTankVentControl);
    ScriptResult res = {0, 0, false};
    uint8_t* const sv = tank_sv;
    for (uint64_t g = 0;; g += 10) {
        store<uint64_t>(sv + kOffTime, g);
        // [all_states] inputs, each guard just before its input.
        if (read_U64(sv + kOffTime) == 0) {
            write_F64(sv + kOffTankPressure, start_pressure);
            write_bool(sv + kOffValveOpen, 0);
        }
        if (truthy(read_bool(sv + kOffValveOpen)))
            write_F64(sv + kOffTankPressure, read_F64(sv + kOffTankPressure) - 1);
        if (!truthy(read_bool(sv + kOffValveOpen)))
            write_F64(sv + kOffTankPressure, read_F64(sv + kOffTankPressure) + 1);
        const bool stop = read_U64(sv + kOffTime) == 1000;
        const bool assert_active = tank_machine.state == kTankVentControl;
        TEST_ASSERT_EQUAL(kOk, tank_step());
        ++res.steps;
        if (stop) return res;
        if (assert_active) {
            const bool ok = counter_assert
                ? read_U64(tank_locals + kLocCounter) < 10
                : read_bool(sv + kOffValveOpen) == real_from_truth(read_F64(sv + kOffTankPressure) > 775);
            if (!ok) {
                res.failed = true;
                return res;
            }
            ++res.asserts_passed;
        }
    }
}

static void test_tank_script(void) {
    const ScriptResult r = run_script(600, false);
    TEST_ASSERT_FALSE(r.failed);
    TEST_ASSERT_EQUAL_UINT16(101, r.steps);
    TEST_ASSERT_EQUAL_UINT16(100, r.asserts_passed);
    TEST_ASSERT_EQUAL_UINT64(1000, load<uint64_t>(tank_sv + kOffTime));
    TEST_ASSERT_EQUAL_UINT32(1, load<uint32_t>(tank_sv + kOffState));
    TEST_ASSERT_EQUAL_UINT64(1000, machine_T(tank_machine));
    TEST_ASSERT_EQUAL_UINT64(0, load<uint64_t>(tank_locals + kLocCounter));
    ASSERT_REAL_SAME(Real(701), read_F64(tank_sv + kOffTankPressure));
    TEST_ASSERT_EQUAL_UINT8(0, tank_sv[kOffValveOpen]);
    ASSERT_REAL_SAME(static_cast<Real>(3.14159), read_F64(tank_locals + kLocPi));
}

static void test_tank_770_script(void) {
    const ScriptResult r = run_script(770, false);
    TEST_ASSERT_FALSE(r.failed);
    TEST_ASSERT_EQUAL_UINT16(101, r.steps);
    TEST_ASSERT_EQUAL_UINT16(100, r.asserts_passed);
    TEST_ASSERT_EQUAL_UINT64(48, load<uint64_t>(tank_locals + kLocCounter));
    ASSERT_REAL_SAME(Real(775), read_F64(tank_sv + kOffTankPressure));
}

static void test_tank_counter_script_fails_at_step_24(void) {
    const ScriptResult r = run_script(770, true);
    TEST_ASSERT_TRUE(r.failed);
    TEST_ASSERT_EQUAL_UINT16(24, r.steps);
    TEST_ASSERT_EQUAL_UINT16(23, r.asserts_passed);
    TEST_ASSERT_EQUAL_UINT64(230, load<uint64_t>(tank_sv + kOffTime));
    TEST_ASSERT_EQUAL_UINT64(10, load<uint64_t>(tank_locals + kLocCounter));
    ASSERT_REAL_SAME(Real(776), read_F64(tank_sv + kOffTankPressure));
    TEST_ASSERT_EQUAL_UINT8(1, tank_sv[kOffValveOpen]);
}

static void test_tank_aborts_outside_the_pressure_band(void) {
    tank_init(kTankVentControl);
    store<uint64_t>(tank_sv + kOffTime, 0);
    write_F64(tank_sv + kOffTankPressure, 830);
    TEST_ASSERT_EQUAL(kOk, tank_step());
    TEST_ASSERT_EQUAL_UINT32(kAbort, tank_machine.state);
    TEST_ASSERT_EQUAL_UINT32(kTankVentControl, load<uint32_t>(tank_sv + kOffState));  // S moves next step
    store<uint64_t>(tank_sv + kOffTime, 10);
    TEST_ASSERT_EQUAL(kOk, tank_step());
    TEST_ASSERT_EQUAL_UINT32(kAbort, load<uint32_t>(tank_sv + kOffState));
    TEST_ASSERT_EQUAL(kErrTime, tank_step());  // same G again
}

static void run(void) {
    UNITY_BEGIN();
    RUN_TEST(test_tank_script);
    RUN_TEST(test_tank_770_script);
    RUN_TEST(test_tank_counter_script_fails_at_step_24);
    RUN_TEST(test_tank_aborts_outside_the_pressure_band);
    (void)UNITY_END();
}

FSW_TEST_MAIN(run)
