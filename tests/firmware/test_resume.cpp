// Scenario: resuming a flight after a reset (fsw_resume.h, docs/safety.md):
// the kept RAM copied into two banks with a sequence number and a check,
// copied back after a brown-out or a watchdog reset only, from the newest
// whole bank; a save cut short leaves the other bank to resume from.
#include "test_support.h"

using namespace fsw;

void setUp(void) {}
void tearDown(void) {}

static const uint8_t kPowerOn = 0x01, kExternal = 0x02, kBrownOut = 0x04, kWatchdog = 0x08;

// What an application keeps: two pieces of RAM.
static uint8_t a[5];
static uint8_t b[3];
static const ResumeSpan kSpans[2] FSW_FLASH = {{a, sizeof a}, {b, sizeof b}};
static uint8_t banks[2 * (sizeof a + sizeof b + 3)];
static const ResumeConfig kConfig FSW_FLASH = {kSpans, banks, 0x12345678UL, sizeof a + sizeof b, 2, 0, 0};
static const ResumeConfig kOther FSW_FLASH = {kSpans, banks, 0x12345679UL, sizeof a + sizeof b, 2, 0, 0};

static void fill(uint8_t v) {
    for (uint8_t i = 0; i < sizeof a; ++i) a[i] = static_cast<uint8_t>(v + i);
    for (uint8_t i = 0; i < sizeof b; ++i) b[i] = static_cast<uint8_t>(v + 0x40 + i);
}
static void clear() {  // what the C runtime does to .bss at boot
    memset(a, 0, sizeof a);
    memset(b, 0, sizeof b);
}
static bool holds(uint8_t v) {
    for (uint8_t i = 0; i < sizeof a; ++i) if (a[i] != static_cast<uint8_t>(v + i)) return false;
    for (uint8_t i = 0; i < sizeof b; ++i) if (b[i] != static_cast<uint8_t>(v + 0x40 + i)) return false;
    return true;
}
// A first boot: banks of whatever RAM held at power-on.
static void power_on(Resume& r) {
    for (uint16_t i = 0; i < sizeof banks; ++i) banks[i] = static_cast<uint8_t>(i * 37u + 11u);
    clear();
    TEST_ASSERT_FALSE(resume_begin(r, &kConfig, kPowerOn));
}

static void test_a_brown_out_resumes_the_last_save(void) {
    Resume r;
    power_on(r);
    fill(1);
    resume_save(r);
    fill(2);
    resume_save(r);
    fill(3);  // changed after the last save: lost with the reset
    clear();
    TEST_ASSERT_TRUE(resume_begin(r, &kConfig, kBrownOut));
    TEST_ASSERT_TRUE(holds(2));
}

static void test_a_watchdog_reset_resumes_and_saves_go_on(void) {
    Resume r;
    power_on(r);
    for (uint8_t k = 1; k <= 9; ++k) {  // odd and even banks alike
        fill(k);
        resume_save(r);
        clear();
        TEST_ASSERT_TRUE(resume_begin(r, &kConfig, kWatchdog));
        TEST_ASSERT_TRUE(holds(k));
    }
}

static void test_power_on_and_external_resets_start_fresh(void) {
    const uint8_t fresh[] = {kPowerOn, kExternal, 0, kBrownOut | kExternal, kWatchdog | kPowerOn};
    for (uint8_t k = 0; k < sizeof fresh; ++k) {
        Resume r;
        power_on(r);
        fill(7);
        resume_save(r);
        clear();
        TEST_ASSERT_FALSE(resume_begin(r, &kConfig, fresh[k]));
        TEST_ASSERT_EQUAL_UINT8(0, a[0]);  // nothing copied back
        TEST_ASSERT_EQUAL_UINT8(0, b[2]);
        // and the banks from before the fresh start are never taken later
        TEST_ASSERT_EQUAL_INT8(-1, resume_newest(&kConfig));
        TEST_ASSERT_FALSE(resume_begin(r, &kConfig, kBrownOut));
    }
}

static void test_nothing_saved_yet_starts_fresh(void) {
    Resume r;
    power_on(r);
    TEST_ASSERT_FALSE(resume_begin(r, &kConfig, kBrownOut));  // reset before the first save
    TEST_ASSERT_EQUAL_UINT8(0, a[0]);
}

static void test_another_firmwares_banks_are_not_taken(void) {
    Resume r;
    power_on(r);
    fill(4);
    resume_save(r);
    clear();
    TEST_ASSERT_FALSE(resume_begin(r, &kOther, kBrownOut));
    TEST_ASSERT_EQUAL_UINT8(0, a[0]);
}

// A reset part way through a save: the bank being written is invalid from
// its first byte on, and the other holds the save before.
static void test_a_save_cut_short_resumes_the_one_before(void) {
    const uint16_t bank = sizeof a + sizeof b + 3;
    for (uint16_t cut = 0; cut <= bank; ++cut) {
        Resume r;
        power_on(r);
        fill(5);
        resume_save(r);
        fill(6);
        uint8_t before[sizeof banks];
        memcpy(before, banks, sizeof banks);
        resume_save(r);  // the whole save; then the bank as it was `cut` bytes in
        const uint8_t w = static_cast<uint8_t>(r.next ^ 1u);  // the bank just written
        uint8_t* const at = banks + w * bank;
        uint8_t torn[sizeof banks];
        memcpy(torn, before, sizeof banks);
        // the save's order: the check's first byte flipped first, then the bytes in order
        torn[w * bank + bank - 2] = static_cast<uint8_t>(~before[w * bank + bank - 2]);
        for (uint16_t i = 0; i < cut; ++i) torn[w * bank + i] = at[i];  // bytes, sequence number, check
        memcpy(banks, torn, sizeof banks);
        clear();
        TEST_ASSERT_TRUE(resume_begin(r, &kConfig, kBrownOut));
        if (cut == bank) {
            TEST_ASSERT_TRUE(holds(6));
        } else if (cut == bank - 1) {  // the check's second byte still the old one: whole only if it matched
            TEST_ASSERT_TRUE(holds(5) || holds(6));
        } else {
            TEST_ASSERT_TRUE(holds(5));
        }
    }
}

static void test_a_flipped_bit_is_refused(void) {
    Resume r;
    power_on(r);
    fill(8);
    resume_save(r);
    const int8_t k = resume_newest(&kConfig);
    TEST_ASSERT_TRUE(k >= 0);
    for (uint16_t bit = 0; bit < 8u * (sizeof a + sizeof b + 3); ++bit) {
        uint8_t* const p = banks + k * (sizeof a + sizeof b + 3) + bit / 8;
        *p = static_cast<uint8_t>(*p ^ (1u << (bit % 8)));
        TEST_ASSERT_EQUAL_INT8(-1, resume_newest(&kConfig));  // the other bank was never written
        *p = static_cast<uint8_t>(*p ^ (1u << (bit % 8)));
    }
    TEST_ASSERT_EQUAL_INT8(k, resume_newest(&kConfig));
}

// Fletcher-16's one blind spot among two-bit errors: the same bit of two
// bytes 255 apart, set in one and cleared in the other (+2^k and -2^k:
// 256 = 1 mod 255, so both sums stay). Every other pair of flipped bits
// of a bank's bytes and sequence number is refused; a bank of up to 254
// bytes has no such pair (natively: a bank of 300 bytes, every pair of
// places and both directions; the simulated ATmega328P's 2 KB are full).
#if !defined(__AVR__)
static uint8_t big[300];
static const ResumeSpan kBigSpans[1] FSW_FLASH = {{big, sizeof big}};
static uint8_t big_banks[2 * (sizeof big + 3)];
static const ResumeConfig kBig FSW_FLASH = {kBigSpans, big_banks, 0x0BADF00DUL, sizeof big, 1, 0, 0};

static void test_two_bit_errors_pass_only_255_bytes_apart(void) {
    Resume r;
    memset(big_banks, 0x33, sizeof big_banks);
    TEST_ASSERT_FALSE(resume_begin(r, &kBig, kPowerOn));
    for (uint16_t i = 0; i < sizeof big; ++i) big[i] = static_cast<uint8_t>(i * 7u + 3u);
    resume_save(r);
    const int8_t k = resume_newest(&kBig);
    TEST_ASSERT_TRUE(k >= 0);
    uint8_t* const bank = big_banks + k * (sizeof big + 3);
    uint16_t passed = 0;
    for (uint16_t i = 0; i <= sizeof big; ++i) {  // the bytes and the sequence number
        for (uint16_t j = static_cast<uint16_t>(i + 1u); j <= sizeof big; ++j) {
            const uint8_t m = static_cast<uint8_t>(1u << (i % 8u));
            const bool opposite = ((bank[i] ^ bank[j]) & m) != 0;
            bank[i] = static_cast<uint8_t>(bank[i] ^ m);
            bank[j] = static_cast<uint8_t>(bank[j] ^ m);
            const int8_t got = resume_newest(&kBig);
            bank[i] = static_cast<uint8_t>(bank[i] ^ m);
            bank[j] = static_cast<uint8_t>(bank[j] ^ m);
            if (j - i == 255u && opposite) {
                TEST_ASSERT_EQUAL_INT8(k, got);
                ++passed;
            } else {
                TEST_ASSERT_EQUAL_INT8(-1, got);
            }
        }
    }
    TEST_ASSERT_TRUE(passed > 0);
    TEST_ASSERT_EQUAL_INT8(k, resume_newest(&kBig));
}
#endif

// Sequence numbers wrap: the newer of two whole banks is taken across 255 -> 0.
static void test_the_sequence_number_wraps(void) {
    Resume r;
    power_on(r);
    for (uint16_t k = 0; k < 600; ++k) {
        fill(static_cast<uint8_t>(k));
        resume_save(r);
        if (k % 61 == 0 || (k > 250 && k < 260)) {
            clear();
            TEST_ASSERT_TRUE(resume_begin(r, &kConfig, kBrownOut));
            TEST_ASSERT_TRUE(holds(static_cast<uint8_t>(k)));
        }
    }
}

// A strided span (resume_strided): one byte of each record of an array,
// kept and copied back in order, and the record's other bytes left alone.
struct Rec {
    uint8_t before, kept, after;
};
static Rec recs[5];
static uint8_t c[2];
static const ResumeSpan kStridedSpans[3] FSW_FLASH = {
    {c, 1}, {&recs[0].kept, resume_strided(5, sizeof(Rec))}, {c + 1, 1}};
static const uint16_t kStridedSize = 1 + resume_span_size(resume_strided(5, sizeof(Rec))) + 1;
static uint8_t strided_banks[2 * (kStridedSize + 3)];
static const ResumeConfig kStrided FSW_FLASH = {kStridedSpans, strided_banks, 0x0BADF00DUL, kStridedSize, 3, 0, 0};

static void fill_recs(uint8_t v) {
    for (uint8_t i = 0; i < 5; ++i) {
        recs[i].before = static_cast<uint8_t>(v + 0x10 + i);
        recs[i].kept = static_cast<uint8_t>(v + i);
        recs[i].after = static_cast<uint8_t>(v + 0x20 + i);
    }
    c[0] = static_cast<uint8_t>(v + 0x30);
    c[1] = static_cast<uint8_t>(v + 0x31);
}

static void test_a_strided_span_keeps_a_byte_of_each_record(void) {
    TEST_ASSERT_EQUAL_UINT16(7, kStridedSize);
    Resume r;
    for (uint16_t i = 0; i < sizeof strided_banks; ++i) strided_banks[i] = static_cast<uint8_t>(i * 29u + 3u);
    TEST_ASSERT_FALSE(resume_begin(r, &kStrided, kPowerOn));
    fill_recs(0x40);
    resume_save(r);
    fill_recs(0x80);
    resume_save(r);
    // the bank: c[0], the five kept bytes in order, c[1], then the sequence number
    const int8_t k = resume_newest(&kStrided);
    TEST_ASSERT_TRUE(k >= 0);
    const uint8_t* bank = strided_banks + k * (kStridedSize + 3);
    TEST_ASSERT_EQUAL_UINT8(0xB0, bank[0]);
    for (uint8_t i = 0; i < 5; ++i) TEST_ASSERT_EQUAL_UINT8(0x80 + i, bank[1 + i]);
    TEST_ASSERT_EQUAL_UINT8(0xB1, bank[6]);
    fill_recs(0xC0);  // after the last save: the kept bytes go back to it, the others stay
    TEST_ASSERT_TRUE(resume_begin(r, &kStrided, kBrownOut));
    for (uint8_t i = 0; i < 5; ++i) {
        TEST_ASSERT_EQUAL_UINT8(0x80 + i, recs[i].kept);
        TEST_ASSERT_EQUAL_UINT8(0xD0 + i, recs[i].before);
        TEST_ASSERT_EQUAL_UINT8(0xE0 + i, recs[i].after);
    }
    TEST_ASSERT_EQUAL_UINT8(0xB0, c[0]);
    TEST_ASSERT_EQUAL_UINT8(0xB1, c[1]);
    // every bit of the bank is in the check
    for (uint16_t bit = 0; bit < 8u * (kStridedSize + 3); ++bit) {
        uint8_t* const p = strided_banks + k * (kStridedSize + 3) + bit / 8;
        *p = static_cast<uint8_t>(*p ^ (1u << (bit % 8)));
        TEST_ASSERT_NOT_EQUAL(k, resume_newest(&kStrided));
        *p = static_cast<uint8_t>(*p ^ (1u << (bit % 8)));
    }
    TEST_ASSERT_EQUAL_INT8(k, resume_newest(&kStrided));
}

// Spans of every size the save's loop handles apart: 0..3 bytes before
// its turns of eight, an odd or an even number of quads, none.
static uint8_t sized[183];
static const ResumeSpan kSizedSpans[15] FSW_FLASH = {{sized + 0, 1}, {sized + 1, 2}, {sized + 3, 3}, {sized + 6, 4}, {sized + 10, 5}, {sized + 15, 6}, {sized + 21, 7}, {sized + 28, 8}, {sized + 36, 9}, {sized + 45, 12}, {sized + 57, 13}, {sized + 70, 17}, {sized + 87, 31}, {sized + 118, 32}, {sized + 150, 33}};
static uint8_t sized_banks[2 * (183 + 3)];
static const ResumeConfig kSized FSW_FLASH = {kSizedSpans, sized_banks, 0x5151D00DUL, 183, 15, 0, 0};

static void test_spans_of_every_size_are_kept_whole(void) {
    Resume r;
    for (uint16_t i = 0; i < sizeof sized_banks; ++i) sized_banks[i] = static_cast<uint8_t>(i * 13u + 5u);
    TEST_ASSERT_FALSE(resume_begin(r, &kSized, kPowerOn));
    for (uint8_t k = 1; k <= 3; ++k) {  // both banks, then the first again
        for (uint16_t i = 0; i < sizeof sized; ++i) sized[i] = static_cast<uint8_t>(i * 7u + k);
        resume_save(r);
        const int8_t b = resume_newest(&kSized);
        TEST_ASSERT_TRUE(b >= 0);
        TEST_ASSERT_EQUAL_UINT8_ARRAY(sized, sized_banks + b * (sizeof sized + 3), sizeof sized);
        memset(sized, 0, sizeof sized);
        TEST_ASSERT_TRUE(resume_begin(r, &kSized, kWatchdog));
        for (uint16_t i = 0; i < sizeof sized; ++i) TEST_ASSERT_EQUAL_UINT8(static_cast<uint8_t>(i * 7u + k), sized[i]);
    }
}

// Watched spans (ResumeWatch): a span whose writer says when it changed is
// copied while it changes and left in the banks once both hold it; every
// bank is the one a save copying everything writes, bit for bit (its check
// too), whatever the seed and the spans' sizes (natively 255 bytes: n x a
// is 0 mod 255), and resumes to the state saved.
static uint8_t w_head[3];
#if defined(__AVR__)
static uint8_t w_win[40];  // the simulated ATmega328P's 2 KB
#else
static uint8_t w_win[255];
#endif
static uint8_t w_tail[2];
static uint8_t w_changed, w_state[3];
static uint8_t w_banks[2 * (sizeof w_head + sizeof w_win + sizeof w_tail + 3)];
static uint8_t w_plain_banks[sizeof w_banks];
static const uint16_t kWSize = sizeof w_head + sizeof w_win + sizeof w_tail;
static const ResumeSpan kWSpans[3] FSW_FLASH = {{w_head, sizeof w_head}, {w_win, sizeof w_win}, {w_tail, sizeof w_tail}};
static const ResumeWatch kWatch[1] FSW_FLASH = {{1, &w_changed, w_state}};
static const ResumeConfig kWatched0 FSW_FLASH = {kWSpans, w_banks, 0x00000000UL, kWSize, 3, kWatch, 1};
static const ResumeConfig kPlain0 FSW_FLASH = {kWSpans, w_plain_banks, 0x00000000UL, kWSize, 3, 0, 0};
static const ResumeConfig kWatched1 FSW_FLASH = {kWSpans, w_banks, 0xA5C3F00FUL, kWSize, 3, kWatch, 1};
static const ResumeConfig kPlain1 FSW_FLASH = {kWSpans, w_plain_banks, 0xA5C3F00FUL, kWSize, 3, 0, 0};

static void test_a_watched_span_saves_the_banks_a_full_save_does(void) {
    const ResumeConfig* const watched[2] = {&kWatched0, &kWatched1};
    const ResumeConfig* const plain[2] = {&kPlain0, &kPlain1};
    for (uint8_t cfg = 0; cfg < 2; ++cfg) {  // a zero seed (the sums 0 until a non-zero byte), and another
        for (uint8_t fill = 0; fill < 2; ++fill) {  // zero bytes before the watched span, and others
            Resume r, p;
            memset(w_banks, 0x5A, sizeof w_banks);
            memset(w_plain_banks, 0x5A, sizeof w_plain_banks);
            memset(w_head, fill ? 0x81 : 0, sizeof w_head);
            memset(w_win, 0, sizeof w_win);
            memset(w_tail, 0, sizeof w_tail);
            memset(w_state, 0x02, sizeof w_state);  // as a test before left it: the start copies again
            w_changed = 0;
            TEST_ASSERT_FALSE(resume_begin(r, watched[cfg], kPowerOn));
            TEST_ASSERT_FALSE(resume_begin(p, plain[cfg], kPowerOn));
            for (uint16_t k = 0; k < 40; ++k) {
                if (k % 7 == 3 || k == 20) {  // the watched span changes (twice in a row at 20, 21)
                    w_win[(k * 37u) % sizeof w_win] = static_cast<uint8_t>(k * 11u + 1u);
                    w_changed = 1;
                }
                if (k == 21) {
                    w_win[0] = 0xFF;
                    w_changed = 1;
                }
                if (k % 5 == 0) w_tail[k % 2] = static_cast<uint8_t>(k);  // unwatched spans change
                if (fill && k % 3 == 0) w_head[1] = static_cast<uint8_t>(w_head[1] + 1u);
                resume_save(r);
                resume_save(p);
                TEST_ASSERT_EQUAL_UINT8_ARRAY(w_plain_banks, w_banks, sizeof w_banks);
            }
            const uint8_t want = w_win[0];
            w_win[0] = static_cast<uint8_t>(want + 1u);  // after the last save: not kept
            TEST_ASSERT_TRUE(resume_begin(r, watched[cfg], kBrownOut));
            TEST_ASSERT_EQUAL_UINT8(want, w_win[0]);
        }
    }
}

// A watched span's writer that says nothing: the banks keep its bytes of
// the save that last copied it (what a writer must set `changed` for).
static void test_a_watched_span_is_left_until_it_is_said_to_change(void) {
    Resume r;
    memset(w_win, 0, sizeof w_win);
    w_changed = 0;
    TEST_ASSERT_FALSE(resume_begin(r, &kWatched1, kPowerOn));
    resume_save(r);
    resume_save(r);
    w_win[5] = 9;  // not said
    resume_save(r);
    resume_save(r);
    TEST_ASSERT_TRUE(resume_begin(r, &kWatched1, kBrownOut));
    TEST_ASSERT_EQUAL_UINT8(0, w_win[5]);
    w_win[5] = 9;
    w_changed = 1;  // said
    resume_save(r);
    TEST_ASSERT_TRUE(resume_begin(r, &kWatched1, kBrownOut));
    TEST_ASSERT_EQUAL_UINT8(9, w_win[5]);
}

static void run(void) {
    UNITY_BEGIN();
    RUN_TEST(test_a_brown_out_resumes_the_last_save);
    RUN_TEST(test_a_watchdog_reset_resumes_and_saves_go_on);
    RUN_TEST(test_power_on_and_external_resets_start_fresh);
    RUN_TEST(test_nothing_saved_yet_starts_fresh);
    RUN_TEST(test_another_firmwares_banks_are_not_taken);
    RUN_TEST(test_a_save_cut_short_resumes_the_one_before);
    RUN_TEST(test_a_flipped_bit_is_refused);
#if !defined(__AVR__)
    RUN_TEST(test_two_bit_errors_pass_only_255_bytes_apart);
#endif
    RUN_TEST(test_the_sequence_number_wraps);
    RUN_TEST(test_a_strided_span_keeps_a_byte_of_each_record);
    RUN_TEST(test_spans_of_every_size_are_kept_whole);
    RUN_TEST(test_a_watched_span_saves_the_banks_a_full_save_does);
    RUN_TEST(test_a_watched_span_is_left_until_it_is_said_to_change);
    (void)UNITY_END();
}

FSW_TEST_MAIN(run)
