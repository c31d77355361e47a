// Scenario: the bytecode verifier (docs/bytecode.md, "The verifier") refuses
// an image that breaks each of its rules, with that rule's reason code
// (test_vm_step.cpp: the VM steps a verified image as a generated machine steps).
#include "vm_images.h"

void setUp(void) {}
void tearDown(void) {}

void test_the_good_image_verifies(void) {
    Image im;
    good(im);
    TEST_ASSERT_EQUAL_UINT(kVmOk, verify(im));
    TEST_ASSERT_EQUAL_UINT(48, im.code);  // header 28, states 12, local 3, window 4, initial value 1
    TEST_ASSERT_TRUE(vm_ram_size(im.b, im.len) <= sizeof ram);
}

void test_header_rules(void) {
    Image im;
    good(im);
    im.b[0] = 'X';
    TEST_ASSERT_EQUAL_UINT(kVmBadMagic, verify(im));
    good(im);
    im.b[4] = 1;  // the format before the typed instructions
    TEST_ASSERT_EQUAL_UINT(kVmBadVersion, verify(im));
    good(im);
    im.b[4] = 2;  // typed instructions naming a variable by its index
    TEST_ASSERT_EQUAL_UINT(kVmBadVersion, verify(im));
    good(im);
    im.b[6] = 0x80;  // an unknown flag
    TEST_ASSERT_EQUAL_UINT(kVmBadVersion, verify(im));
    good(im);
    im.b[5] = sizeof(Real) == 4 ? 8 : 4;
    TEST_ASSERT_EQUAL_UINT(kVmBadReal, verify(im));
    good(im);
    const VmLayout other = {kElems, 4, 0x12345679UL};
    TEST_ASSERT_EQUAL_UINT(kVmBadSchema, vm_verify(im.b, im.len, other, sizeof ram));
    const VmLayout fewer = {kElems, 3, 0x12345678UL};
    TEST_ASSERT_EQUAL_UINT(kVmBadSchema, vm_verify(im.b, im.len, fewer, sizeof ram));
    TEST_ASSERT_EQUAL_UINT(kVmBadSize, vm_verify(im.b, static_cast<uint16_t>(im.len - 1u), kLayout, sizeof ram));
    TEST_ASSERT_EQUAL_UINT(kVmBadSize, vm_verify(im.b, static_cast<uint16_t>(im.len + 1u), kLayout, sizeof ram));
    TEST_ASSERT_EQUAL_UINT(kVmBadSize, vm_verify(im.b, 27, kLayout, sizeof ram));
    TEST_ASSERT_EQUAL_UINT(kVmNoRam, vm_verify(im.b, im.len, kLayout, vm_ram_size(im.b, im.len) - 1u));
    TEST_ASSERT_EQUAL_UINT(kVmOk, vm_verify(im.b, im.len, kLayout, vm_ram_size(im.b, im.len)));
}

void test_element_rules(void) {
    TEST_ASSERT_EQUAL_UINT(kVmBadElement, patched(1, 4));     // element 4 of 4
    TEST_ASSERT_EQUAL_UINT(kVmBadElement, patched(3, kF64));  // x is F32
    TEST_ASSERT_EQUAL_UINT(kVmBadElement, patched(29, kI32)); // a store of n as I32
    Image im;
    good(im);
    put16(im.b + 14, 12);  // G bound to x (F32)
    TEST_ASSERT_EQUAL_UINT(kVmBadElement, verify(im));
    good(im);
    put16(im.b + 16, 0);  // S bound to G (U64)
    TEST_ASSERT_EQUAL_UINT(kVmBadElement, verify(im));
    good(im);
    put16(im.b + 14, 1);  // G inside itself: no element's offset
    TEST_ASSERT_EQUAL_UINT(kVmBadElement, verify(im));
    good(im);
    put16(im.b + 16, 1);  // S by its index (format 2): G's second byte
    TEST_ASSERT_EQUAL_UINT(kVmBadElement, verify(im));
}

void test_local_rules(void) {
    TEST_ASSERT_EQUAL_UINT(kVmBadLocal, patched(15, 1));  // local 1 of 1
    Image im;
    good(im);
    im.b[28 + 12] = kU16;  // the U8 local declared U16: outside the 1 byte of locals
    TEST_ASSERT_EQUAL_UINT(kVmBadLocal, verify(im));
    good(im);
    im.b[28 + 12] = 11;  // no such type
    TEST_ASSERT_EQUAL_UINT(kVmBadLocal, verify(im));
}

// The good image with its U8 local declared `type` (4 or 8 bytes, zero).
void wide_local(Image& im, uint8_t type, uint8_t bytes) {
    good(im);
    im.b[28 + 12] = type;
    put16(im.b + 22, bytes);
    const uint8_t more = static_cast<uint8_t>(bytes - 1u);
    memmove(im.b + im.code + more, im.b + im.code, im.len - im.code);
    memset(im.b + im.code - 1, 0, bytes);
    im.code = static_cast<uint16_t>(im.code + more);
    im.len = static_cast<uint16_t>(im.len + more);
}

#if !defined(__AVR__)
// The layout above with x an F64: a type this VM was built without.
const VmElem kF64Elems[] FSW_FLASH = {{0, kU64}, {8, kU32}, {12, kF64}, {20, kI16}};
#endif

void test_feature_rules(void) {
    // A window function and a value type this VM was built without.
    Image im;
    good(im);
    im.b[28 + 15] = 4;  // roll_median
    TEST_ASSERT_EQUAL_UINT(kVmNoFeature, verify(im));
    wide_local(im, kF64, 8);
    TEST_ASSERT_EQUAL_UINT(kVmNoFeature, verify(im));
#if !defined(__AVR__)  // (the rest on a host: the suite fills the ATmega328P's flash)
    // ... and those it was built with: the same images otherwise.
    good(im);
    im.b[28 + 15] = 2;  // roll_max
    TEST_ASSERT_EQUAL_UINT(kVmOk, verify(im));
    wide_local(im, kF32, 4);
    TEST_ASSERT_EQUAL_UINT(kVmOk, verify(im));
    // A rule of the window or the local itself comes first.
    good(im);
    im.b[28 + 15] = 4;
    put16(im.b + 28 + 17, 0);  // N = 0
    TEST_ASSERT_EQUAL_UINT(kVmBadWindow, verify(im));
    wide_local(im, kF64, 8);
    put16(im.b + 22, 7);  // and the local past the locals' bytes
    TEST_ASSERT_EQUAL_UINT(kVmBadLocal, vm_verify(im.b, static_cast<uint16_t>(im.len - 1u), kLayout, sizeof ram));
    // A layout with such a type: no image runs on it, refused before its
    // code is read (a generated layout's types are always the VM's).
    const VmLayout f64 = {kF64Elems, 4, 0x12345678UL};
    good(im);
    TEST_ASSERT_EQUAL_UINT(kVmNoFeature, vm_verify(im.b, im.len, f64, sizeof ram));
#endif
}

void test_state_rules(void) {
    TEST_ASSERT_EQUAL_UINT(kVmBadState, patched(13, 2));  // goto state 2 of 2
    Image im;
    good(im);
    put16(im.b + 28 + 2, static_cast<uint16_t>(sizeof kCode));  // a .step past the code
    TEST_ASSERT_EQUAL_UINT(kVmBadState, verify(im));
    good(im);
    im.b[18] = 0;  // no states (and no state table)
    memmove(im.b + 28, im.b + 40, im.len - 40u);
    im.len = static_cast<uint16_t>(im.len - 12u);
    TEST_ASSERT_EQUAL_UINT(kVmBadState, verify(im));
}

void test_window_rules(void) {
    TEST_ASSERT_EQUAL_UINT(kVmBadWindow, patched(60, 1));  // push window 1 of 1
    Image im;
    good(im);
    im.b[28 + 15] = 5;  // no such function
    TEST_ASSERT_EQUAL_UINT(kVmBadWindow, verify(im));
    good(im);
    put16(im.b + 28 + 17, 0);  // N = 0
    TEST_ASSERT_EQUAL_UINT(kVmBadWindow, verify(im));
    const uint8_t roll_missing[] = {ROLL, 1, STE, 3, 0, kI16, END};
    TEST_ASSERT_EQUAL_UINT(kVmBadWindow, with_step(roll_missing, sizeof roll_missing, 1));
    // A prelude that reads its window before pushing it, or never pushes it.
    const uint8_t early[] = {END, ROLL, 0, WPUSH, 0, END};
    const uint16_t offs[6] = {NO, 0, NO, NO, NO, NO};
    build(im, early, sizeof early, offs, 1, 1);
    TEST_ASSERT_EQUAL_UINT(kVmBadWindow, verify(im));
    const uint8_t none[] = {END, END};
    build(im, none, sizeof none, offs, 1, 0);
    TEST_ASSERT_EQUAL_UINT(kVmBadWindow, verify(im));
}

void test_jump_rules(void) {
    // Past the code, and into the middle of an instruction (the goto's operand).
    TEST_ASSERT_EQUAL_UINT(kVmBadJump, patched(10, 200));
    TEST_ASSERT_EQUAL_UINT(kVmBadJump, patched(10, 1));
    // Out of its block: over the .step's END to the prelude that follows.
    const uint8_t out[] = {LDT, JF, 1, 0, END};
    TEST_ASSERT_EQUAL_UINT(kVmBadJump, with_step(out, sizeof out, 1));
    // Over the GOTO into the .exit: the code between (the .step's else
    // branch) is then reached by nothing.
    TEST_ASSERT_EQUAL_UINT(kVmBadEnd, patched(10, 13));
    // A backward jump cannot be written: the displacement is unsigned, and
    // 0xFFFF forward leaves the code.
    Image im;
    good(im);
    put16(im.b + im.code + 10, 0xFFFFu);
    TEST_ASSERT_EQUAL_UINT(kVmBadJump, verify(im));
}

void test_stack_rules(void) {
    const uint8_t underflow[] = {LDT, ADD, STE, 3, 0, kI16, END};
    TEST_ASSERT_EQUAL_UINT(kVmBadStack, with_step(underflow, sizeof underflow, 1));
    const uint8_t left[] = {LDT, END};
    TEST_ASSERT_EQUAL_UINT(kVmBadStack, with_step(left, sizeof left, 1));
    const uint8_t ok[] = {LDT, LDT, ADD, STE, 3, 0, kI16, END};
    TEST_ASSERT_EQUAL_UINT(kVmOk, with_step(ok, sizeof ok, 2));
    TEST_ASSERT_EQUAL_UINT(kVmBadStack, with_step(ok, sizeof ok, 3));  // declared deeper than it is
    uint8_t deep[2 * FSW_VM_STACK + 8];
    uint16_t n = 0;
    for (int k = 0; k <= FSW_VM_STACK; ++k) deep[n++] = LDT;
    for (int k = 0; k < FSW_VM_STACK; ++k) deep[n++] = ADD;
    deep[n++] = STE; deep[n++] = 3; deep[n++] = 0; deep[n++] = kI16; deep[n++] = END;
    TEST_ASSERT_EQUAL_UINT(kVmBadStack, with_step(deep, n, FSW_VM_STACK + 1));
    // Two paths reaching one place with different depths.
    const uint8_t uneven[] = {LDT, LDT, JF, 1, 0, LDT, STE, 3, 0, kI16, END};
    TEST_ASSERT_EQUAL_UINT(kVmBadStack, with_step(uneven, sizeof uneven, 2));
}

void test_opcode_and_end_rules(void) {
    TEST_ASSERT_EQUAL_UINT(kVmBadOpcode, patched(8, 0x77));
    const uint8_t cut[] = {CONST, 0};  // its value runs past the code
    const uint16_t offs[6] = {NO, 0, NO, NO, NO, NO};
    const uint16_t none[6] = {NO, NO, NO, NO, NO, NO};
    Image im;
    build(im, cut, sizeof cut, none, 0, 1);
    TEST_ASSERT_EQUAL_UINT(kVmBadOpcode, verify(im));
    // The code not ending with END.
    const uint8_t unended[] = {LDE, 2, 0, kF32, WPUSH, 0, END, LDT, STE, 3, 0, kI16};
    build(im, unended, sizeof unended, offs, 0, 1);
    put16(im.b + 28 + 2, 7);
    TEST_ASSERT_EQUAL_UINT(kVmBadEnd, verify(im));
    // A block offset in the middle of a block, and code nothing reaches.
    good(im);
    put16(im.b + 28 + 4, 26);  // A's .exit at the STE after LDT
    TEST_ASSERT_EQUAL_UINT(kVmBadEnd, verify(im));
    const uint8_t dead[] = {LDT, JF, 3, 0, GOTO, 0, LDT, END};  // LDT after the goto: never reached
    TEST_ASSERT_EQUAL_UINT(kVmBadEnd, with_step(dead, sizeof dead, 1));
}

void test_place_rules(void) {
    // A goto in .exit, and in the prelude; a window push in a .step.
    Image im;
    const uint8_t ex[] = {GOTO, 0, LDE, 2, 0, kF32, WPUSH, 0, END};
    const uint16_t offs[6] = {NO, NO, 0, NO, NO, NO};
    build(im, ex, sizeof ex, offs, 2, 1);
    TEST_ASSERT_EQUAL_UINT(kVmBadPlace, verify(im));
    const uint8_t pre[] = {LDE, 2, 0, kF32, WPUSH, 0, GOTO, 0};
    const uint16_t none[6] = {NO, NO, NO, NO, NO, NO};
    build(im, pre, sizeof pre, none, 0, 1);
    TEST_ASSERT_EQUAL_UINT(kVmBadPlace, verify(im));
    const uint8_t push[] = {LDT, WPUSH, 0, END};
    TEST_ASSERT_EQUAL_UINT(kVmBadPlace, with_step(push, sizeof push, 1));
    // One block both a .step (may transition) and an .exit (may not).
    const uint8_t both[] = {END, LDE, 2, 0, kF32, WPUSH, 0, END};
    const uint16_t shared[6] = {NO, 0, 0, NO, NO, NO};
    build(im, both, sizeof both, shared, 1, 1);
    TEST_ASSERT_EQUAL_UINT(kVmBadPlace, verify(im));
}

void test_nesting_rule(void) {
    // FSW_VM_PENDING + 1 jumps pending at once (all to the END).
    uint8_t code[4 * (FSW_VM_PENDING + 1) + 8];
    uint16_t n = 0;
    const int jumps = FSW_VM_PENDING + 1;
    for (int k = 0; k < jumps; ++k) {
        code[n++] = LDT;
        code[n++] = JF;
        put16(code + n, static_cast<uint16_t>(4 * (jumps - 1 - k)));
        n = static_cast<uint16_t>(n + 2u);
    }
    code[n++] = END;
    TEST_ASSERT_EQUAL_UINT(kVmTooNested, with_step(code, n, 1));
    TEST_ASSERT_EQUAL_UINT(kVmOk, with_step(code + 4, static_cast<uint16_t>(n - 4u), 1));
}

// A typed instruction's rule: the step's code (in flash, as the table is
// long for an Uno) and the reason it gets.
struct TypedCase {
    uint8_t code[14];
    uint8_t n, stack, reason;
};
const uint8_t kIfF32 = sizeof(Real) == 4 ? kVmBadOpcode : kVmOk;
const TypedCase kTypedCases[] FSW_FLASH = {
    // JKEY x > 1.5 (its key 0xBFC00000), jump past END to END
    {{JKEY, 12, 0, kF32, 2, 0x00, 0x00, 0xC0, 0xBF, 1, 0, END, END}, 13, 1, kVmOk},
    {{JKEY, 16, 0, kI16, 2, 0x00, 0x00, 0xC0, 0xBF, 1, 0, END, END}, 13, 1, kVmBadElement},  // n: an I16
    {{JKEY, 12, 0, kF64, 2, 0x00, 0x00, 0xC0, 0xBF, 1, 0, END, END}, 13, 1, kVmBadElement},  // x is no F64
    {{JKEY, 14, 0, kF32, 2, 0x00, 0x00, 0xC0, 0xBF, 1, 0, END, END}, 13, 1, kVmBadElement},  // inside x
    {{JKEY, 20, 0, kF32, 2, 0x00, 0x00, 0xC0, 0xBF, 1, 0, END, END}, 13, 1, kVmBadElement},  // past the layout
    {{JKEY, 0, L0, kU8, 2, 0x00, 0x00, 0xC0, 0xBF, 1, 0, END, END}, 13, 1, kVmBadLocal},    // local 0: a U8
    {{JKEY, 0, L0, kF32, 2, 0x00, 0x00, 0xC0, 0xBF, 1, 0, END, END}, 13, 1, kVmBadLocal},   // 4 bytes of 1
    {{JKEY, 1, L0, kU8, 2, 0x00, 0x00, 0xC0, 0xBF, 1, 0, END, END}, 13, 1, kVmBadLocal},    // past the locals
    {{JKEY, 0, L0, 11, 2, 0x00, 0x00, 0xC0, 0xBF, 1, 0, END, END}, 13, 1, kVmBadLocal},     // no type
    {{JKEY, 12, 0, kF32, 4, 0x00, 0x00, 0xC0, 0xBF, 1, 0, END, END}, 13, 1, kVmBadOpcode},  // an unknown flag
    // JINT T > 0x00000FA0 (4 bytes for T, whose type is U64's), jump past END
    {{JINT, TLO, THI, kU64, 0x82, 0xA0, 0x0F, 0, 0, 1, 0, END, END}, 13, 1, kVmOk},
    {{JINT, TLO, THI, kU32, 0x82, 0xA0, 0x0F, 0, 0, 1, 0, END, END}, 13, 1, kVmBadElement},  // T of another type
    {{JINT, TLO, THI, kU64, 0x86, 0xA0, 0x0F, 0, 0, 1, 0, END, END}, 13, 1, kVmBadOpcode},  // comparison 6: none
    {{JINT, 12, 0, kF32, 0x02, 0, 0, 0, 0, 1, 0, END, END}, 13, 1, kVmBadElement},         // x is no integer
    {{JINT, TLO, THI, kU64, 0x82, 0, 0, 0, 0, 9, 0, END, END}, 13, 1, kVmBadJump},         // past the code
    // SETK: T takes nothing
    {{SETK, 0, L0, kU8, 7, END}, 6, 1, kVmOk},
    {{SETK, TLO, THI, kU64, 0, 0, 0, 0, 0, 0, 0, 0, END}, 13, 1, kVmBadElement},
    // typed instructions run at depth 0 only
    {{LDT, SETK, 0, L0, kU8, 7, STE, 3, 0, kI16, END}, 11, 1, kVmBadStack},
    // IADD n = l + k: integers only, |k| below 2^24 in binary32
    {{IADD, 16, 0, kI16, 0, L0, kU8, 0xF6, 0xFF, 0xFF, 0xFF, END}, 12, 1, kVmOk},         // k = -10
    {{IADD, 12, 0, kF32, 0, L0, kU8, 0xF6, 0xFF, 0xFF, 0xFF, END}, 12, 1, kVmBadElement}, // into x: a float
    {{IADD, 16, 0, kI16, 1, L0, kU8, 0xF6, 0xFF, 0xFF, 0xFF, END}, 12, 1, kVmBadLocal},   // from past the locals
    {{IADD, 16, 0, kI16, 0, L0, kU8, 0x00, 0x00, 0x00, 0x01, END}, 12, 1, kIfF32},        // k = 2^24
    // JCMP pops two
    {{LDT, LDT, JCMP, 0x00, 1, 0, END, END}, 8, 2, kVmOk},
    {{LDT, JCMP, 0x00, 1, 0, END, END}, 7, 1, kVmBadStack},
};

void test_typed_instruction_rules(void) {
    for (uint8_t k = 0; k < sizeof kTypedCases / sizeof kTypedCases[0]; ++k) {
        TypedCase c;
        flash_read(&c, &kTypedCases[k], sizeof c);
        // 100 k + reason: a failure shows the case's index too
        TEST_ASSERT_EQUAL_UINT(100u * k + c.reason, 100u * k + with_step(c.code, c.n, c.stack));
    }
    // a locked state vector: elements only through LDE/STE
    TypedCase c;
    flash_read(&c, &kTypedCases[0], sizeof c);
    Image im;
    step_image(im, c.code, c.n, c.stack);
    TEST_ASSERT_EQUAL_UINT(kVmOk, verify(im));
    im.b[6] = 1;
    TEST_ASSERT_EQUAL_UINT(kVmBadElement, verify(im));
}


#if !defined(__AVR__)
// The same rules in slices (vm_check_eeprom: what a board runs a slice of
// at each machine step for a commit or an activation, fsw_reload.h), over
// the image in the EEPROM: vm_verify's answer for every budget, each call
// within the reads fsw_vm.h promises, over many calls for a small budget.
// (Natively: the host's EEPROM model counts the reads; and an Uno's test_vm
// has no flash left for the EEPROM verifier.)
uint8_t sliced(const Image& im, uint16_t budget, uint32_t& calls) {
    memcpy(native::sim_eeprom() + 100, im.b, im.len);
    VmCheck c;
    vm_check_begin(c);
    uint8_t r = kVmMore;
    for (calls = 0; r == kVmMore; ++calls) {
        const uint32_t before = native::sim_eeprom_reads();
        r = vm_check_eeprom(c, 100, im.len, kLayout, sizeof ram, budget);
        const uint32_t reads = native::sim_eeprom_reads() - before, header = calls == 0 ? 27u : 10u;
        TEST_ASSERT_TRUE(reads <= (budget > header ? budget + 13u : header + 14u));
        TEST_ASSERT_TRUE(calls < 1000);
    }
    return r;
}

void test_the_check_in_slices_gives_vm_verify_s_answer(void) {
    native::sim_eeprom_erase();
    const uint16_t budgets[] = {1, 16, 48, 0xFFFF};
    Image cases[5];
    good(cases[0]);
    good(cases[1]);
    cases[1].b[0] = 'X';                   // kVmBadMagic
    good(cases[2]);
    cases[2].b[cases[2].code + 10] = 200;  // the JF past the code: kVmBadJump
    good(cases[3]);
    cases[3].b[cases[3].code + 24] = 0xEE;  // an unknown opcode
    good(cases[4]);
    put16(cases[4].b + 28 + 8, 26);        // B's .step moved into A's .exit: B's goto, kVmBadPlace
    for (const Image& im : cases) {
        const VmReason want = verify(im);
        for (uint16_t budget : budgets) {
            uint32_t calls;
            TEST_ASSERT_EQUAL_UINT(want, sliced(im, budget, calls));
            TEST_ASSERT_EQUAL_UINT(want, vm_verify_eeprom(100, im.len, kLayout, sizeof ram));
        }
    }
    TEST_ASSERT_EQUAL_UINT(kVmOk, verify(cases[0]));
    TEST_ASSERT_EQUAL_UINT(kVmBadMagic, verify(cases[1]));
    TEST_ASSERT_EQUAL_UINT(kVmBadJump, verify(cases[2]));
    TEST_ASSERT_EQUAL_UINT(kVmBadOpcode, verify(cases[3]));
    TEST_ASSERT_EQUAL_UINT(kVmBadPlace, verify(cases[4]));
    uint32_t calls;
    TEST_ASSERT_EQUAL_UINT(kVmOk, sliced(cases[0], 16, calls));
    TEST_ASSERT_TRUE(calls >= 8);  // the good image's ~150 reads, 16 a call or so
    TEST_ASSERT_EQUAL_UINT(kVmOk, sliced(cases[0], 0xFFFF, calls));
    TEST_ASSERT_EQUAL_UINT(1, calls);
}
#endif

FSW_TEST_MAIN([] {
    UNITY_BEGIN();
    RUN_TEST(test_the_good_image_verifies);
    RUN_TEST(test_header_rules);
    RUN_TEST(test_element_rules);
    RUN_TEST(test_local_rules);
    RUN_TEST(test_feature_rules);
    RUN_TEST(test_state_rules);
    RUN_TEST(test_window_rules);
    RUN_TEST(test_jump_rules);
    RUN_TEST(test_stack_rules);
    RUN_TEST(test_opcode_and_end_rules);
    RUN_TEST(test_place_rules);
    RUN_TEST(test_nesting_rule);
    RUN_TEST(test_typed_instruction_rules);
#if !defined(__AVR__)
    RUN_TEST(test_the_check_in_slices_gives_vm_verify_s_answer);
#endif
    (void)UNITY_END();
})
