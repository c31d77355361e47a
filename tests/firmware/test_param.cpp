// Scenario: the parameter g_store (docs/parameters.md) on the host PSL's
// EEPROM model: boot from the newest valid bank, else the other, else the
// defaults; SET all or nothing, refused out of range (NaN too), for an
// unknown id, or outside the declaring machine's allowed states; SAVE into
// the other bank in the background; a load staged into the other bank and
// committed whole after a CRC check; BUSY while a bank is written (a load
// left open holds neither SET nor SAVE); and a
// power cut after every write of a save or a load leaves the old set or the
// new one, never a mix.
#include "test_support.h"

#include "fsw_crc.h"
#include "psl_native.h"

using namespace fsw;

// sv: U32 S at 0. Parameters: F32 MAIN_ALT [50, 3000] in states 1 and 2;
// U32 BACKUP [2000, 60000] in state 1; bool BEEP in state 1; I16 TRIM
// [-100, 100] in states 1 and 2. Value block: 4 + 4 + 1 + 2 = 11 bytes.
static uint8_t sv[4];
static uint8_t val[11];
static uint8_t staged_bits[1];
static ParamStore g_store;

static const ParamDef kDefs[4] FSW_FLASH = {
    {val + 0, 0, 0, kF32, 0}, {val + 4, 4, 8, kU32, 1}, {val + 8, 8, 0, kBool, 1}, {val + 9, 9, 16, kI16, 0}};
static const ParamWhen kWhens[2] FSW_FLASH = {{0, 20, 1}, {0, 21, 1}};
static const uint8_t kPool[22] FSW_FLASH = {
    0x00, 0x00, 0x48, 0x42, 0x00, 0x80, 0x3b, 0x45,  // 50.0f, 3000.0f
    0xd0, 0x07, 0x00, 0x00, 0x60, 0xea, 0x00, 0x00,  // 2000, 60000
    0x9c, 0xff, 0x64, 0x00,                          // -100, 100
    0x03, 0x01};                                     // states {1, 2}, {1}
static const uint8_t kDefaults[11] FSW_FLASH = {0x00, 0x00, 0x16, 0x43,  // 150.0f
                                                0x10, 0x27, 0x00, 0x00,  // 10000
                                                0x01,                    // true
                                                0xfb, 0xff};             // -5
static const ParamConfig kConfig FSW_FLASH = {kDefs, kWhens, kPool, kDefaults, staged_bits, sv,
                                              0x12345678UL, 11, 0, 4, false};
static const ParamConfig kOtherTable FSW_FLASH = {kDefs, kWhens, kPool, kDefaults, staged_bits, sv,
                                                  0x12345679UL, 11, 0, 4, false};
static const uint16_t kBank = kParamHeader + 11;

static void set_state(uint32_t s) { memcpy(sv, &s, 4); }
static void boot(const ParamConfig* c = &kConfig) {
    memset(val, 0xAA, sizeof val);
    param_begin(g_store, c);
}
static void drain() {
    for (int i = 0; i < 1000 && (g_store.source & kParamWriting) && g_store.w_job != 0; ++i) param_poll(g_store);
}
static float f32_at(uint16_t off) { float f; memcpy(&f, val + off, 4); return f; }
static uint32_t u32_at(uint16_t off) { uint32_t u; memcpy(&u, val + off, 4); return u; }
static int16_t i16_at(uint16_t off) { int16_t v; memcpy(&v, val + off, 2); return v; }

// (id, value) entries
static uint8_t args[32];
static uint8_t nargs;
static void entry_f32(uint8_t id, float f) { args[nargs++] = id; memcpy(args + nargs, &f, 4); nargs += 4; }
static void entry_u32(uint8_t id, uint32_t u) { args[nargs++] = id; memcpy(args + nargs, &u, 4); nargs += 4; }
static void entry_i16(uint8_t id, int16_t v) { args[nargs++] = id; memcpy(args + nargs, &v, 2); nargs += 2; }
static void entry_bool(uint8_t id, uint8_t b) { args[nargs++] = id; args[nargs++] = b; }

static uint8_t set(uint8_t& bad) {
    const uint8_t st = param_set(g_store, args, nargs, bad);
    nargs = 0;
    return st;
}

void setUp(void) {
    native::sim_reset();
    native::sim_eeprom_erase();
    set_state(1);
    nargs = 0;
    boot();
}
void tearDown(void) {}

static void test_an_erased_eeprom_boots_the_defaults(void) {
    TEST_ASSERT_EQUAL_HEX8(kParamDefaults, g_store.source);
    TEST_ASSERT_EQUAL(0, g_store.seq);
    TEST_ASSERT_EQUAL_FLOAT(150.0f, f32_at(0));
    TEST_ASSERT_EQUAL_UINT32(10000, u32_at(4));
    TEST_ASSERT_EQUAL(1, val[8]);
    TEST_ASSERT_EQUAL_INT16(-5, i16_at(9));
    TEST_ASSERT_EQUAL_HEX16(crc16(val, 11), param_crc(g_store));
}

static void test_set_then_save_then_reboot_takes_bank_a_then_bank_b(void) {
    uint8_t bad;
    entry_f32(0, 200.0f);
    entry_i16(3, 7);
    TEST_ASSERT_EQUAL(kParamOk, set(bad));
    TEST_ASSERT_EQUAL_FLOAT(200.0f, f32_at(0));
    TEST_ASSERT_EQUAL_HEX8(kParamDefaults | kParamDirty, g_store.source);
    TEST_ASSERT_EQUAL(kParamOk, param_save(g_store));
    TEST_ASSERT_EQUAL_HEX8(kParamDefaults | kParamDirty | kParamWriting, g_store.source);
    drain();
    TEST_ASSERT_EQUAL_HEX8(kParamBankA, g_store.source);
    TEST_ASSERT_EQUAL(1, g_store.seq);
    // the bank as docs/parameters.md lays it out
    const uint8_t* ee = native::sim_eeprom();
    TEST_ASSERT_EQUAL_HEX8(kParamMagic, ee[0]);
    TEST_ASSERT_EQUAL_HEX8(1, ee[1]);
    TEST_ASSERT_EQUAL_HEX8(0x78, ee[3]);
    TEST_ASSERT_EQUAL_MEMORY(val, ee + kParamHeader, 11);
    boot();
    TEST_ASSERT_EQUAL_HEX8(kParamBankA, g_store.source);
    TEST_ASSERT_EQUAL_FLOAT(200.0f, f32_at(0));
    TEST_ASSERT_EQUAL_INT16(7, i16_at(9));
    entry_u32(1, 30000);
    TEST_ASSERT_EQUAL(kParamOk, set(bad));
    TEST_ASSERT_EQUAL(kParamOk, param_save(g_store));
    drain();
    TEST_ASSERT_EQUAL_HEX8(kParamBankB, g_store.source);
    TEST_ASSERT_EQUAL(2, g_store.seq);
    boot();
    TEST_ASSERT_EQUAL_HEX8(kParamBankB, g_store.source);
    TEST_ASSERT_EQUAL_UINT32(30000, u32_at(4));
    TEST_ASSERT_EQUAL_FLOAT(200.0f, f32_at(0));
    // setting a value back to the bank's is not a change
    entry_u32(1, 30001);
    TEST_ASSERT_EQUAL(kParamOk, set(bad));
    TEST_ASSERT_EQUAL_HEX8(kParamBankB | kParamDirty, g_store.source);
    entry_u32(1, 30000);
    TEST_ASSERT_EQUAL(kParamOk, set(bad));
    TEST_ASSERT_EQUAL_HEX8(kParamBankB, g_store.source);
}

static void save_value(float alt) {
    uint8_t bad;
    entry_f32(0, alt);
    TEST_ASSERT_EQUAL(kParamOk, set(bad));
    TEST_ASSERT_EQUAL(kParamOk, param_save(g_store));
    drain();
}

static void test_a_bad_bank_falls_back_to_the_other_then_to_the_defaults(void) {
    save_value(300.0f);  // bank A, seq 1
    save_value(400.0f);  // bank B, seq 2
    uint8_t* ee = native::sim_eeprom();
    ee[kBank + kParamHeader + 2] ^= 0x01;  // a value byte of bank B: its CRC fails
    boot();
    TEST_ASSERT_EQUAL_HEX8(kParamBankA, g_store.source);
    TEST_ASSERT_EQUAL_FLOAT(300.0f, f32_at(0));
    ee[0] = 0x00;  // bank A not whole
    boot();
    TEST_ASSERT_EQUAL_HEX8(kParamDefaults, g_store.source);
    TEST_ASSERT_EQUAL_FLOAT(150.0f, f32_at(0));
}

static void test_banks_of_another_table_are_not_taken(void) {
    save_value(300.0f);
    boot(&kOtherTable);
    TEST_ASSERT_EQUAL_HEX8(kParamDefaults, g_store.source);
    TEST_ASSERT_EQUAL_FLOAT(150.0f, f32_at(0));
}

static void test_the_newer_bank_wins_across_the_sequence_wrap(void) {
    save_value(300.0f);
    save_value(400.0f);
    uint8_t* ee = native::sim_eeprom();
    // rewrite both banks' sequence numbers as 0xFFFF (A) and 0x0000 (B), CRCs fixed up
    for (uint8_t b = 0; b < 2; ++b) {
        uint8_t* bank = ee + b * kBank;
        bank[1] = bank[2] = b ? 0x00 : 0xFF;
        uint16_t crc = crc16(bank + 1, 6);
        crc = crc16(bank + kParamHeader, 11, crc);
        bank[7] = static_cast<uint8_t>(crc >> 8);
        bank[8] = static_cast<uint8_t>(crc);
    }
    boot();
    TEST_ASSERT_EQUAL_HEX8(kParamBankB, g_store.source);
    TEST_ASSERT_EQUAL_FLOAT(400.0f, f32_at(0));
}

static void test_refusals_change_nothing(void) {
    uint8_t bad;
    entry_f32(0, 200.0f);
    entry_f32(0, 3000.5f);  // over MAX
    TEST_ASSERT_EQUAL(kParamOutOfRange, set(bad));
    TEST_ASSERT_EQUAL(0, bad);
    TEST_ASSERT_EQUAL_FLOAT(150.0f, f32_at(0));  // the valid entry before it was not applied
    const uint32_t nan_bits = 0x7FC00000u, neg_nan = 0xFFC00000u;
    float nan;
    memcpy(&nan, &nan_bits, 4);
    entry_f32(0, nan);
    TEST_ASSERT_EQUAL(kParamOutOfRange, set(bad));
    memcpy(&nan, &neg_nan, 4);
    entry_f32(0, nan);
    TEST_ASSERT_EQUAL(kParamOutOfRange, set(bad));
    entry_bool(2, 2);
    TEST_ASSERT_EQUAL(kParamOutOfRange, set(bad));
    TEST_ASSERT_EQUAL(2, bad);
    entry_i16(3, -101);
    TEST_ASSERT_EQUAL(kParamOutOfRange, set(bad));
    entry_i16(3, -100);
    TEST_ASSERT_EQUAL(kParamOk, set(bad));
    entry_u32(1, 1999);
    TEST_ASSERT_EQUAL(kParamOutOfRange, set(bad));
    entry_u32(9, 1);
    TEST_ASSERT_EQUAL(kParamNoParam, set(bad));
    TEST_ASSERT_EQUAL(9, bad);
    args[0] = 0;  // an entry cut short
    nargs = 3;
    TEST_ASSERT_EQUAL(kParamBadLength, set(bad));
    nargs = 0;
    TEST_ASSERT_EQUAL(kParamBadLength, set(bad));
    entry_f32(0, -0.0f);  // -0 is 0: below 50
    TEST_ASSERT_EQUAL(kParamOutOfRange, set(bad));
}

static void test_a_change_needs_an_allowed_state(void) {
    uint8_t bad;
    set_state(2);
    entry_f32(0, 250.0f);  // MAIN_ALT: states 1 and 2
    TEST_ASSERT_EQUAL(kParamOk, set(bad));
    entry_u32(1, 20000);  // BACKUP: state 1 only
    TEST_ASSERT_EQUAL(kParamWrongState, set(bad));
    TEST_ASSERT_EQUAL(1, bad);
    entry_u32(1, 10000);  // its value already: not a change
    TEST_ASSERT_EQUAL(kParamOk, set(bad));
    set_state(0);  // before the first step
    entry_f32(0, 260.0f);
    TEST_ASSERT_EQUAL(kParamWrongState, set(bad));
    set_state(9);  // beyond the bitset
    entry_f32(0, 260.0f);
    TEST_ASSERT_EQUAL(kParamWrongState, set(bad));
    TEST_ASSERT_EQUAL_FLOAT(250.0f, f32_at(0));
}

static void test_busy_while_a_bank_is_written(void) {
    uint8_t bad;
    TEST_ASSERT_EQUAL(kParamOk, param_save(g_store));
    entry_f32(0, 250.0f);
    TEST_ASSERT_EQUAL(kParamBusy, set(bad));
    TEST_ASSERT_EQUAL(kParamBusy, param_save(g_store));
    TEST_ASSERT_EQUAL(kParamBusy, param_load_begin(g_store));
    drain();
    entry_f32(0, 250.0f);
    TEST_ASSERT_EQUAL(kParamOk, set(bad));
}

static uint16_t block_crc_with(float alt, uint32_t backup) {
    uint8_t block[11];
    memcpy(block, val, 11);
    memcpy(block, &alt, 4);
    memcpy(block + 4, &backup, 4);
    return crc16(block, 11);
}

static void test_a_load_is_applied_whole_after_its_crc_and_states_are_checked(void) {
    uint8_t bad;
    TEST_ASSERT_EQUAL(kParamNoLoad, param_stage(g_store, args, 0, bad));
    TEST_ASSERT_EQUAL(kParamNoLoad, param_commit(g_store, 0, bad));
    TEST_ASSERT_EQUAL(kParamOk, param_load_begin(g_store));
    entry_f32(0, 500.0f);
    entry_u32(1, 40000);
    TEST_ASSERT_EQUAL(kParamOk, param_stage(g_store, args, nargs, bad));
    nargs = 0;
    TEST_ASSERT_EQUAL(kParamBusy, param_commit(g_store, block_crc_with(500.0f, 40000), bad));  // queue not drained
    entry_f32(0, 3001.0f);
    TEST_ASSERT_EQUAL(kParamOutOfRange, param_stage(g_store, args, nargs, bad));
    nargs = 0;
    drain();
    TEST_ASSERT_EQUAL_FLOAT(150.0f, f32_at(0));  // nothing live yet
    TEST_ASSERT_EQUAL(kParamMismatch, param_commit(g_store, block_crc_with(500.0f, 40001), bad));
    set_state(2);  // BACKUP may change only in state 1
    TEST_ASSERT_EQUAL(kParamWrongState, param_commit(g_store, block_crc_with(500.0f, 40000), bad));
    TEST_ASSERT_EQUAL(1, bad);
    set_state(1);
    TEST_ASSERT_EQUAL(kParamOk, param_commit(g_store, block_crc_with(500.0f, 40000), bad));
    TEST_ASSERT_EQUAL_FLOAT(500.0f, f32_at(0));  // live at once
    TEST_ASSERT_EQUAL_UINT32(40000, u32_at(4));
    TEST_ASSERT_TRUE(g_store.source & kParamWriting);
    drain();
    TEST_ASSERT_EQUAL_HEX8(kParamBankA, g_store.source);
    boot();
    TEST_ASSERT_EQUAL_HEX8(kParamBankA, g_store.source);
    TEST_ASSERT_EQUAL_FLOAT(500.0f, f32_at(0));
    TEST_ASSERT_EQUAL_UINT32(40000, u32_at(4));
    TEST_ASSERT_EQUAL_INT16(-5, i16_at(9));
}

// A load left open (the ground gone between BEGIN and COMMIT) holds
// neither SET nor SAVE: a SET changes live values, which the load's COMMIT
// then finds in its CRC; a SAVE ends the load (STAGE and COMMIT answer
// NO_LOAD) and writes the live values, the staged one never live. A BEGIN
// waits for a committed load's bank as it does for a save's.
static void test_an_open_load_holds_neither_set_nor_save(void) {
    uint8_t bad;
    TEST_ASSERT_EQUAL(kParamOk, param_load_begin(g_store));
    entry_u32(1, 40000);
    TEST_ASSERT_EQUAL(kParamOk, param_stage(g_store, args, nargs, bad));
    nargs = 0;
    for (int i = 0; i < 50; ++i) param_poll(g_store);  // staged into bank A
    entry_f32(0, 250.0f);
    TEST_ASSERT_EQUAL(kParamOk, set(bad));
    TEST_ASSERT_EQUAL_FLOAT(250.0f, f32_at(0));
    TEST_ASSERT_EQUAL(kParamMismatch, param_commit(g_store, block_crc_with(150.0f, 40000), bad));
    TEST_ASSERT_EQUAL(kParamOk, param_save(g_store));
    entry_u32(1, 40000);
    TEST_ASSERT_EQUAL(kParamNoLoad, param_stage(g_store, args, nargs, bad));
    nargs = 0;
    TEST_ASSERT_EQUAL(kParamNoLoad, param_commit(g_store, block_crc_with(250.0f, 40000), bad));
    drain();
    TEST_ASSERT_EQUAL_HEX8(kParamBankA, g_store.source);
    boot();
    TEST_ASSERT_EQUAL_HEX8(kParamBankA, g_store.source);
    TEST_ASSERT_EQUAL_FLOAT(250.0f, f32_at(0));
    TEST_ASSERT_EQUAL_UINT32(10000, u32_at(4));  // the staged value never took effect
    // a committed load's bank is written before another load begins
    TEST_ASSERT_EQUAL(kParamOk, param_load_begin(g_store));
    entry_u32(1, 40000);
    TEST_ASSERT_EQUAL(kParamOk, param_stage(g_store, args, nargs, bad));
    nargs = 0;
    for (int i = 0; i < 50; ++i) param_poll(g_store);
    TEST_ASSERT_EQUAL(kParamOk, param_commit(g_store, block_crc_with(250.0f, 40000), bad));
    TEST_ASSERT_EQUAL(kParamBusy, param_load_begin(g_store));
    entry_f32(0, 300.0f);
    TEST_ASSERT_EQUAL(kParamBusy, set(bad));
    TEST_ASSERT_EQUAL(kParamBusy, param_save(g_store));
    drain();
    TEST_ASSERT_EQUAL_HEX8(kParamBankB, g_store.source);
    TEST_ASSERT_EQUAL(kParamOk, param_load_begin(g_store));
}

static void test_the_stage_queue_says_busy_when_full(void) {
    uint8_t bad;
    TEST_ASSERT_EQUAL(kParamOk, param_load_begin(g_store));
    int accepted = 0;
    for (int i = 0; i < 10; ++i) {
        entry_f32(0, 100.0f + static_cast<float>(i));
        const uint8_t st = param_stage(g_store, args, nargs, bad);
        nargs = 0;
        if (st == kParamBusy) break;
        TEST_ASSERT_EQUAL(kParamOk, st);
        ++accepted;
    }
    TEST_ASSERT_EQUAL(FSW_PARAM_QUEUE / 5, accepted);
}

// A power cut after `cut` EEPROM writes of a save (load: of a load) that
// changes MAIN_ALT 300 -> 700 and BACKUP 10000 -> 50000: after the reboot
// the set is the old one or the new one, from a bank whose CRC holds.
static int cut_case(uint32_t cut, bool load, uint32_t& writes_total) {
    native::sim_eeprom_erase();
    set_state(1);
    boot();
    save_value(300.0f);  // the old set, in bank A
    uint8_t bad;
    const uint32_t w0 = native::sim_eeprom_writes();
    native::sim_eeprom_freeze_after(cut);
    if (load) {
        TEST_ASSERT_EQUAL(kParamOk, param_load_begin(g_store));
        entry_f32(0, 700.0f);
        entry_u32(1, 50000);
        TEST_ASSERT_EQUAL(kParamOk, param_stage(g_store, args, nargs, bad));
        nargs = 0;
        drain();
        const uint8_t st = param_commit(g_store, block_crc_with(700.0f, 50000), bad);
        if (st != kParamOk && st != kParamMismatch) TEST_FAIL_MESSAGE("the commit was refused");
    } else {
        entry_f32(0, 700.0f);
        entry_u32(1, 50000);
        TEST_ASSERT_EQUAL(kParamOk, set(bad));
        TEST_ASSERT_EQUAL(kParamOk, param_save(g_store));
    }
    drain();
    writes_total = native::sim_eeprom_writes() - w0;
    native::sim_eeprom_freeze_after(0xFFFFFFFFu);
    boot();
    const bool old_set = f32_at(0) == 300.0f && u32_at(4) == 10000;
    const bool new_set = f32_at(0) == 700.0f && u32_at(4) == 50000;
    TEST_ASSERT_TRUE_MESSAGE(old_set || new_set, "a mix of the old and the new set");
    TEST_ASSERT_TRUE_MESSAGE(g_store.source == kParamBankA || g_store.source == kParamBankB, "no valid bank");
    return new_set ? 1 : 0;
}

static void test_a_power_cut_at_any_write_leaves_the_old_or_the_new_set(void) {
    for (int load = 0; load < 2; ++load) {
        uint32_t total = 0;
        cut_case(0xFFFFFF, load != 0, total);  // no cut: how many writes the change takes
        // clear the magic, 11 value bytes (a load's 8 staged ones, then the
        // 3 others), 8 header bytes, the magic
        TEST_ASSERT_EQUAL(1 + 11 + 8 + 1, total);
        int news = 0;
        for (uint32_t cut = 0; cut <= total; ++cut) {
            uint32_t t;
            news += cut_case(cut, load != 0, t);
        }
        TEST_ASSERT_EQUAL(1, news);  // only the cut after the last write (the magic) has the new set
    }
}

static void run(void) {
    UNITY_BEGIN();
    RUN_TEST(test_an_erased_eeprom_boots_the_defaults);
    RUN_TEST(test_set_then_save_then_reboot_takes_bank_a_then_bank_b);
    RUN_TEST(test_a_bad_bank_falls_back_to_the_other_then_to_the_defaults);
    RUN_TEST(test_banks_of_another_table_are_not_taken);
    RUN_TEST(test_the_newer_bank_wins_across_the_sequence_wrap);
    RUN_TEST(test_refusals_change_nothing);
    RUN_TEST(test_a_change_needs_an_allowed_state);
    RUN_TEST(test_busy_while_a_bank_is_written);
    RUN_TEST(test_a_load_is_applied_whole_after_its_crc_and_states_are_checked);
    RUN_TEST(test_an_open_load_holds_neither_set_nor_save);
    RUN_TEST(test_the_stage_queue_says_busy_when_full);
    RUN_TEST(test_a_power_cut_at_any_write_leaves_the_old_or_the_new_set);
    (void)UNITY_END();
}

FSW_TEST_MAIN(run)
