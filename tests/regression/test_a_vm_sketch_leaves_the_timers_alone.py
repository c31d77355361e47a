"""A sketch that runs the bytecode VM and checks an image kept in the
EEPROM (vm_verify_eeprom) used to link the platform layer's whole
psl_arduino.cpp through its EEPROM read: the cycle timer's TIMER1_COMPA and
the ADC scan's interrupts, and their 30 B of state, in a sketch that has no
executor. A sketch using Timer1 itself (the Servo library does) would have
lost it. The EEPROM has a file of its own (psl_arduino_eeprom.cpp); this
sketch links no interrupt of the platform layer but the EEPROM's, and no
cycle-timer state."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

ARDUINO = Path("/usr/share/arduino/hardware/arduino/avr")

SKETCH = r"""
#include <Arduino.h>
#include "fswkit.h"

namespace {
const fsw::VmElem kElems[] FSW_FLASH = {{0, fsw::kU64}, {8, fsw::kU32}};
const fsw::VmLayout kLayout = {kElems, 2, 0x12345678UL};
uint8_t sv[12];
alignas(fsw::kVmRamAlign) uint8_t ram[32];
uint8_t image[64];
fsw::Machine machine;
}  // namespace
extern const uint16_t fsw::vm_features = fsw::kVmAllFeatures;

void setup() {
    pinMode(13, OUTPUT);
    if (fsw::vm_verify_eeprom(0, sizeof image, kLayout, sizeof ram) == fsw::kVmOk &&
        fsw::vm_step(image, kLayout, sv, ram, machine) == fsw::kOk)
        digitalWrite(13, HIGH);
}

void loop() {}
"""

pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or not ARDUINO.is_dir(),
                                reason="gcc-avr and arduino-core-avr are needed (make setup)")


def test_a_vm_sketch_links_no_cycle_timer_or_adc_interrupt():
    from support.simfw import sketch_elf

    elf = sketch_elf("vm-eeprom-sketch", SKETCH)  # as fsw build links: the runtime's archive, LTO
    syms = subprocess.run(["avr-nm", "-C", elf], capture_output=True, text=True, check=True).stdout
    # the sketch is what it says: the VM's interpreter, its EEPROM verifier and the EEPROM read (LTO inlines the
    # rest; the read itself, or into the verifier's reader)
    assert "::run_block(" in syms and "EepromImage" in syms, syms
    assert "fsw::pal::eeprom_read" in syms or "EepromImage::operator[]" in syms, syms
    # ATmega328P vectors: 11 TIMER1_COMPA (the cycle timer), 21 ADC (the scan); 22 EE_READY is the EEPROM's own
    vectors = {int(line.split("__vector_")[1]) for line in syms.splitlines()
               if " T __vector_" in line and line.split("__vector_")[1].isdigit()}
    assert not vectors & {11, 21}, sorted(vectors)
    assert "g_ct" not in syms and "g_scan" not in syms, [x for x in syms.splitlines() if "g_ct" in x or "g_scan" in x]
