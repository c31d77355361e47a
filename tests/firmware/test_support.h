// Shared by every firmware suite: the closing "N passed, N failed" line that
// CI reads, the suite entry point (main on a host, setup() under the Arduino
// core on AVR, ending the simulation), and bit-exact float helpers.
#ifndef FSW_TEST_SUPPORT_H
#define FSW_TEST_SUPPORT_H

#include "fswkit.h"
#include "unity.h"

// Prints "N passed, N failed" after UNITY_END(); returns 0 when none failed.
int fsw_test_finish(void);
// AVR: sets UART0 up for test output / waits for it to drain and stops
// the simulation (cli + sleep).
void fsw_test_uart_begin(void);
void fsw_test_halt(void);

#if defined(__AVR__)
#define FSW_TEST_MAIN(run)       \
    extern "C" void setup() {    \
        fsw_test_uart_begin();   \
        run();                   \
        (void)fsw_test_finish(); \
        fsw_test_halt();         \
    }                            \
    extern "C" void loop() {}
#else
#define FSW_TEST_MAIN(run)         \
    int main() {                   \
        run();                     \
        return fsw_test_finish();  \
    }
#endif

// Bit patterns, for exact comparisons (sign of zero, NaN payloads).
inline uint32_t bits_of(float f) { uint32_t u; memcpy(&u, &f, sizeof u); return u; }
inline float float_of(uint32_t u) { float f; memcpy(&f, &u, sizeof f); return f; }
#if !defined(__AVR__)
inline uint64_t bits_of(double d) { uint64_t u; memcpy(&u, &d, sizeof u); return u; }
inline double double_of(uint64_t u) { double d; memcpy(&d, &u, sizeof d); return d; }
#endif

// Asserts two Reals are the same value bit for bit (NaNs: both NaN).
#define ASSERT_REAL_SAME(expected, actual) \
    TEST_ASSERT_TRUE_MESSAGE(fsw_test_same((expected), (actual)), "Real values differ")
inline bool fsw_test_same(fsw::Real a, fsw::Real b) {
    if (a != a) return b != b;
    return memcmp(&a, &b, sizeof a) == 0;
}

#endif
