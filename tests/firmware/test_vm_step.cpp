// Scenario: the bytecode VM steps a verified image (vm_images.h) as a
// generated machine steps: typed instructions, the good image's states,
// transitions, exit blocks and windows (test_vm.cpp: the verifier's rules).
#include "vm_images.h"

namespace {
uint8_t sv[18];  // the state vector the images are bound to
}  // namespace

void setUp(void) {}
void tearDown(void) {}

void test_the_vm_steps_typed_instructions(void) {
    const uint8_t code[] = {
        SETK, 0, L0, kU8, 7,                                 // 0: l = 7
        IADD, 16, 0, kI16, 0, L0, kU8, 0xF6, 0xFF, 0xFF, 0xFF,  // 5: n = l - 10
        JINT, 16, 0, kI16, 0x80, 0, 0, 5, 0,                 // 16: n < 0: past the next
        SETK, 0, L0, kU8, 99,                                // 25
        JKEY, 12, 0, kF32, 2, 0x00, 0x00, 0xC0, 0xBF, 2, 0,  // 30: x > 1.5: past the goto
        GOTO, 1,                                             // 41: to B
        END,                                                 // 43
    };
    Image im;
    step_image(im, code, sizeof code, 1);
    TEST_ASSERT_EQUAL_UINT(kVmOk, verify(im));
    Machine m;
    memset(sv, 0, sizeof sv);
    vm_reset(im.b, ram, m, 1);
    const uint8_t* loc = vm_locals(im.b, ram);
    store<float>(sv + 12, 2.0f);
    store<uint64_t>(sv, 10);
    TEST_ASSERT_EQUAL_UINT(kOk, vm_step(im.b, kLayout, sv, ram, m));
    TEST_ASSERT_EQUAL_UINT8(7, loc[0]);  // the SETK after the JINT skipped
    TEST_ASSERT_EQUAL_INT16(-3, load<int16_t>(sv + 16));
    TEST_ASSERT_EQUAL_UINT32(1, m.state);  // x > 1.5: no goto
    store<float>(sv + 12, -2.0f);  // a negative key is below every positive one
    store<uint64_t>(sv, 20);
    TEST_ASSERT_EQUAL_UINT(kOk, vm_step(im.b, kLayout, sv, ram, m));
    TEST_ASSERT_EQUAL_UINT32(2, m.state);
    const float above[] = {1.5000001f, 3e38f};
    const float below[] = {1.5f, -0.0f, -3e38f, 1e-45f};
    for (int k = 0; k < 6; ++k) {
        vm_reset(im.b, ram, m, 1);
        store<float>(sv + 12, k < 2 ? above[k] : below[k - 2]);
        store<uint64_t>(sv, static_cast<uint64_t>(30 + k));
        TEST_ASSERT_EQUAL_UINT(kOk, vm_step(im.b, kLayout, sv, ram, m));
        TEST_ASSERT_EQUAL_UINT32(k < 2 ? 1 : 2, m.state);
    }
    vm_reset(im.b, ram, m, 1);
    uint32_t nan = 0x7FC00001UL;  // a NaN reads as 0: not > 1.5
    memcpy(sv + 12, &nan, 4);
    store<uint64_t>(sv, 40);
    TEST_ASSERT_EQUAL_UINT(kOk, vm_step(im.b, kLayout, sv, ram, m));
    TEST_ASSERT_EQUAL_UINT32(2, m.state);
    // IADD saturates at its target's range: n = l + 40000 is 32767
    const uint8_t sat[] = {IADD, 16, 0, kI16, 0, L0, kU8, 0x40, 0x9C, 0x00, 0x00, END};
    step_image(im, sat, sizeof sat, 1);
    TEST_ASSERT_EQUAL_UINT(kVmOk, verify(im));
    vm_reset(im.b, ram, m, 1);
    store<uint64_t>(sv, 50);
    TEST_ASSERT_EQUAL_UINT(kOk, vm_step(im.b, kLayout, sv, ram, m));
    TEST_ASSERT_EQUAL_INT16(32767, load<int16_t>(sv + 16));  // 3 + 40000, saturated
}

// kJInt of an 8-byte integer (G, U64) under each comparison, against a
// constant whose bytes all differ, for values that differ from it in the
// low byte, a middle one, the top one, or not at all: the AVR's compare
// chain (fsw_vm.cpp's u64_order) orders them as the C integers do.
void test_the_vm_orders_8_byte_integers(void) {
    const uint64_t c = 0x0102030405060708ULL;
    const uint64_t values[] = {0, 0x0102030305060708ULL, c - 1, c, c + 1, c + 0xFF00, 0x0202030405060708ULL,
                               0xF102030405060707ULL};
    Image im;
    Machine m;
    for (uint8_t cmp = 0; cmp < 6; ++cmp) {  // <, <=, >, >=, ==, !=
        uint8_t code[] = {JINT, 0, 0, kU64, static_cast<uint8_t>(0x80 | cmp), 8, 7, 6, 5, 4, 3, 2, 1, 2, 0,
                          GOTO, 1, END};  // the test holds: past the goto, in A
        step_image(im, code, sizeof code, 1);
        TEST_ASSERT_EQUAL_UINT(kVmOk, verify(im));
        for (uint8_t k = 0; k < sizeof values / sizeof values[0]; ++k) {
            const uint64_t v = values[k];
            const bool holds = cmp == 0   ? v < c
                               : cmp == 1 ? v <= c
                               : cmp == 2 ? v > c
                               : cmp == 3 ? v >= c
                               : cmp == 4 ? v == c
                                          : v != c;
            memset(sv, 0, sizeof sv);
            vm_reset(im.b, ram, m, 1);
            store<uint64_t>(sv, v);
            TEST_ASSERT_EQUAL_UINT(kOk, vm_step(im.b, kLayout, sv, ram, m));
            TEST_ASSERT_EQUAL_UINT32_MESSAGE(holds ? 1 : 2, m.state, "the order of an 8-byte integer");
        }
    }
}

void test_the_vm_steps_the_good_image(void) {
    Image im;
    good(im);
    TEST_ASSERT_EQUAL_UINT(kVmOk, verify(im));
    Machine m;
    memset(sv, 0, sizeof sv);
    vm_reset(im.b, ram, m, 1);
    uint8_t* loc = vm_locals(im.b, ram);
    TEST_ASSERT_EQUAL_UINT8(3, loc[0]);
    store<float>(sv + 12, 0.0f);  // x 0, n 0: not x > n: l doubles (3 -> 6)
    store<uint64_t>(sv, 10);
    TEST_ASSERT_EQUAL_UINT(kOk, vm_step(im.b, kLayout, sv, ram, m));
    TEST_ASSERT_EQUAL_UINT32(1, load<uint32_t>(sv + 8));
    TEST_ASSERT_EQUAL_UINT8(6, loc[0]);
    TEST_ASSERT_EQUAL_UINT(kErrTime, vm_step(im.b, kLayout, sv, ram, m));  // G did not increase
    TEST_ASSERT_EQUAL_UINT8(6, loc[0]);
    store<float>(sv + 12, 2.5f);  // x > n: to B, .exit writes n = T (20)
    store<uint64_t>(sv, 30);
    TEST_ASSERT_EQUAL_UINT(kOk, vm_step(im.b, kLayout, sv, ram, m));
    TEST_ASSERT_EQUAL_INT16(20, load<int16_t>(sv + 16));
    TEST_ASSERT_EQUAL_UINT32(2, m.state);
    TEST_ASSERT_EQUAL_UINT8(6, loc[0]);  // l unchanged on the transition
    // In B: x and l are true: (x and l) or not l holds: back to A.
    store<uint64_t>(sv, 40);
    TEST_ASSERT_EQUAL_UINT(kOk, vm_step(im.b, kLayout, sv, ram, m));
    TEST_ASSERT_EQUAL_UINT32(2, load<uint32_t>(sv + 8));
    TEST_ASSERT_EQUAL_UINT32(1, m.state);
    TEST_ASSERT_EQUAL_UINT8(1, m.pending);
}


FSW_TEST_MAIN([] {
    UNITY_BEGIN();
    RUN_TEST(test_the_vm_steps_typed_instructions);
    RUN_TEST(test_the_vm_orders_8_byte_integers);
    RUN_TEST(test_the_vm_steps_the_good_image);
    (void)UNITY_END();
})
