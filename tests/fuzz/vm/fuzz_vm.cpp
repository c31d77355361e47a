// libFuzzer target: the bytecode verifier and VM (firmware/src/fsw_vm.cpp,
// docs/bytecode.md), compiled natively with ASan and UBSan. Whatever bytes
// an image holds:
//   1. an image the verifier accepts never makes the VM read or write
//      outside the state vector, its RAM or the image (the sanitizers: each
//      lives in an allocation of exactly its size), nor run into undefined
//      behaviour, through resets, steps and a leave;
//   2. the verifier reading the image in the EEPROM (vm_verify_eeprom, what
//      a board's loader runs at boot, docs/reload.md) gives the same answer
//      as the one reading RAM, and so does the same check in slices
//      (vm_check_eeprom, what it runs for a commit or an activation), with
//      a budget from the input's last byte: each call reads at most what
//      fsw_vm.h says, and the check ends.
// The input is bound to this target's state vector (schema, element count,
// G and S, the evaluation type) before it is checked, so that the fuzzer
// spends its time on the code and the tables rather than on the header.
#include <stdio.h>
#include <stdlib.h>

#include "fswkit.h"
#include "psl_native.h"

using namespace fsw;

namespace {

// one element of every type: G (U64) and S (U32) first
const VmElem kElems[] = {{0, kU64},  {8, kU32},  {12, kBool}, {13, kU8},  {14, kI8},  {15, kU16}, {17, kI16},
                         {19, kU32}, {23, kI32}, {27, kU64},  {35, kI64}, {43, kF32}, {47, kF64}};
const uint16_t kCount = sizeof kElems / sizeof kElems[0];
const uint16_t kSvSize = 55;
const uint32_t kSchema = 0x5EED0001UL;
const VmLayout kLayout = {kElems, kCount, kSchema};
const uint32_t kRamCap = 1u << 16;

void put16(uint8_t* p, uint16_t v) { p[0] = static_cast<uint8_t>(v); p[1] = static_cast<uint8_t>(v >> 8); }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 28 || size > 4096) return 0;
    uint8_t* im = static_cast<uint8_t*>(malloc(size));
    memcpy(im, data, size);
    im[5] = sizeof(Real);
    put16(im + 8, static_cast<uint16_t>(kSchema));
    put16(im + 10, static_cast<uint16_t>(kSchema >> 16));
    put16(im + 12, kCount);
    put16(im + 14, 0);
    put16(im + 16, 8);  // (G and S by their offsets)
    const uint16_t len = static_cast<uint16_t>(size);
    uint32_t need = vm_ram_size(im, len);
    const uint32_t ram_len = need == 0 ? 1u : need > kRamCap ? kRamCap : need;
    const VmReason r = vm_verify(im, len, kLayout, ram_len);
    if (len <= pal::eeprom_size()) {  // the loader's verifier, reading the EEPROM
        memcpy(native::sim_eeprom(), im, len);
        const VmReason e = vm_verify_eeprom(0, len, kLayout, ram_len);
        if (e != r) {
            fprintf(stderr, "vm_verify says %u, vm_verify_eeprom %u\n", static_cast<unsigned>(r),
                    static_cast<unsigned>(e));
            abort();
        }
        const uint16_t budget = static_cast<uint16_t>(1u + data[size - 1] % 64u);
        VmCheck c;
        vm_check_begin(c);
        uint8_t s = kVmMore;
        for (uint32_t call = 0; s == kVmMore; ++call) {
            const uint32_t before = native::sim_eeprom_reads();
            s = vm_check_eeprom(c, 0, len, kLayout, ram_len, budget);
            const uint32_t reads = native::sim_eeprom_reads() - before, header = call == 0 ? 27u : 10u;
            const uint32_t most = budget > header ? budget + 13u : header + 14u;
            if (reads > most || call > 70000u) {
                fprintf(stderr, "vm_check_eeprom: call %u read %u bytes (budget %u, at most %u)\n",
                        static_cast<unsigned>(call), static_cast<unsigned>(reads), static_cast<unsigned>(budget),
                        static_cast<unsigned>(most));
                abort();
            }
        }
        if (s != r) {
            fprintf(stderr, "vm_verify says %u, vm_check_eeprom (budget %u) %u\n", static_cast<unsigned>(r),
                    static_cast<unsigned>(budget), static_cast<unsigned>(s));
            abort();
        }
    }
    if (r == kVmOk) {
        uint8_t* sv = static_cast<uint8_t*>(malloc(kSvSize));
        uint8_t* ram = static_cast<uint8_t*>(malloc(ram_len));
        for (uint16_t i = 0; i < kSvSize; ++i) sv[i] = data[i % size];  // element values from the input
        Machine m;
        vm_reset(im, ram, m, 1);
        for (uint32_t k = 1; k <= 24; ++k) {
            store<uint64_t>(sv, k * 10u);
            (void)vm_step(im, kLayout, sv, ram, m);
            if (k == 12) vm_leave(im, kLayout, sv, ram, m);
        }
        free(ram);
        free(sv);
    }
    free(im);
    return 0;
}
