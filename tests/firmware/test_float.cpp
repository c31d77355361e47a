// Scenario: the float routines the kit puts ahead of avr-libc's (on AVR
// only: elsewhere the compiler's own arithmetic runs): binary32 addition
// and subtraction (__addsf3, __subsf3 in fsw_element.cpp), bit for bit
// avr-libc's on tens of thousands of operand pairs. A suite of its own: the
// conversions' suite leaves its stack too little RAM for another test.
#include <avr/pgmspace.h>

#include "test_support.h"

void setUp(void) {}
void tearDown(void) {}

// avr-libc's __addsf3: `clr r26, clr r27`, its __addsf3x, then its
// __fp_round, called here as it calls them (its __subsf3: the same with
// b's sign flipped).
static float libm_add(float a, float b) {
    register float r __asm__("r22") = a;
    register float v __asm__("r18") = b;
    __asm__ __volatile__("clr r26\n\tclr r27\n\tcall __addsf3x\n\tcall __fp_round"
                         : "+r"(r), "+r"(v)
                         :
                         : "r0", "r26", "r27", "r30", "r31", "memory");
    return r;
}
extern "C" const char __addsf3[];

static uint32_t xorshift(uint32_t& x) {
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    return x;
}

// Where a result differs: the operands, in hex, then the failing result
// (Unity's own printing: no printf nor message buffer in the suite's RAM,
// which leaves its stack short).
static __attribute__((noinline)) void sum_differs(uint32_t ab, uint32_t bb, const uint32_t* got, const uint32_t* want) {
    UnityPrintNumberHex(ab, 8);
    UNITY_OUTPUT_CHAR(' ');
    UnityPrintNumberHex(bb, 8);
    UNITY_OUTPUT_CHAR(' ');
    TEST_ASSERT_EQUAL_HEX32_MESSAGE(want[0], got[0], "a + b");
    TEST_ASSERT_EQUAL_HEX32_MESSAGE(want[1], got[1], "a - b");
}

static void check_sum(uint32_t ab, uint32_t bb) {
    float a, b;
    memcpy(&a, &ab, sizeof a);
    memcpy(&b, &bb, sizeof b);
    volatile float va = a, vb = b;  // the operations at run time, through the compiler's calls
    const float sum = va + vb, diff = va - vb;
    const float want_sum = libm_add(a, b), want_diff = libm_add(a, -b);
    uint32_t got[2], want[2];
    memcpy(&got[0], &sum, 4);
    memcpy(&got[1], &diff, 4);
    memcpy(&want[0], &want_sum, 4);
    memcpy(&want[1], &want_diff, 4);
    if (got[0] != want[0] || got[1] != want[1]) sum_differs(ab, bb, got, want);
}

// Every result the same bits as avr-libc's: random patterns of every kind
// (NaNs, infinities, subnormals, zeros), then pairs of one exponent and
// opposite signs (the case the kit works out itself: any difference,
// cancellation down to +0, the exponents at the edges 1, 24, 25 and 254),
// then pairs a few units in the last place apart.
static void test_float_addition_is_avr_libcs_bit_for_bit(void) {
    // The kit's routine is the one linked: it starts `mov r26, r25`
    // (avr-libc's `clr r27`).
    TEST_ASSERT_EQUAL_HEX16(0x2FA9, pgm_read_word(__addsf3));
    uint32_t x = 0x2545F491UL;
    for (uint16_t i = 0; i < 6000; ++i) check_sum(xorshift(x), xorshift(x));
    static const uint8_t kEdges[] PROGMEM = {1, 2, 23, 24, 25, 26, 127, 150, 253, 254};
    for (uint16_t i = 0; i < 12000; ++i) {
        const uint32_t r = xorshift(x);
        const uint32_t e = i < 4000 ? pgm_read_byte(&kEdges[i % sizeof kEdges]) : (r >> 24) % 254u + 1u;  // 1..254
        const uint32_t sa = (r & 1u) ? 0x80000000UL : 0, sb = (r & 2u) ? 0x80000000UL : 0;
        const uint32_t ma = xorshift(x) & 0x7FFFFFUL;
        uint32_t mb = xorshift(x) & 0x7FFFFFUL;
        if (i % 3u == 1u) mb = ma;  // equal: +0
        if (i % 3u == 2u) mb = (ma ^ (r >> 8 & (0x7FFFFFUL >> (r >> 27)))) & 0x7FFFFFUL;  // its high bits the same
        check_sum(sa | e << 23 | ma, sb | e << 23 | mb);
    }
    for (uint16_t i = 0; i < 6000; ++i) {  // a few units in the last place apart, across exponents too
        const uint32_t a = xorshift(x);
        const uint32_t d = xorshift(x) % 64u;
        check_sum(a, (i & 1u) ? a + d : a - d);
        check_sum(a, (a + d) ^ 0x80000000UL);
    }
}

static void run(void) {
    UNITY_BEGIN();
    RUN_TEST(test_float_addition_is_avr_libcs_bit_for_bit);
    (void)UNITY_END();
}

FSW_TEST_MAIN(run)
