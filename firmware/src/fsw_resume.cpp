// Resuming a flight after a reset (fsw_resume.h, docs/safety.md).
#include "fsw_resume.h"

namespace fsw {

namespace {

ResumeConfig config(const ResumeConfig* cfg) {
    ResumeConfig c;
    flash_read(&c, cfg, sizeof c);
    return c;
}

uint8_t* bank_at(const ResumeConfig& c, uint8_t b) { return c.banks + b * static_cast<uint16_t>(c.size + 3u); }

// The check: Fletcher-16, two sums modulo 255 kept with an end-around carry
// (each in 0..255, where 255 and 0 both mean 0: the save and the check
// compute them alike), seeded with the schema hash so that another
// firmware's bank does not check. Every single-bit error of a bank changes
// it, and every two-bit error but the same bit of two bytes 255 apart set
// in one and cleared in the other (256 = 1 mod 255: +2^k and -2^k, 255
// bytes apart, leave both sums; docs/safety.md).
// x + y with the sums' end-around carry (Check::add's step): 0 only when
// both are 0, else 1..255 (255 for the sums' 0).
inline __attribute__((always_inline)) uint8_t plus(uint8_t x, uint8_t y) {
#if defined(__AVR__)
    __asm__("add %0, %1\n\tadc %0, __zero_reg__" : "+r"(x) : "r"(y));  // the carry back in: 2 instructions
    return x;
#else
    const uint8_t t = static_cast<uint8_t>(x + y);
    return static_cast<uint8_t>(t + (t < y ? 1u : 0u));
#endif
}

struct Check {
    uint8_t a, b;
    // In C, not with plus(): the boot's checks of the banks (resume_begin)
    // take as long as before, so the cycles keep their phase to the
    // simulated plant's steps and the closed-loop flights their results.
    inline __attribute__((always_inline)) void add(uint8_t v) {
        const uint8_t t = static_cast<uint8_t>(a + v);
        a = static_cast<uint8_t>(t + (t < v ? 1u : 0u));
        const uint8_t u = static_cast<uint8_t>(b + a);
        b = static_cast<uint8_t>(u + (u < a ? 1u : 0u));
    }
};

// The spans' bytes copied to `at` and into the check: the save's loop, 8.5
// cycles a byte on AVR, eight bytes a turn after each span's n % 4 first
// ones, taken as a byte and a pair as the size's bits 0 and 1 leave it
// for its count of quads (11 cycles a byte, one at a time, before; an odd
// quad enters the first turn half way; four bytes a turn took 9
// cycles a byte: 6 us more a save on the rocket, for 56 B less of code)
// (the same sums as Check::add, in assembly: the compiler's version
// took twice as long, and the save runs every cycle). On AVR the walk of
// the spans' table is in the assembly too: a span's address and size read
// from flash in 4 instructions, 30 cycles a span where the compiler's
// loop around the copy took about 45. A strided span (kResumeStrided) takes
// 13 cycles a byte: the rocket's seven task modes, about 40 cycles each as
// spans of one byte, in about 110 together.
#if defined(__AVR__)
#define FSW_RESUME_BYTE              \
    "ld __tmp_reg__, Z+\n\t"         \
    "st X+, __tmp_reg__\n\t"         \
    "add %[a], __tmp_reg__\n\t"      \
    "adc %[a], __zero_reg__\n\t"     \
    "add %[b], %[a]\n\t"             \
    "adc %[b], __zero_reg__\n\t"
#endif
// The check and the place after the bytes, returned in registers (a call
// of the loop saved and restored six registers when it wrote the check
// through a reference, about 50 cycles of the 2 or 3 calls a save makes).
struct Copied {
    uint8_t* at;
    Check k;
};
FSW_NOINLINE Copied copy_spans(uint8_t* at, const ResumeSpan* spans, uint8_t n_spans, Check k) {
    if (n_spans == 0) {
        const Copied c = {at, k};
        return c;
    }
#if defined(__AVR__) && FSW_USE_PROGMEM  // the table in flash
    // Every register the loop takes is one a call may change (the count of
    // quads in r24:r25, the one such pair adiw and sbiw take): nothing to save.
    uint8_t a = k.a, b = k.b;
    register uint16_t quads asm("r24");
    uint16_t table;
    __asm__ __volatile__(
        "1:\n\t"
        "lpm  r0, Z+\n\t"  // the span's address, in r1:r0 for a moment
        "lpm  r1, Z+\n\t"
        "lpm  %A[q], Z+\n\t"  // its size
        "lpm  %B[q], Z+\n\t"
        "movw %[table], r30\n\t"  // Z: the span's bytes, the table's place kept
        "movw r30, r0\n\t"
        "clr  r1\n\t"
        "sbrc %B[q], 7\n\t"  // kResumeStrided
        "rjmp 6f\n\t"
        "lsr  %B[q]\n\t"  // the size's bit 0 out to the carry: a byte before the turns
        "ror  %A[q]\n\t"
        "brcc 2f\n\t" FSW_RESUME_BYTE
        "2:\n\t"
        "lsr  %B[q]\n\t"  // its bit 1: a pair (the size is then its quads)
        "ror  %A[q]\n\t"
        "brcc 3f\n\t" FSW_RESUME_BYTE FSW_RESUME_BYTE
        "3:\n\t"
        "lsr  %B[q]\n\t"  // eight bytes a turn: an odd quad in the first turn's second half
        "ror  %A[q]\n\t"
        "brcc 9f\n\t"
        "adiw %[q], 1\n\t"  // an odd number of quads: one more turn, entered half way
        "rjmp 10f\n\t"
        "9:\n\t"
        "sbiw %[q], 0\n\t"
        "breq 5f\n\t"
        "4:\n\t" FSW_RESUME_BYTE FSW_RESUME_BYTE FSW_RESUME_BYTE FSW_RESUME_BYTE
        "10:\n\t" FSW_RESUME_BYTE FSW_RESUME_BYTE FSW_RESUME_BYTE FSW_RESUME_BYTE
        "sbiw %[q], 1\n\t"
        "brne 4b\n\t"
        "5:\n\t"
        "movw r30, %[table]\n\t"
        "dec  %[n]\n\t"
        "breq 8f\n\t"
        "rjmp 1b\n\t"  // the loop is longer than a branch reaches
        "6:\n\t"  // strided: the count in the size's low byte, the stride in its high one
        "andi %B[q], 0x7F\n\t"
        "7:\n\t"
        "ld   __tmp_reg__, Z\n\t"
        "st   X+, __tmp_reg__\n\t"
        "add  %[a], __tmp_reg__\n\t"
        "adc  %[a], __zero_reg__\n\t"
        "add  %[b], %[a]\n\t"
        "adc  %[b], __zero_reg__\n\t"
        "add  r30, %B[q]\n\t"
        "adc  r31, __zero_reg__\n\t"
        "dec  %A[q]\n\t"
        "brne 7b\n\t"
        "rjmp 5b\n\t"
        "8:\n\t"
        : [a] "+r"(a), [b] "+r"(b), [n] "+r"(n_spans), [q] "=&w"(quads), [table] "=&r"(table),
          [z] "+z"(spans), [at] "+x"(at)
        :
        : "memory");
    k.a = a;
    k.b = b;
#else
    for (uint8_t i = 0; i < n_spans; ++i) {
        const uint8_t* p = flash_get(spans[i].p);
        const uint16_t n = flash_get(spans[i].n);
        const uint8_t stride = (n & kResumeStrided) != 0 ? static_cast<uint8_t>((n >> 8) & 0x7Fu) : 1u;
        for (uint16_t left = resume_span_size(n); left != 0; --left) {
            const uint8_t v = *p;
            p += stride;
            *at++ = v;
            k.add(v);
        }
    }
#endif
    const Copied c = {at, k};
    return c;
}

// k, then the n bytes whose own sums (from {0, 0}) are z: the bits adding
// the bytes one at a time (Check::add) gives. Each byte adds a running
// `a` to `b`: the n bytes add n times k.a (mod 255) besides their own
// sums. Both ways give equal sums mod 255, each 0 only when every term is
// 0 (plus() keeps a sum of non-zero terms in 1..255): the same bits.
void combine(Check& k, Check z, uint16_t n) {
    uint8_t t = 0;  // n x k.a, mod 255: 0 only when k.a is (a sum of non-zero terms, then, as Check::add's is)
    if (k.a != 0 && n != 0) {
        // 256 = 1 mod 255: a 16-bit number's bytes added are it, mod 255 (no division routine)
        const uint8_t m = plus(static_cast<uint8_t>(n), static_cast<uint8_t>(n >> 8));
        const uint16_t p = static_cast<uint16_t>(m * k.a);
        t = plus(static_cast<uint8_t>(p), static_cast<uint8_t>(p >> 8));
        if (t == 0) t = 255u;
    }
    k.b = plus(plus(k.b, t), z.b);
    k.a = plus(k.a, z.a);
}

// A watched span (ResumeWatch): copied, its sums kept, while it changed in
// the last two saves; else left as both banks hold it, its kept sums added.
uint8_t* watched_span(uint8_t* at, const ResumeSpan* span, const ResumeWatch* w, Check& k) {
    uint8_t* const changed = flash_get(w->changed);
    uint8_t* const st = flash_get(w->state);  // saves since it changed, then its sums
    const uint16_t n = resume_span_size(flash_get(span->n));
    if (*changed != 0) {
        *changed = 0;
        st[0] = 0;
    } else if (st[0] < 2u) {
        ++st[0];
    }
    Check z = {st[1], st[2]};
    if (st[0] < 2u) {  // this bank's bytes may be older: copied
        const Check zero = {0, 0};
        const Copied c = copy_spans(at, span, 1, zero);
        at = c.at;
        z = c.k;
        st[1] = z.a;
        st[2] = z.b;
    } else {
        at += n;
    }
    combine(k, z, n);
    return at;
}

Check seeded(const ResumeConfig& c) {
    Check k = {0, 0};
    uint8_t s[4];
    memcpy(s, &c.schema, sizeof s);
    for (uint8_t i = 0; i < 4; ++i) k.add(s[i]);
    return k;
}

// A bank's bytes and sequence number checked against its last two bytes.
bool bank_ok(const ResumeConfig& c, const uint8_t* bank) {
    Check k = seeded(c);
    for (uint16_t i = 0; i <= c.size; ++i) k.add(bank[i]);
    return bank[c.size + 1u] == k.a && bank[c.size + 2u] == k.b;
}

int8_t newest(const ResumeConfig& c) {
    const bool ok0 = bank_ok(c, bank_at(c, 0));
    const bool ok1 = bank_ok(c, bank_at(c, 1));
    if (ok0 && ok1) {  // sequence numbers wrap: the newer is at most 127 ahead
        const uint8_t d = static_cast<uint8_t>(bank_at(c, 1)[c.size] - bank_at(c, 0)[c.size]);
        return d != 0 && d < 128u ? 1 : 0;
    }
    return ok0 ? 0 : ok1 ? 1 : -1;
}

}  // namespace

int8_t resume_newest(const ResumeConfig* cfg) { return newest(config(cfg)); }

bool resume_begin(Resume& r, const ResumeConfig* cfg, uint8_t cause) {
    const ResumeConfig c = config(cfg);
    r.cfg = cfg;
    r.seq = 0;
    r.next = 0;
    const Check seed = seeded(c);
    r.seed_a = seed.a;
    r.seed_b = seed.b;
    for (uint8_t i = 0; i < c.n_watch; ++i) {  // the next two saves copy the watched spans into both banks
        ResumeWatch w;
        flash_read(&w, &c.watch[i], sizeof w);
        *w.changed = 1;
    }
    const int8_t b = (cause & kResetKeepsRam) != 0 && (cause & kResetFresh) == 0 ? newest(c) : -1;
    if (b < 0) {  // a fresh start: no bank from before it may ever be taken for one of this run's
        for (uint8_t k = 0; k < 2; ++k) {
            uint8_t* const bank = bank_at(c, k);
            if (bank_ok(c, bank)) bank[c.size + 1u] = static_cast<uint8_t>(~bank[c.size + 1u]);
        }
        return false;
    }
    const uint8_t* bank = bank_at(c, static_cast<uint8_t>(b));
    r.seq = bank[c.size];
    r.next = static_cast<uint8_t>(b ^ 1);
    for (uint8_t i = 0; i < c.n_spans; ++i) {
        ResumeSpan s;
        flash_read(&s, &c.spans[i], sizeof s);
        uint8_t stride = 1;
        if ((s.n & kResumeStrided) != 0) {  // a byte every stride
            stride = static_cast<uint8_t>((s.n >> 8) & 0x7Fu);
            s.n = static_cast<uint8_t>(s.n);
        }
        for (uint8_t* p = s.p; s.n != 0; --s.n, p += stride) *p = *bank++;
    }
    return true;
}

void resume_save(Resume& r) {
    // the configuration and the spans a field at a time (no copy routine: the save runs every cycle)
    const ResumeConfig& f = *r.cfg;
    const uint16_t size = flash_get(f.size);
    uint8_t* const bank = flash_get(f.banks) + (r.next != 0 ? size + 3u : 0u);
    bank[size + 1u] = static_cast<uint8_t>(~bank[size + 1u]);  // invalid while it is written
    uint8_t* at = bank;
    Check k = {r.seed_a, r.seed_b};  // seeded()'s sums, as resume_begin found them (4 us a save to work out)
    const ResumeSpan* const spans = flash_get(f.spans);
    const uint8_t n_spans = flash_get(f.n_spans);
    uint8_t done = 0;  // the spans copied (or left) so far
    const ResumeWatch* w = flash_get(f.watch);
    for (uint8_t i = flash_get(f.n_watch); i != 0; --i, ++w) {
        const uint8_t s = flash_get(w->span);
        const Copied c = copy_spans(at, spans + done, static_cast<uint8_t>(s - done), k);
        at = c.at;
        k = c.k;
        at = watched_span(at, spans + s, w, k);
        done = static_cast<uint8_t>(s + 1u);
    }
    const Copied c = copy_spans(at, spans + done, static_cast<uint8_t>(n_spans - done), k);
    at = c.at;
    k = c.k;
    r.seq = static_cast<uint8_t>(r.seq + 1u);
    *at = r.seq;
    k.a = plus(k.a, r.seq);  // Check::add
    k.b = plus(k.b, k.a);
    bank[size + 1u] = k.a;  // the check last: once it matches, every byte before it is this save's
    bank[size + 2u] = k.b;
    r.next = static_cast<uint8_t>(r.next ^ 1u);
}

}  // namespace fsw
