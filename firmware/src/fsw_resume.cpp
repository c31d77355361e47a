// Resuming a flight after a reset (fsw_resume.h, docs/safety.md).
#include "fsw_resume.h"

#include "fsw_crc.h"

namespace fsw {

namespace {

ResumeConfig config(const ResumeConfig* cfg) {
    ResumeConfig c;
    flash_read(&c, cfg, sizeof c);
    return c;
}

uint8_t* bank_at(const ResumeConfig& c, uint8_t b) { return c.banks + b * static_cast<uint16_t>(c.size + 3u); }

// The CRC of a bank's bytes and sequence number, seeded with the schema.
uint16_t bank_crc(const ResumeConfig& c, const uint8_t* bank) {
    uint8_t s[4];
    memcpy(s, &c.schema, sizeof s);
    return crc16(bank, static_cast<uint16_t>(c.size + 1u), crc16(s, sizeof s));
}

bool bank_ok(const ResumeConfig& c, const uint8_t* bank) {
    const uint16_t crc = bank_crc(c, bank);
    return bank[c.size + 1u] == static_cast<uint8_t>(crc) && bank[c.size + 2u] == static_cast<uint8_t>(crc >> 8);
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
    const int8_t b = (cause & kResetKeepsRam) != 0 && (cause & kResetFresh) == 0 ? newest(c) : -1;
    if (b < 0) {  // a fresh start: no bank from before it may ever be taken for one of this run's
        for (uint8_t k = 0; k < 2; ++k) {
            uint8_t* const bank = bank_at(c, k);
            const uint16_t crc = static_cast<uint16_t>(~bank_crc(c, bank));
            bank[c.size + 1u] = static_cast<uint8_t>(crc);
            bank[c.size + 2u] = static_cast<uint8_t>(crc >> 8);
        }
        return false;
    }
    const uint8_t* bank = bank_at(c, static_cast<uint8_t>(b));
    r.seq = bank[c.size];
    r.next = static_cast<uint8_t>(b ^ 1);
    for (uint8_t i = 0; i < c.n_spans; ++i) {
        ResumeSpan s;
        flash_read(&s, &c.spans[i], sizeof s);
        memcpy(s.p, bank, s.n);
        bank += s.n;
    }
    return true;
}

void resume_save(Resume& r) {
    const ResumeConfig c = config(r.cfg);
    uint8_t* const bank = bank_at(c, r.next);
    bank[c.size + 1u] = static_cast<uint8_t>(~bank[c.size + 1u]);  // invalid while it is written
    uint8_t* at = bank;
    for (uint8_t i = 0; i < c.n_spans; ++i) {
        ResumeSpan s;
        flash_read(&s, &c.spans[i], sizeof s);
        memcpy(at, s.p, s.n);
        at += s.n;
    }
    r.seq = static_cast<uint8_t>(r.seq + 1u);
    bank[c.size] = r.seq;
    const uint16_t crc = bank_crc(c, bank);
    bank[c.size + 1u] = static_cast<uint8_t>(crc);
    bank[c.size + 2u] = static_cast<uint8_t>(crc >> 8);
    r.next = static_cast<uint8_t>(r.next ^ 1u);
}

}  // namespace fsw
