// Machines replaced at run time (docs/reload.md): the machine task that an
// application's `[reload]` names runs either its generated step or a
// bytecode image (fsw_vm.h) that the ground uploaded over the link into one
// of two EEPROM slots. An upload never touches the slot whose image runs; an
// image is checked (CRC and the verifier, read in the EEPROM) when it is
// committed and again before it runs, each check in slices of
// FSW_RELOAD_SLICE EEPROM reads, a slice at each of the machine task's
// steps (a COMMIT answers BUSY until its check is over); the switch happens
// at the machine task's step, in a state the configuration allows: the old
// machine's `.exit`, then the new one's first step (`.entry`, `.step`). The
// board boots the newest activated valid image, else the other, else the
// generated machine. EEPROM bytes are written in the background, one
// whenever the EEPROM is ready: nothing here waits for it.
#ifndef FSW_RELOAD_H
#define FSW_RELOAD_H

#include "fsw_config.h"  // FSW_RELOAD_QUEUE
#include "fsw_machine.h"
#include "fsw_types.h"
#include "fsw_vm.h"

namespace fsw {

// A slot in the EEPROM: a header, then the image, then the state mask (the
// image's states in which another machine may take over: bit (s-1)%8 of
// byte (s-1)/8 for state s).
static const uint8_t kReloadMagic = 0xA5;  // header byte 0 once the header is whole
static const uint8_t kReloadHeader = 9;    // magic, status, seq u16, len u16, mask bytes u8, CRC u16
// A slot's status (header byte 1).
enum ReloadSlotStatus : uint8_t {
    kSlotEmpty = 0,   // nothing valid (RAM only: the header is not whole, or its CRC fails)
    kSlotStored = 1,  // a committed, verified image, not booted
    kSlotBoot = 2,    // activated: the board boots the newest of these
};
// `ReloadStore::active` and ACTIVATE's argument: the generated machine, or a slot.
static const uint8_t kReloadBuiltIn = 0;
static const uint8_t kReloadNone = 0xFF;  // no activation pending
// `ReloadStore::reason` beyond the VmReason codes: the slot's bytes no longer
// have the CRC they were committed with.
static const uint8_t kReloadCrcFails = 0x80;

typedef Result (*ReloadStepFn)();
typedef void (*ReloadLeaveFn)();
typedef void (*ReloadResetFn)(uint32_t initial);

// The application's reload configuration (FSW_FLASH), generated from `[reload]`.
struct ReloadConfig {
    uint8_t* image;          // RAM: the running image and its mask (size bytes)
    uint8_t* ram;            // RAM: the running image's windows and locals (ram_size bytes, aligned for Real)
    uint8_t* sv;             // the state vector
    const VmLayout* layout;  // the state vector's layout (RAM; its element table FSW_FLASH)
    Machine* machine;        // the generated machine's record: the VM steps the same one
    ReloadStepFn step;       // the generated machine's step()
    ReloadLeaveFn leave;     // its leave(): the current state's .exit
    ReloadResetFn reset;     // its reset(initial)
    const uint8_t* allow;    // FSW_FLASH: the generated machine's state mask (n_allow bytes)
    uint16_t size;           // bytes of a slot's image and mask together, at most
    uint16_t ram_size;
    uint16_t eeprom_base;    // EEPROM address of slot 1 (slot 2 follows it)
    uint8_t n_allow;
};

// EEPROM bytes the two slots take from `base`.
constexpr uint16_t reload_eeprom_end(uint16_t base, uint16_t size) {
    return static_cast<uint16_t>(base + 2u * (kReloadHeader + size));
}

// A slot as the store knows it (RAM copy of a whole header).
struct ReloadSlot {
    uint16_t seq;     // activation order (0: never activated)
    uint16_t len;     // image bytes
    uint16_t crc;     // CRC-16 of the image and its mask
    uint8_t status;   // ReloadSlotStatus
    uint8_t nmask;    // mask bytes after the image
};

// The store's run-time record (RAM).
struct ReloadStore {
    const ReloadConfig* cfg;  // FSW_FLASH
    ReloadSlot slot[2];
    uint8_t active;           // kReloadBuiltIn, 1 or 2
    uint8_t pending;          // the machine ACTIVATE asked for, waiting for an allowed state (kReloadNone)
    uint8_t refused;          // the slot whose image was refused last (0: none) ...
    uint8_t reason;           // ... and why (VmReason, or kReloadCrcFails)
    // the open upload (BEGIN .. COMMIT)
    uint8_t up_slot;          // 1 or 2 (0: none open)
    uint8_t up_nmask;
    uint16_t up_len;          // image bytes
    uint16_t up_crc;          // CRC-16 the image and its mask must have
    uint16_t up_next;         // bytes from the start written or queued without a gap
    // the background writer: up to two runs of bytes (a header's body, then its magic)
    uint16_t w_addr[2];
    uint8_t w_n[2];
    uint8_t w_seg;            // the run being written (2: none)
    uint8_t w_i;              // bytes of it written
    bool sync;                // the slots' status and seq bytes are to be brought up to date
    uint8_t queue[FSW_RELOAD_QUEUE];
    // the check of a slot (its CRC, then the verifier), a slice a machine step
    // (and one a COMMIT when no step ran one since the last COMMIT): the open
    // upload's (COMMIT), or the pending activation's
    uint8_t ck_slot;          // the slot being checked (0: none)
    bool sliced;              // a machine step ran a slice since the last COMMIT
    uint8_t ck_result;        // the upload's check, over: kReloadOk, kReloadMismatch, kReloadBadImage (kReloadNone: none)
    uint8_t ck_reason;        // ... and the verifier's VmReason
    uint8_t ready;            // the slot of the pending activation whose check passed (0: none)
    uint16_t ck_at;           // bytes of the slot's CRC read so far (all of them: the verifier runs)
    uint16_t ck_crc;
    VmCheck vm;               // the verifier's state between slices
};

// Ack statuses of the reload commands (continuing LinkStatus).
enum ReloadStatus : uint8_t {
    kReloadOk = 0,
    kReloadBadLength = 3,
    kReloadOutOfRange = 9,   // WRITE past the open upload's end
    kReloadBusy = 11,        // the writer is busy, or a check runs: try again
    kReloadNoLoad = 12,      // WRITE or COMMIT without BEGIN, or COMMIT before every byte was written
    kReloadMismatch = 13,    // the bytes in the slot do not have BEGIN's CRC
    kReloadTooBig = 14,      // BEGIN: the image and its mask do not fit a slot
    kReloadBadImage = 15,    // the verifier refused the image: its VmReason in the ack
    kReloadNoImage = 16,     // ACTIVATE of a slot without a committed image
    kReloadWrongState = 10,  // BEGIN into the slot an activation waits for
};

// Boot: reads both slots' headers, checks their CRCs, and runs the newest
// activated image that the verifier accepts (else the other, else the
// generated machine), from its first state. Blocking EEPROM reads only.
// After a reset in flight (docs/safety.md), `resumed` is the machine that
// ran when the flight's state was kept (`active`: kReloadBuiltIn, 1 or 2),
// whose record and RAM the resume put back: that one goes on in its state,
// not from its first (the generated machine, or the slot's image if it
// still checks; else the boot goes on as above). kReloadNone: a fresh start.
void reload_begin(ReloadStore& s, const ReloadConfig* cfg, uint8_t resumed = kReloadNone);

// The machine task's step: a slice of the check that runs (at most
// FSW_RELOAD_SLICE EEPROM reads and the unit of work it ends in), else an
// activation whose check passed takes place if the machine is in an
// allowed state; then the running machine steps.
Result reload_step(ReloadStore& s);

// The commands (the link calls them, with the arguments as received).
uint8_t reload_upload_begin(ReloadStore& s, uint16_t len, uint8_t nmask, uint16_t crc);
uint8_t reload_write(ReloadStore& s, uint16_t off, const uint8_t* data, uint8_t n);
// COMMIT: the first of a whole upload starts its check and answers BUSY, as
// do those while it runs; the next one answers its result (and, when it
// passed, queues the slot's header). A COMMIT runs a slice of the check
// itself when no machine step did since the COMMIT before: the ground's
// COMMITs carry the check on while the machine's task is disabled or safed
// (or steps more slowly than the ground asks).
uint8_t reload_commit(ReloadStore& s, uint8_t& reason);
uint8_t reload_activate(ReloadStore& s, uint8_t which);
// Whether the background writer has bytes to write.
// (reload_poll's work: the main loop is woken for it between cycles.)
bool reload_writing(const ReloadStore& s);

// The background writer: writes the next EEPROM byte if the EEPROM is ready
// and there is one to write. Called from loop() between cycles.
void reload_poll(ReloadStore& s);

}  // namespace fsw

#endif  // FSW_RELOAD_H
