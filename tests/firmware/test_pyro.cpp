// Scenario: the pyro gate (docs/safety.md, "checked at run time"): a pyro
// pin high only while its element is true, every arming pin reads armed,
// the machine is in a fire state, and for at most `pulse` runs of the
// outputs task from the element's rise; one pulse per rise.
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

static const uint16_t kPulse = 5;  // runs

// Runs the gate `n` times with the same inputs; the number of runs it was high.
static uint16_t runs_high(PyroGate& g, bool element, bool armed, bool fire, uint16_t n) {
    uint16_t high = 0;
    for (uint16_t i = 0; i < n; ++i) {
        if (pyro_gate(g, element, armed, fire, kPulse, kPyroNoSense)) ++high;
    }
    return high;
}

static void test_low_while_the_element_is_false(void) {
    PyroGate g = {0, 0, 0};
    TEST_ASSERT_EQUAL_UINT16(0, runs_high(g, false, true, true, 20));
}

static void test_element_true_with_a_key_low_keeps_the_pin_low(void) {
    PyroGate g = {0, 0, 0};
    TEST_ASSERT_FALSE(pyro_gate(g, true, false, true, kPulse, kPyroNoSense));
    // the key coming up later in the same rise does not fire it
    TEST_ASSERT_EQUAL_UINT16(0, runs_high(g, true, true, true, 20));
}

static void test_element_true_outside_a_fire_state_keeps_the_pin_low(void) {
    PyroGate g = {0, 0, 0};
    TEST_ASSERT_EQUAL_UINT16(0, runs_high(g, true, true, false, 20));
}

static void test_element_held_true_drops_the_pin_after_the_pulse(void) {
    PyroGate g = {0, 0, 0};
    for (uint16_t i = 0; i < kPulse; ++i) TEST_ASSERT_TRUE(pyro_gate(g, true, true, true, kPulse, kPyroNoSense));
    TEST_ASSERT_FALSE(pyro_gate(g, true, true, true, kPulse, kPyroNoSense));  // latched low
    TEST_ASSERT_EQUAL_UINT16(0, runs_high(g, true, true, true, 100));
}

static void test_refires_only_after_the_element_falls_and_rises(void) {
    PyroGate g = {0, 0, 0};
    TEST_ASSERT_EQUAL_UINT16(kPulse, runs_high(g, true, true, true, 50));
    TEST_ASSERT_EQUAL_UINT16(0, runs_high(g, false, true, true, 1));
    TEST_ASSERT_EQUAL_UINT16(kPulse, runs_high(g, true, true, true, 50));
    // a fall mid-pulse ends it; the next rise is a whole new pulse
    TEST_ASSERT_EQUAL_UINT16(0, runs_high(g, false, true, true, 1));
    TEST_ASSERT_EQUAL_UINT16(2, runs_high(g, true, true, true, 2));
    TEST_ASSERT_EQUAL_UINT16(0, runs_high(g, false, true, true, 1));
    TEST_ASSERT_EQUAL_UINT16(kPulse, runs_high(g, true, true, true, 50));
}

static void test_the_key_dropping_mid_pulse_ends_the_pulse(void) {
    PyroGate g = {0, 0, 0};
    TEST_ASSERT_EQUAL_UINT16(2, runs_high(g, true, true, true, 2));
    TEST_ASSERT_FALSE(pyro_gate(g, true, false, true, kPulse, kPyroNoSense));
    // the key back on in the same rise: still low, the pulse is over
    TEST_ASSERT_EQUAL_UINT16(0, runs_high(g, true, true, true, 20));
}

static void test_leaving_the_fire_state_mid_pulse_ends_the_pulse(void) {
    PyroGate g = {0, 0, 0};
    TEST_ASSERT_EQUAL_UINT16(1, runs_high(g, true, true, true, 1));
    TEST_ASSERT_FALSE(pyro_gate(g, true, true, false, kPulse, kPyroNoSense));
    TEST_ASSERT_EQUAL_UINT16(0, runs_high(g, true, true, true, 20));
}

static void test_a_one_run_pulse_and_the_widest(void) {
    PyroGate g = {0, 0, 0};
    TEST_ASSERT_TRUE(pyro_gate(g, true, true, true, 1, kPyroNoSense));
    TEST_ASSERT_FALSE(pyro_gate(g, true, true, true, 1, kPyroNoSense));
    PyroGate w = {0, 0, 0};
    uint32_t high = 0;
    for (uint32_t i = 0; i < 70000UL; ++i) {
        if (pyro_gate(w, true, true, true, 0xFFFF, kPyroNoSense)) ++high;
    }
    TEST_ASSERT_EQUAL_UINT32(0xFFFFUL, high);
}

// The status the health frame carries: armed, continuity, fired (latched),
// firing, and the run a pulse starts (when the firmware keeps its state
// before the pin goes high).
static void test_the_status_bits(void) {
    PyroGate g = {0, 0, 0};
    TEST_ASSERT_FALSE(pyro_gate(g, false, false, false, kPulse, kPyroContinuity));
    TEST_ASSERT_EQUAL_HEX8(kPyroContinuity, g.status);
    TEST_ASSERT_FALSE(pyro_gate(g, false, true, false, kPulse, 0));  // an open igniter, armed
    TEST_ASSERT_EQUAL_HEX8(kPyroArmed, g.status);
    TEST_ASSERT_TRUE(pyro_gate(g, true, true, true, kPulse, kPyroNoSense));
    TEST_ASSERT_EQUAL_HEX8(kPyroArmed | kPyroNoSense | kPyroFired | kPyroFiring | kPyroRose, g.status);
    TEST_ASSERT_TRUE(pyro_gate(g, true, true, true, kPulse, kPyroNoSense));  // the rise is one run only
    TEST_ASSERT_EQUAL_HEX8(kPyroArmed | kPyroNoSense | kPyroFired | kPyroFiring, g.status);
    TEST_ASSERT_EQUAL_UINT16(kPulse - 2, runs_high(g, true, true, true, 50));
    TEST_ASSERT_EQUAL_HEX8(kPyroArmed | kPyroNoSense | kPyroFired, g.status);  // fired stays
    TEST_ASSERT_FALSE(pyro_gate(g, false, false, false, kPulse, kPyroNoSense));
    TEST_ASSERT_EQUAL_HEX8(kPyroNoSense | kPyroFired, g.status);
}

// A reset in the middle of a pulse: the kept gate is not started again,
// whatever the element; a new rise fires as always.
static void test_a_resumed_gate_does_not_finish_the_pulse(void) {
    PyroGate g = {0, 0, 0};
    TEST_ASSERT_EQUAL_UINT16(2, runs_high(g, true, true, true, 2));
    PyroGate kept = g;  // the bank taken before the reset
    pyro_resumed(&kept, 1);
    TEST_ASSERT_EQUAL_HEX8(kPyroArmed | kPyroNoSense | kPyroFired, kept.status);
    TEST_ASSERT_EQUAL_UINT16(0, runs_high(kept, true, true, true, 20));
    TEST_ASSERT_EQUAL_UINT16(0, runs_high(kept, false, true, true, 1));
    TEST_ASSERT_EQUAL_UINT16(kPulse, runs_high(kept, true, true, true, 20));
}

// The generated outputs task's line: the arming pin read now, the pyro pin
// driven with the gate's level (fsw_io.h: io_pin_read, io_pin_write).
static void test_the_pin_follows_the_gate(void) {
#if !FSW_AVR_PORTS
    PyroGate g = {0, 0, 0};
    native::sim_set_digital(2, true);
    io_pin_begin(FSW_PIN(5, D, 5), kIoOut);
    io_pin_write(FSW_PIN(5, D, 5), pyro_gate(g, true, io_pin_read(FSW_PIN(2, D, 2)), true, kPulse, kPyroNoSense));
    TEST_ASSERT_TRUE(native::sim_digital(5));
    native::sim_set_digital(2, false);  // the key off
    io_pin_write(FSW_PIN(5, D, 5), pyro_gate(g, true, io_pin_read(FSW_PIN(2, D, 2)), true, kPulse, kPyroNoSense));
    TEST_ASSERT_FALSE(native::sim_digital(5));
#else
    PyroGate g = {0, 0, 0};
    io_pin_begin(FSW_PIN(5, D, 5), kIoOut);
    io_pin_write(FSW_PIN(5, D, 5), pyro_gate(g, true, true, true, kPulse, kPyroNoSense));
    TEST_ASSERT_TRUE(PORTD & _BV(5));
    TEST_ASSERT_TRUE(DDRD & _BV(5));
    io_pin_write(FSW_PIN(5, D, 5), pyro_gate(g, true, false, true, kPulse, kPyroNoSense));  // the key off
    TEST_ASSERT_FALSE(PORTD & _BV(5));
#endif
}

static void run(void) {
    UNITY_BEGIN();
    RUN_TEST(test_low_while_the_element_is_false);
    RUN_TEST(test_element_true_with_a_key_low_keeps_the_pin_low);
    RUN_TEST(test_element_true_outside_a_fire_state_keeps_the_pin_low);
    RUN_TEST(test_element_held_true_drops_the_pin_after_the_pulse);
    RUN_TEST(test_refires_only_after_the_element_falls_and_rises);
    RUN_TEST(test_the_key_dropping_mid_pulse_ends_the_pulse);
    RUN_TEST(test_leaving_the_fire_state_mid_pulse_ends_the_pulse);
    RUN_TEST(test_a_one_run_pulse_and_the_widest);
    RUN_TEST(test_the_status_bits);
    RUN_TEST(test_a_resumed_gate_does_not_finish_the_pulse);
    RUN_TEST(test_the_pin_follows_the_gate);
    (void)UNITY_END();
}

FSW_TEST_MAIN(run)
