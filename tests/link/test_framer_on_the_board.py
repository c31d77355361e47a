"""The AVR framer and UART driver on the simulated Uno, byte for byte
against the host's reference: cobs_frame's assembly (its CRC, its zeros,
its full blocks of 254 bytes, a body in place and two parts copied in after
it: a sample frame's stored samples and its current region) and the
transmit handler, which sends the runs console_send hands
it where they lie, goes on with a second run at a run's end and compares
its place with the end with no instruction that changes the status
register. Frames of every length around a block's end, with no zeros, only
zeros and some zeros, are each handed in three runs: two that join (the
second starts where the first ends) and a third elsewhere (a copy of the
frame's last half), so the handler goes on from one run to the next at
every frame, across low bytes of every value."""

from __future__ import annotations

import os
import shutil

import pytest

from support.simfw import sketch_elf  # noqa: E402

pytestmark = pytest.mark.skipif(shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                reason="gcc-avr and libsimavr-dev are needed (make setup)")

# (bytes composed in place, bytes copied in from a buffer, bytes copied in
# from a second buffer after them) of each frame (the loop counts a part's
# bytes in its count's low byte, each 256 in the high byte: parts of 255,
# 256, 257, 511, 512 and 513 bytes cross that; a full block ends in each
# part, and across two)
CASES = [(1, 0, 0), (2, 0, 0), (5, 0, 0), (60, 0, 0), (252, 0, 0), (253, 0, 0), (254, 0, 0), (255, 0, 0),
         (256, 0, 0), (257, 0, 0), (300, 0, 0), (508, 0, 0), (511, 0, 0), (512, 0, 0), (513, 0, 0), (600, 0, 0),
         (6, 24, 0), (6, 247, 0), (6, 248, 0), (6, 249, 0), (6, 256, 0), (100, 300, 0), (0, 1, 0), (0, 256, 0),
         (250, 10, 0), (7, 24, 24), (7, 0, 24), (0, 0, 1), (0, 0, 300), (3, 250, 4), (7, 240, 20), (100, 100, 254),
         (0, 255, 256), (253, 1, 1)]
MODES = 4  # 0: every byte zero; 1: no zero; 2: about one in four zero; 3: random bytes

SKETCH = r"""
#include <Arduino.h>
#include "fswkit.h"
#include "fsw_cobs.h"

static uint8_t buf[620];
static uint8_t half[320];
static uint8_t src[300];
static uint8_t src2[300];
static uint32_t seed = 12345;
static const uint16_t kCases[][3] = {CASES};

static uint8_t rnd() {
    seed = seed * 1103515245UL + 12345UL;
    return static_cast<uint8_t>(seed >> 16);
}
static void fill(uint8_t* p, uint16_t n, uint8_t mode) {
    for (uint16_t i = 0; i < n; ++i) {
        uint8_t b = rnd();
        if (mode == 0) b = 0;
        if (mode == 1) b |= 1;
        if (mode == 2 && (b & 3) == 0) b = 0;
        p[i] = b;
    }
}
static void send(const uint8_t* p, uint16_t n) {
    const uint16_t h = static_cast<uint16_t>(n / 2), q = static_cast<uint16_t>(h / 2);
    memcpy(half, p + h, n - h);
    fsw::pal::console_send(p, q);
    fsw::pal::console_send(p + q, static_cast<uint16_t>(h - q));  // joins the first run
    fsw::pal::console_send(half, static_cast<uint16_t>(n - h));  // the second run
    while (fsw::pal::console_sending() != 0) {
    }  // every byte out: the buffers are free
}
void setup() {
    fsw::pal::console_begin(115200UL);
    for (uint8_t mode = 0; mode < MODES; ++mode) {
        for (uint8_t i = 0; i < sizeof kCases / sizeof kCases[0]; ++i) {
            fill(buf + 1, kCases[i][0], mode);
            fill(src, kCases[i][1], mode);
            fill(src2, kCases[i][2], mode);
            send(buf, fsw::cobs_frame(buf, kCases[i][0], src, kCases[i][1], src2, kCases[i][2]));
        }
    }
}
void loop() {}
"""


def expected() -> bytes:
    from fswkit.link import wire

    seed = 12345

    def fill(n: int, mode: int) -> bytes:
        nonlocal seed
        out = bytearray()
        for _ in range(n):
            seed = (seed * 1103515245 + 12345) & 0xFFFFFFFF
            b = (seed >> 16) & 0xFF
            if mode == 0:
                b = 0
            if mode == 1:
                b |= 1
            if mode == 2 and b & 3 == 0:
                b = 0
            out.append(b)
        return bytes(out)

    out = bytearray()
    for mode in range(MODES):
        for in_place, copied, copied2 in CASES:
            body = fill(in_place, mode)
            body += fill(copied, mode)
            body += fill(copied2, mode)
            out += wire.frame(body)
    return bytes(out)


@pytest.mark.parametrize("board, defines", [("uno", ()), ("mega2560", ("FSW_CONSOLE_ARDUINO_SERIAL=1",))],
                         ids=["uart0-driver", "arduino-serial"])
def test_framed_bytes_on_the_wire_are_the_references(board, defines):
    """The kit's UART0 driver, and the core's Serial behind the same
    console_send (FSW_CONSOLE_ARDUINO_SERIAL=1: the runs fed to Serial as
    its buffer takes them while the sketch polls console_sending; on the
    Mega, where the sketch's buffers and Serial's two rings fit)."""
    from fswkit.sim.board import SimBoard

    source = SKETCH.replace("{CASES}", "{" + ", ".join(f"{{{a}, {b}, {c}}}" for a, b, c in CASES) + "}")
    source = source.replace("MODES", str(MODES))
    elf = sketch_elf("framer", source, board, defines)
    want = expected()
    got = bytearray()
    with SimBoard(elf, board, uart="control") as sim:
        for _ in range(400):  # 40 simulated seconds at most; about 1.5 s of line time needed
            sim.step(sim.cycles_for(0.1))
            got += sim.uart_read()
            if len(got) >= len(want):
                break
    assert len(got) == len(want), (len(got), len(want))
    first = next((i for i, (a, b) in enumerate(zip(got, want)) if a != b), None)
    assert first is None, (first, bytes(got[max(0, first - 8):first + 8]).hex(), want[max(0, first - 8):first + 8].hex())
