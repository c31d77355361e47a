"""Faults between the target and the ground: random bit errors (BER 1e-3),
dropped bytes and garbage at boot on the tank firmware's real link bytes
(10 simulated minutes at 115200 baud). No corrupted frame is accepted,
decoding resumes on the next good frame, and the loss counters are exact:
the frames the ground counts as lost are exactly the frames the faults
destroyed."""

from __future__ import annotations

import random

import numpy as np
import pytest

from fswkit.link import wire
from fswkit.link.session import Session
from support.linkfw import TANK, build_native, needs_cxx, simulated_link, tank_layout

pytestmark = needs_cxx()


@pytest.fixture(scope="module")
def clean():
    exe = build_native(TANK)
    data = simulated_link(exe, 60000, "--uart", "115200", "a14=700")  # 10 simulated minutes
    return data


def frame_spans(data: bytes) -> list[tuple[int, int]]:
    """(start, end) of each frame, end = the index of its delimiter (the
    empty span before the delimiter the target sends first at boot is no
    frame)."""
    z = np.flatnonzero(np.frombuffer(data, np.uint8) == 0)
    starts = np.r_[0, z[:-1] + 1]
    return [(a, b) for a, b in zip(starts.tolist(), z.tolist()) if b > a]


def test_clean_link_loses_nothing(clean):
    s = Session(tank_layout())
    events = s.feed(clean)
    assert s.stats.lost == 0 and s.deframer.stats.invalid == 0 and s.deframer.stats.crc_errors == 0
    assert s.stats.frames == len(frame_spans(clean)) > 20000
    assert s.health["dropped"] == 0  # the target never found its transmit buffer full
    healths = [e for e in events if e.kind == "health"]
    assert len(healths) > 100
    # each health frame counts the frames sent before it: its own sequence number
    assert all(e.info["frames"] == e.seq for e in healths)
    assert healths[-1].seq <= s.last_seq


def corrupt(data: bytes, rnd: random.Random, ber: float, drop: float) -> tuple[bytes, np.ndarray]:
    """Bit errors at `ber` and dropped bytes at rate `drop`; returns the bytes
    and a mask of the original bytes that arrived intact."""
    arr = np.frombuffer(data, np.uint8).copy()
    g = np.random.default_rng(rnd.randrange(2**32))
    bits = g.random(len(arr) * 8) < ber
    flips = np.packbits(bits.reshape(-1, 8), axis=1, bitorder="little").ravel()
    arr ^= flips
    dropped = g.random(len(arr)) < drop
    intact = (flips == 0) & ~dropped
    return arr[~dropped].tobytes(), intact


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_bit_errors_dropped_bytes_and_boot_garbage(clean, seed):
    lost = check_faults(clean, tank_layout(), random.Random(seed))
    assert lost > 1000  # the faults did bite (about a quarter of the frames)


def check_faults(clean: bytes, layout, rnd: random.Random) -> int:
    """Corrupts a clean capture that starts at the target's boot (frame i
    has sequence number i) and checks the ground against what the faults
    destroyed; returns the number of frames lost."""
    spans = frame_spans(clean)
    noisy, intact = corrupt(clean, rnd, ber=1e-3, drop=2e-4)
    garbage = bytes(rnd.randrange(256) for _ in range(rnd.randrange(1, 400)))
    # a frame arrives whole when all its bytes and its delimiter do, and the
    # previous delimiter too (else it merges with the frame before it)
    ok_prefix = np.concatenate(([0], np.cumsum(~intact)))
    def whole(i):
        a, b = spans[i]
        if ok_prefix[b + 1] - ok_prefix[a] != 0:
            return False
        return i == 0 or intact[spans[i - 1][1]]
    boot = spans[0][0] - 1  # the delimiter the target sends first at boot (-1: none)
    survived = [i for i in range(len(spans)) if whole(i)]
    ended = boot >= 0 and intact[boot]  # the boot's delimiter ends whatever garbage came before
    if garbage.rfind(b"\0") != len(garbage) - 1 and not ended and survived and survived[0] == 0:
        survived = survived[1:]  # the boot garbage runs into the first frame
    expect_seqs = set(survived)
    # what the ground gets, in pieces of random size as a serial port delivers them
    s = Session(layout)
    stream = garbage + noisy
    at = 0
    while at < len(stream):
        n = rnd.randrange(1, 20000)
        for ev in s.feed(stream[at:at + n]):
            assert ev.seq in expect_seqs
        at += n
    # every accepted frame is one the target sent, unaltered
    expect_bodies = {}
    for i in survived:
        a, b = spans[i]
        expect_bodies[i] = wire.cobs_decode(clean[a:b])
    d = wire.Deframer(Session(layout).consistent)  # the session's own acceptance
    bodies = [(t, sq, tm, p) for t, sq, tm, p in d.feed(stream)]
    assert len(bodies) == len(survived), "a corrupted frame was accepted, or a good one refused"
    for (t, sq, tm, p), i in zip(bodies, survived):
        assert bytes((t, sq)) + tm.to_bytes(4, "little") + p == expect_bodies[i][:-2]
    # the loss counter is exact: every frame between the first and last received
    # that did not arrive whole, and nothing else
    first, last = survived[0], survived[-1]
    assert s.stats.frames == len(survived)
    assert s.stats.lost == (last - first + 1) - len(survived)
    # a corrupted frame that passes the CRC-16 by chance (1 in 65,536 of the
    # ~4,000 corrupted here) is refused by its type and length, never decoded
    assert s.deframer.stats.invalid <= 2
    assert s.last_seq == last
    return len(spans) - len(survived)
