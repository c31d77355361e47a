// Scenario: state-machine bookkeeping (spec 4.6): G must strictly increase,
// first-step entry, T in exact U64 arithmetic, transitions and self-loops.
#include "test_support.h"

using namespace fsw;

void setUp(void) {}
void tearDown(void) {}

static void test_first_step_enters_the_initial_state_with_T_zero(void) {
    Machine m = FSW_MACHINE_INIT(1);
    TEST_ASSERT_EQUAL(kOk, machine_begin_step(m, 0));
    TEST_ASSERT_EQUAL_UINT8(1, m.entering);
    TEST_ASSERT_EQUAL_UINT32(1, m.state);
    TEST_ASSERT_EQUAL_UINT64(0, machine_T(m));
    TEST_ASSERT_EQUAL(kOk, machine_begin_step(m, 10));
    TEST_ASSERT_EQUAL_UINT8(0, m.entering);
    TEST_ASSERT_EQUAL_UINT64(10, machine_T(m));
}

static void test_G_must_strictly_increase_and_a_refused_step_changes_nothing(void) {
    Machine m;
    machine_reset(m, 2);
    TEST_ASSERT_EQUAL(kOk, machine_begin_step(m, 100));
    TEST_ASSERT_EQUAL(kOk, machine_begin_step(m, 110));
    Machine before = m;
    TEST_ASSERT_EQUAL(kErrTime, machine_begin_step(m, 110));  // equal
    TEST_ASSERT_EQUAL(kErrTime, machine_begin_step(m, 50));   // backwards
    TEST_ASSERT_EQUAL_UINT64(before.last_g, m.last_g);
    TEST_ASSERT_EQUAL_UINT64(before.entry_g, m.entry_g);
    TEST_ASSERT_EQUAL_UINT64(machine_T(before), machine_T(m));
    TEST_ASSERT_EQUAL_UINT32(before.state, m.state);
    TEST_ASSERT_EQUAL_UINT8(before.pending, m.pending);
    TEST_ASSERT_EQUAL(kOk, machine_begin_step(m, 111));
    TEST_ASSERT_EQUAL_UINT64(11, machine_T(m));
}

static void test_transition_makes_the_next_step_the_targets_first(void) {
    Machine m = FSW_MACHINE_INIT(1);
    TEST_ASSERT_EQUAL(kOk, machine_begin_step(m, 0));
    TEST_ASSERT_EQUAL(kOk, machine_begin_step(m, 5));
    machine_transition(m, 3);
    TEST_ASSERT_EQUAL_UINT32(3, m.state);
    TEST_ASSERT_EQUAL(kOk, machine_begin_step(m, 7));
    TEST_ASSERT_EQUAL_UINT8(1, m.entering);
    TEST_ASSERT_EQUAL_UINT64(0, machine_T(m));
    TEST_ASSERT_EQUAL(kOk, machine_begin_step(m, 20));
    TEST_ASSERT_EQUAL_UINT8(0, m.entering);
    TEST_ASSERT_EQUAL_UINT64(13, machine_T(m));
    machine_transition(m, 3);  // to itself: restarts
    TEST_ASSERT_EQUAL(kOk, machine_begin_step(m, 21));
    TEST_ASSERT_EQUAL_UINT8(1, m.entering);
    TEST_ASSERT_EQUAL_UINT64(0, machine_T(m));
}

static void test_T_is_exact_beyond_what_R_can_hold(void) {
    Machine m = FSW_MACHINE_INIT(1);
    const uint64_t entry = (1ULL << 60) + 1;
    TEST_ASSERT_EQUAL(kOk, machine_begin_step(m, entry));
    TEST_ASSERT_EQUAL(kOk, machine_begin_step(m, entry + (1ULL << 40) + 6));
    TEST_ASSERT_EQUAL_UINT64((1ULL << 40) + 6, machine_T(m));
    TEST_ASSERT_EQUAL(kErrTime, machine_begin_step(m, entry + 3));
}

static void test_init_macro_equals_reset(void) {
    Machine a = FSW_MACHINE_INIT(4);
    Machine b;
    memset(&b, 0x5A, sizeof b);
    machine_reset(b, 4);
    TEST_ASSERT_EQUAL_UINT32(a.state, b.state);
    TEST_ASSERT_EQUAL_UINT8(a.pending, b.pending);
    TEST_ASSERT_EQUAL_UINT8(a.started, b.started);
    TEST_ASSERT_EQUAL_UINT64(a.entry_g, b.entry_g);
}

// What generated code reads T as: R(T) (machine_T_real, on AVR without the
// 64-bit conversion), `x = T` into integers (machine_T_int) and T against a
// constant (machine_T32) agree with the R semantics, bit for bit.
static void check_T(uint64_t t) {
    Machine m = FSW_MACHINE_INIT(1);
    m.entry_g = 0x0123456789ABCDEFULL;  // T = last_g - entry_g: a borrow between the halves for most t
    m.last_g = m.entry_g + t;
    const Real r = real_from_U64(t);
    ASSERT_REAL_SAME(r, machine_T_real(m));
    TEST_ASSERT_EQUAL_UINT32(U32_from_real(r), machine_T_int(m, 0xFFFFFFFFUL));
    TEST_ASSERT_EQUAL_UINT32(static_cast<uint32_t>(I32_from_real(r)), machine_T_int(m, 0x7FFFFFFFUL));
    TEST_ASSERT_EQUAL_UINT32(U16_from_real(r), machine_T_int(m, 0xFFFFUL));
    TEST_ASSERT_EQUAL_UINT32(static_cast<uint32_t>(I8_from_real(r)), machine_T_int(m, 0x7FUL));
    TEST_ASSERT_EQUAL_UINT32(t >= 0xFFFFFFFFULL ? 0xFFFFFFFFUL : static_cast<uint32_t>(t), machine_T32(m));
}

static void test_T_reads_as_R_and_converts_like_R(void) {
    const uint64_t edges[] = {0, 1, 127, 128, 255, 256, 65535, 65536, 0xFFFFFFULL, 0x1000000ULL, 0x1000001ULL,
                              0x1000002ULL, 0x1000003ULL, 0x2000006ULL, 0x7FFFFFBFULL, 0x7FFFFFC0ULL, 0x7FFFFFFFULL,
                              0x80000000ULL, 0xFFFFFF7FULL, 0xFFFFFF80ULL, 0xFFFFFF81ULL, 0xFFFFFFFEULL, 0xFFFFFFFFULL,
                              0x100000000ULL, 0x100000001ULL, 0x100000080ULL, 0x100000100ULL, 0x100000180ULL,
                              0x1000000FFULL, (1ULL << 40) + (1ULL << 16), (1ULL << 40) + (1ULL << 16) + 1,
                              (1ULL << 63) - 1, 1ULL << 63, ~0ULL};
    for (size_t i = 0; i < sizeof edges / sizeof edges[0]; ++i) check_T(edges[i]);
    uint64_t x = 0x9E3779B97F4A7C15ULL;
    for (int i = 0; i < 400; ++i) {  // every magnitude, and the bits around the rounding point
        x ^= x << 13; x ^= x >> 7; x ^= x << 17;
        const uint64_t t = x >> (i % 64);
        check_T(t);
        check_T(t | 0x80ULL);
        check_T(t & ~0xFFULL);
    }
}

// machine_begin (what generated step() calls: G from its element, S written
// on a state's first step; on AVR byte loops) does what machine_begin_step
// does, G equal, backwards, carrying across bytes and 2^32 included.
static void test_machine_begin_matches_machine_begin_step(void) {
    Machine a = FSW_MACHINE_INIT(2), b = FSW_MACHINE_INIT(2);
    uint8_t g[8], s[4] = {0, 0, 0, 0};
    uint64_t x = 0x0123456789ABCDEFULL, G = 0xFFFFFFF0ULL;
    for (int i = 0; i < 600; ++i) {
        x ^= x << 13; x ^= x >> 7; x ^= x << 17;
        switch (x % 6) {
            case 0: break;                                 // equal: refused
            case 1: G -= (x >> 8) % 300; break;            // backwards: refused
            case 2: G += 1; break;
            case 3: G += 0x100 - (G & 0xFF); break;        // carries into the next byte
            case 4: G += (x >> 16) % 100000; break;
            default: G += 1ULL << ((x >> 8) % 40); break;  // big jumps, past 2^32
        }
        if ((x >> 20) % 7 == 0) {
            machine_transition(a, 1 + (x >> 24) % 3);
            machine_transition(b, a.state);
        }
        memcpy(g, &G, 8);
        const Result ra = machine_begin(a, g, s);
        const Result rb = machine_begin_step(b, G);
        TEST_ASSERT_EQUAL(rb, ra);
        TEST_ASSERT_EQUAL_UINT64(b.last_g, a.last_g);
        TEST_ASSERT_EQUAL_UINT64(b.entry_g, a.entry_g);
        TEST_ASSERT_EQUAL_UINT64(machine_T(b), machine_T(a));
        TEST_ASSERT_EQUAL_UINT8(b.entering, a.entering);
        TEST_ASSERT_EQUAL_UINT8(b.pending, a.pending);
        TEST_ASSERT_EQUAL_UINT8(b.started, a.started);
        if (rb == kOk && b.entering != 0) {
            uint32_t written;
            memcpy(&written, s, 4);
            TEST_ASSERT_EQUAL_UINT32(b.state, written);
        }
    }
}

// Only a machine not yet started is taken for a zero Machine (state 0:
// FSW_MACHINE_INIT(1)), as machine_begin's C version on the host says; a
// started one's step skips that test (on AVR 16 cycles a step), and one in
// state 0 (past every state, as a VM's image may leave it) stays there.
static void test_only_a_machine_not_started_is_taken_for_a_zero_one(void) {
    Machine m = FSW_MACHINE_INIT(2);
    uint8_t g[8], s[4] = {0, 0, 0, 0};
    uint64_t G = 5;
    memcpy(g, &G, 8);
    TEST_ASSERT_EQUAL(kOk, machine_begin(m, g, s));
    m.state = 0;
    G = 6;
    memcpy(g, &G, 8);
    TEST_ASSERT_EQUAL(kOk, machine_begin(m, g, s));
    TEST_ASSERT_EQUAL_UINT32(0, m.state);
    TEST_ASSERT_EQUAL_UINT8(0, m.entering);
    TEST_ASSERT_EQUAL_UINT64(5, m.entry_g);
    TEST_ASSERT_EQUAL_UINT64(6, m.last_g);
}

// A generated machine task steps first and asks whether the clock ticked
// only when the step refused its G (autocode/emit/app.py): machine_begin
// refuses a G not above the last before it changes anything (the Machine's
// bytes and S alike), so the task's same-tick test then sees the last G,
// and finds it for an equal G only.
static void test_a_refused_machine_begin_changes_nothing_and_the_tick_tells_why(void) {
    Machine m = FSW_MACHINE_INIT(3);
    uint8_t g[8], s[4] = {0, 0, 0, 0};
    const uint64_t accepted[] = {1000, 0x1FF, 0x100000000ULL, 0x100000100ULL};
    uint64_t last = 0;
    for (size_t i = 0; i < sizeof accepted / sizeof accepted[0]; ++i) {
        const uint64_t G = i == 1 ? 1001 : accepted[i];  // (each above the one before)
        memcpy(g, &G, 8);
        TEST_ASSERT_EQUAL(kOk, machine_begin(m, g, s));
        last = G;
        const uint64_t refused[] = {last, last - 1, last - 0x100, last & ~0xFFULL};
        for (size_t k = 0; k < sizeof refused / sizeof refused[0]; ++k) {
            if (k != 0 && refused[k] == last) continue;
            Machine before;
            uint8_t s_before[4];
            memcpy(&before, &m, sizeof m);
            memcpy(s_before, s, 4);
            memcpy(g, &refused[k], 8);
            TEST_ASSERT_EQUAL(kErrTime, machine_begin(m, g, s));
            TEST_ASSERT_EQUAL_MEMORY(&before, &m, sizeof m);
            TEST_ASSERT_EQUAL_MEMORY(s_before, s, 4);
            TEST_ASSERT_EQUAL(k == 0, machine_same_tick(m, g));  // the same tick: only the equal G
        }
        if (i == 1) machine_transition(m, 2);  // a pending entry, refused alike
    }
}

// Generated machines are zero-initialised (.bss): machine_begin takes a zero
// Machine for FSW_MACHINE_INIT(1).
static void test_a_zero_machine_begins_in_state_1(void) {
    Machine z;
    memset(&z, 0, sizeof z);
    Machine a = FSW_MACHINE_INIT(1);
    uint8_t s[4] = {0xAA, 0xAA, 0xAA, 0xAA};
    const uint64_t gs[] = {7, 7, 9, 30};
    for (size_t i = 0; i < sizeof gs / sizeof gs[0]; ++i) {
        uint8_t g[8];
        memcpy(g, &gs[i], 8);
        TEST_ASSERT_EQUAL(machine_begin_step(a, gs[i]), machine_begin(z, g, s));
        TEST_ASSERT_EQUAL_UINT32(a.state, z.state);
        TEST_ASSERT_EQUAL_UINT8(a.entering, z.entering);
        TEST_ASSERT_EQUAL_UINT8(a.pending, z.pending);
        TEST_ASSERT_EQUAL_UINT64(machine_T(a), machine_T(z));
        TEST_ASSERT_EQUAL_UINT64(a.entry_g, z.entry_g);
    }
    uint32_t written;
    memcpy(&written, s, 4);
    TEST_ASSERT_EQUAL_UINT32(1, written);  // S written on the first step
}

static void run(void) {
    UNITY_BEGIN();
    RUN_TEST(test_first_step_enters_the_initial_state_with_T_zero);
    RUN_TEST(test_G_must_strictly_increase_and_a_refused_step_changes_nothing);
    RUN_TEST(test_transition_makes_the_next_step_the_targets_first);
    RUN_TEST(test_T_is_exact_beyond_what_R_can_hold);
    RUN_TEST(test_init_macro_equals_reset);
    RUN_TEST(test_T_reads_as_R_and_converts_like_R);
    RUN_TEST(test_machine_begin_matches_machine_begin_step);
    RUN_TEST(test_a_zero_machine_begins_in_state_1);
    RUN_TEST(test_a_refused_machine_begin_changes_nothing_and_the_tick_tells_why);
    RUN_TEST(test_only_a_machine_not_started_is_taken_for_a_zero_one);
    (void)UNITY_END();
}

FSW_TEST_MAIN(run)
