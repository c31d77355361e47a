// Parameters (docs/parameters.md): constants of the state machines that the
// ground may change without a rebuild, kept in two EEPROM banks so that a
// power cut at any byte leaves the old set or the new one. The tables are
// generated from the `[parameters]` sections (FSW_FLASH); the value block
// is RAM the machines read. EEPROM bytes are written in the background, one
// whenever the EEPROM is ready: nothing here waits for it.
#ifndef FSW_PARAM_H
#define FSW_PARAM_H

#include "fsw_types.h"

namespace fsw {

static const uint8_t kParamMagic = 0x50;   // a bank's first byte once it is whole
static const uint8_t kParamHeader = 9;     // magic, seq u16, table hash u32, CRC u16 (high byte first)

// Where the live values came from at boot (ParamStore::source bits 0..1).
enum ParamSource : uint8_t {
    kParamNone = 0,      // the application has no parameters
    kParamDefaults = 1,  // no valid bank: the generated defaults
    kParamBankA = 2,
    kParamBankB = 3,
};
static const uint8_t kParamDirty = 0x40;    // source bit 6: live values differ from the current bank
static const uint8_t kParamWriting = 0x80;  // source bit 7: a bank is being written

// One parameter (FSW_FLASH, in id order). Its value lives in RAM where the
// declaring machine reads it (`ptr`, its generated `prm` block); the value
// block of the banks, the CRC and the defaults are the parameters' values
// laid end to end in id order (`off`).
struct ParamDef {
    uint8_t* ptr;    // the live value (RAM)
    uint16_t off;    // offset of its value in the value block
    uint16_t range;  // offset in the pool of its MIN then MAX (elem_size(type) bytes each,
                     // little-endian values of the type; unused for bool)
    uint8_t type;    // ElemType
    uint8_t when;    // index of its ParamWhen row
};

// The states in which a change is allowed (FSW_FLASH; rows shared by
// parameters with the same machine and states).
struct ParamWhen {
    uint16_t state_off;  // offset of the declaring machine's `S` element (U32) in the state vector
    uint16_t mask;       // offset in the pool of the state bitset: state s allows iff
                         // bit (s-1)%8 of byte (s-1)/8 is set
    uint8_t n;           // bytes of the bitset (states beyond them do not allow)
};

// The application's parameter table (FSW_FLASH).
struct ParamConfig {
    const ParamDef* defs;       // n rows
    const ParamWhen* whens;
    const uint8_t* pool;        // ranges and state bitsets (FSW_FLASH)
    const uint8_t* defaults;    // the default value block, size bytes (FSW_FLASH)
    uint8_t* staged;            // RAM bitset, (n + 7) / 8 bytes: ids staged in the open load
    const uint8_t* sv;          // the state vector (for `S`)
    uint32_t hash;              // the table hash stored in every bank
    uint16_t size;              // value block bytes
    uint16_t eeprom_base;       // EEPROM address of bank A (bank B follows it)
    uint8_t n;                  // parameters, 1..255
    bool lock;                  // state vector `lock`: value reads/writes in a critical section
};

// EEPROM bytes the two banks take: the recorder's area starts here.
constexpr uint16_t param_eeprom_end(uint16_t base, uint16_t size) {
    return static_cast<uint16_t>(base + 2u * (kParamHeader + size));
}

// FSW_PARAM_QUEUE (bytes of the stage queue): fsw_config.h.
static_assert(FSW_PARAM_QUEUE >= FSW_LINK_RX_CAP - 6 && FSW_PARAM_QUEUE <= 255,
              "FSW_PARAM_QUEUE must take the longest STAGE a frame carries (FSW_LINK_RX_CAP - 6 bytes): "
              "a longer one would be BUSY for ever");

// The store's run-time record (RAM).
struct ParamStore {
    const ParamConfig* cfg;     // FSW_FLASH
    uint16_t seq;               // the current bank's sequence number (0 with the defaults)
    uint8_t source;             // ParamSource | kParamDirty | kParamWriting
    uint8_t loading;            // a load is open (PARAM_BEGIN .. PARAM_COMMIT)
    // the background writer (fsw_param.cpp): what it writes, where it is
    uint16_t w_crc;             // the new bank's CRC (header phase)
    uint8_t w_job;              // the writer's phase (0: idle)
    uint8_t w_id;               // parameter (values phase) or header byte
    uint8_t w_b;                // byte within it
    uint8_t q_len;              // bytes in the stage queue
    uint8_t queue[FSW_PARAM_QUEUE];
};

// Ack statuses of the parameter commands (continuing LinkStatus).
enum ParamStatus : uint8_t {
    kParamOk = 0,
    kParamBadLength = 3,
    kParamNoParam = 8,
    kParamOutOfRange = 9,
    kParamWrongState = 10,
    kParamBusy = 11,
    kParamNoLoad = 12,
    kParamMismatch = 13,
};

// Boot: reads both banks, takes the newest valid one (else the defaults)
// into the live value block. Blocking EEPROM reads only (a few hundred us).
// Out of line, as every begin function the generated main() calls: its
// frame is on the stack at boot only, not in main()'s, which every path pays.
FSW_NOINLINE void param_begin(ParamStore& s, const ParamConfig* cfg);

// The commands (the link calls them; `args` as received, `bad` the id a
// refusal stopped at, 0xFF when none). Each returns a ParamStatus.
uint8_t param_set(ParamStore& s, const uint8_t* args, uint8_t len, uint8_t& bad);
uint8_t param_save(ParamStore& s);
uint8_t param_load_begin(ParamStore& s);
uint8_t param_stage(ParamStore& s, const uint8_t* args, uint8_t len, uint8_t& bad);
// (COMMIT out of line: its two value buffers are not in the frame of the
// link's command handler, which SET's deeper path runs through.)
FSW_NOINLINE uint8_t param_commit(ParamStore& s, uint16_t crc, uint8_t& bad);

// The live value of parameter `id` into `out` (8 bytes of room): its size,
// 0 when there is no such parameter.
uint8_t param_value(const ParamStore& s, uint8_t id, uint8_t* out);
// Parameters in the table.
uint8_t param_count(const ParamStore& s);
// CRC-16 of the live value block (the live values in id order).
uint16_t param_crc(const ParamStore& s);

// The background writer: writes the next EEPROM byte if the EEPROM is
// ready and a job is under way. Called from loop() between cycles (and on
// the EEPROM-ready interrupt's wake-up).
void param_poll(ParamStore& s);
// Whether param_poll has a job under way.
bool param_busy(const ParamStore& s);

}  // namespace fsw

#endif  // FSW_PARAM_H
