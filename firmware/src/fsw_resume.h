// Resuming a flight after a reset (docs/safety.md, "A reset in flight"): the
// flight's state -- the state vector, every machine's state, entry time and
// locals, the pyro channels' gates, the recorder's flight -- copied at the
// end of every cycle (and before a pyro pin goes high) into one of two banks
// of RAM the C runtime does not clear at boot (.noinit), each closed by a
// sequence number and a check (Fletcher-16). After a brown-out or a watchdog reset the
// newest whole bank is copied back before the first cycle; after a power-on
// or an external reset (the reset button, a host opening the port) nothing
// is, and the firmware starts on the pad as always.
#ifndef FSW_RESUME_H
#define FSW_RESUME_H

#include "fsw_types.h"

namespace fsw {

// The reset cause's bit (Executor::reset_cause, the hello and health
// frames, the `reset_cause` element) that says the flight's state was
// resumed from a bank. The MCU's own causes use the low four bits (AVR
// MCUSR: power-on 0x01, external 0x02, brown-out 0x04, watchdog 0x08).
static const uint8_t kResetResumed = 0x80;
// The causes after which RAM holds what it held: brown-out and watchdog.
static const uint8_t kResetKeepsRam = 0x04 | 0x08;
// The causes after which a person asked for a fresh start (or RAM is lost).
static const uint8_t kResetFresh = 0x01 | 0x02;

// One piece of RAM kept across a reset (FSW_FLASH table): `n` bytes from
// `p`, or, with kResumeStrided set in `n` (resume_strided), one byte at `p`
// and at every `stride` bytes after it, `count` of them: a byte of each
// record of an array (each task's mode in the executor's TaskStats), in
// one span instead of one a byte (about 40 AVR cycles a span a save).
struct ResumeSpan {
    uint8_t* p;
    uint16_t n;
};
static const uint16_t kResumeStrided = 0x8000u;
// A strided span's `n`: `count` bytes (1..255), `stride` bytes apart (1..127).
constexpr uint16_t resume_strided(uint8_t count, uint8_t stride) {
    return static_cast<uint16_t>(kResumeStrided | static_cast<uint16_t>((stride & 0x7Fu) << 8) | count);
}
// The bytes a span keeps in a bank: `n`, or a strided span's count.
constexpr uint16_t resume_span_size(uint16_t n) {
    return (n & kResumeStrided) != 0 ? static_cast<uint16_t>(n & 0xFFu) : n;
}

// A span the save copies only while its bytes change (FSW_FLASH table, in
// span order): a machine's rolling windows, pushed in some of its states
// only (the rocket's mission: in 4 of its 10). The code that writes the
// span sets `*changed` (the machine's pushes and its reset, generated); a
// save that finds it set clears it and copies the span, and so does the
// save after it (the other bank); once both banks hold the span's bytes a
// save leaves them there and adds their check sums, kept from the copy,
// to the bank's check (the same check bits as adding the bytes one at a
// time: the format and the check are the same as without). `state` is the
// span's RAM of 3 bytes: saves since it changed (0..2), then its two sums.
struct ResumeWatch {
    uint8_t span;       // its index in the spans' table
    uint8_t* changed;   // set by every write of the span's bytes; cleared by the save
    uint8_t* state;     // 3 bytes of RAM, zero at boot
};

// The kept state's description (FSW_FLASH). `banks` is 2 * (size + 3)
// bytes of .noinit RAM: each bank is the spans' bytes in table order, a
// sequence number, and the Fletcher-16 check (seeded with the schema hash)
// of both, low byte first.
struct ResumeConfig {
    const ResumeSpan* spans;
    uint8_t* banks;
    uint32_t schema;   // the application's link schema: another firmware's bank is not ours
    uint16_t size;     // the spans' bytes together
    uint8_t n_spans;
    const ResumeWatch* watch;  // spans copied only while they change, or null (n_watch 0)
    uint8_t n_watch;
};

// The bank written next, and the sequence number it gets (RAM, zeroed at boot).
struct Resume {
    const ResumeConfig* cfg;  // FSW_FLASH
    uint8_t seq;              // the newest bank's sequence number
    uint8_t next;             // 0 or 1: the bank the next save writes
    uint8_t seed_a, seed_b;   // the check's two sums after the schema hash, worked out once at boot
};

// Boot: when `cause` is a brown-out or a watchdog reset (and neither a
// power-on nor an external reset), copies the newest whole bank back into
// the spans and returns true; otherwise changes nothing and returns false.
// Otherwise both banks are made invalid, so that no bank from before a
// fresh start is ever taken for one of this run. Later saves alternate
// from the bank after the newest. Out of line: the frame is on the stack at
// boot only, not in main()'s.
FSW_NOINLINE bool resume_begin(Resume& r, const ResumeConfig* cfg, uint8_t cause);
// Copies the spans into the older bank, then its sequence number, then its
// check: a reset part way through leaves that bank invalid and the other one
// whole. About 9 cycles a byte on AVR.
FSW_NOINLINE void resume_save(Resume& r);
// The newest whole bank: 0 or 1, or -1 when neither is (tests, the link).
int8_t resume_newest(const ResumeConfig* cfg);

}  // namespace fsw

#endif  // FSW_RESUME_H
