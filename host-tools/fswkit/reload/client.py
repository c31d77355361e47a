"""The ground's machine client (docs/reload.md): uploads a bytecode image
into the target's free slot, chunked and resumable over a lossy link, and
verified twice on the target (the CRC BEGIN announced, then the board's own
verifier at COMMIT, both run in slices at its machine task's steps and at
the COMMITs: COMMIT answers BUSY until they are over); lists the slots;
activates a slot or the generated
machine and waits until the target has switched, at the next step of its
machine in a state the application allows.

Commands go through the parameter client's pipeline (fswkit.param.client:
every command acknowledged, sent again with a new sequence number when its
acknowledgement is lost, BUSY tried again a little later), one WRITE at a
time: the target takes a WRITE only when it has written the one before
into its EEPROM (3.4 ms a byte on an AVR)."""

from __future__ import annotations

import struct
from dataclasses import dataclass

from fswkit.autocode.protocol import (OP_MACHINE_ACTIVATE, OP_MACHINE_BEGIN, OP_MACHINE_COMMIT, OP_MACHINE_INFO,
                                      OP_MACHINE_WRITE, RELOAD_CRC_FAILS, RELOAD_INFO, RELOAD_SLOT, crc16)
from fswkit.autocode.vmverify import REASONS
from fswkit.param.client import RX_CAP, ParamClient, ParamError

BUILT_IN = 0
NONE = 0xFF
SLOT_STATUS = {0: "empty", 1: "stored", 2: "activated"}
# the most image bytes a WRITE carries: the target's receive buffer holds an
# encoded frame of RX_CAP bytes (op, seq u16, offset u16, the bytes, CRC, COBS)
CHUNK = RX_CAP - 8
EEPROM_BYTE_S = 0.0034  # an AVR's EEPROM write of one byte
NO_LOAD, MISMATCH, BAD_IMAGE, NO_IMAGE = 12, 13, 15, 16


class MachineError(Exception):
    """A refusal or a failure, said in words."""


def reason_words(code: int) -> str:
    if code == RELOAD_CRC_FAILS:
        return "the slot's bytes no longer have the CRC they were committed with"
    if code in REASONS:
        return f"{REASONS[code]} (verifier reason {code})"
    return f"reason {code}"


@dataclass
class Slot:
    number: int  # 1 or 2
    status: int
    seq: int
    length: int  # image bytes
    nmask: int
    crc: int

    @property
    def status_name(self) -> str:
        return SLOT_STATUS.get(self.status, f"status {self.status}")


@dataclass
class Info:
    active: int  # 0 the generated machine, 1 or 2 a slot
    pending: int  # NONE, or what an activation waits to switch to
    refused: int  # the slot refused last (0: none)
    reason: int
    writing: bool
    size: int  # bytes of a slot (image and mask)
    ram: int
    up_slot: int  # the open upload's slot (0: none)
    up_len: int
    up_nmask: int
    up_crc: int
    up_next: int
    slots: tuple[Slot, Slot]


def payload(image: bytes, mask: bytes) -> bytes:
    return bytes(image) + bytes(mask)


class MachineClient:
    def __init__(self, transport, tx_cap: int, baud: int = 115200, timeout: float = 0.5, deadline: float = 60.0):
        self.cmd = ParamClient(transport, (), tx_cap, timeout=timeout, deadline=deadline, baud=baud)
        self.cmd.busy_words = ("its EEPROM writer or the check of an uploaded image is still under way "
                               "(`fsw machine list` shows the upload)")
        self.t = transport
        self.on_progress = None  # called with (bytes written, bytes in all)

    @property
    def stats(self):
        return self.cmd.stats

    def _one(self, op: int, args: bytes = b"") -> dict:
        return self.cmd.run([(op, args)])[0]

    def info(self) -> Info:
        ack = self._one(OP_MACHINE_INFO)
        if ack["status"] != 0:
            raise MachineError(f"the target refused MACHINE_INFO: {ack['status_name']}: {ack['reason']} "
                               "(its firmware has no [reload] section?)")
        data = ack["data"]
        if len(data) < RELOAD_INFO.size + 2 * RELOAD_SLOT.size:
            raise MachineError("the target's MACHINE_INFO answer is too short: its firmware has no [reload] section")
        v = RELOAD_INFO.unpack_from(data)
        # slot numbers index the slots: one past them (a target of another
        # version, a corrupted answer) is said, never used
        for field, value, allowed in (("active", v[0], (0, 1, 2)), ("pending", v[1], (0, 1, 2, NONE)),
                                      ("refused", v[2], (0, 1, 2)), ("upload slot", v[7], (0, 1, 2))):
            if value not in allowed:
                raise MachineError(f"the target's MACHINE_INFO answer names {field} {value}: not a slot (1, 2) or "
                                   "the generated machine (0); is its firmware of another kit version?")
        slots = tuple(Slot(i + 1, *RELOAD_SLOT.unpack_from(data, RELOAD_INFO.size + i * RELOAD_SLOT.size))
                      for i in range(2))
        s0, s1 = slots
        return Info(v[0], v[1], v[2], v[3], bool(v[4]), v[5], v[6], v[7], v[8], v[9], v[10], v[11],
                    (Slot(1, s0.status, s0.seq, s0.length, s0.nmask, s0.crc),
                     Slot(2, s1.status, s1.seq, s1.length, s1.nmask, s1.crc)))

    def _wait(self, seconds: float) -> None:
        end = self.t.now() + seconds
        while self.t.now() < end:
            self.t.events(min(0.02, end - self.t.now()))

    def upload(self, image: bytes, mask: bytes, restart: bool = False) -> tuple[int, bool]:
        """The image and its state mask into the target's free slot,
        committed and verified: (the slot, whether an interrupted upload of
        the same bytes was resumed)."""
        data = payload(image, mask)
        crc = crc16(data)
        inf = self.info()
        if len(data) > inf.size:
            raise MachineError(f"the image and its state mask take {len(data)} B: the target's slots hold "
                               f"{inf.size} B ([reload] size)")
        resumed = (not restart and inf.up_slot != 0 and inf.up_len == len(image) and inf.up_nmask == len(mask)
                   and inf.up_crc == crc)
        start = inf.up_next if resumed else 0
        if not resumed:
            ack = self._one(OP_MACHINE_BEGIN, struct.pack("<HBH", len(image), len(mask), crc))
            if ack["status"] != 0:
                raise MachineError(f"upload refused: {ack['status_name']}: {ack['reason']}")
        slot = self.info().up_slot if not resumed else inf.up_slot
        if slot == 0:
            raise MachineError("the target has no upload open after BEGIN")
        off = start - start % CHUNK
        while off < len(data):
            chunk = data[off:off + CHUNK]
            ack = self._one(OP_MACHINE_WRITE, struct.pack("<H", off) + chunk)
            if ack["status"] == NO_LOAD:
                raise MachineError("the target's upload was closed (a reset, or another upload): run the upload "
                                   "again")
            if ack["status"] != 0:
                raise MachineError(f"WRITE at {off} refused: {ack['status_name']}: {ack['reason']}")
            off += len(chunk)
            if self.on_progress is not None:
                self.on_progress(off, len(data))
            self._wait(len(chunk) * EEPROM_BYTE_S)  # the target writes it before it takes the next
        busy = self.stats.busy
        try:
            ack = self._one(OP_MACHINE_COMMIT)
        except ParamError:
            if self.stats.busy - busy < 10:
                raise
            raise MachineError(f"COMMIT: the target answered BUSY {self.stats.busy - busy} times in "
                               f"{self.cmd.deadline:g} s: it was "
                               "still checking the image (a slice at each step of the machine's task and at each "
                               "COMMIT); `fsw machine list` shows the upload, and `upload` again commits it") \
                from None
        if ack["status"] == NO_LOAD:  # an earlier copy was applied and its ack lost: the slot says
            after = self.info()
            s = after.slots[slot - 1]
            if not (s.status != 0 and s.crc == crc and s.length == len(image)):
                raise MachineError("the upload did not complete: run it again")
        elif ack["status"] == MISMATCH:
            raise MachineError(f"the bytes in slot {slot} do not have the image's CRC 0x{crc:04x}: the upload was "
                               "corrupted on the way; run it again")
        elif ack["status"] == BAD_IMAGE:
            code = ack["data"][0] if ack["data"] else -1
            raise MachineError(f"the target's verifier refused the image: {reason_words(code)}; the machine that "
                               "runs is unchanged")
        elif ack["status"] != 0:
            raise MachineError(f"COMMIT refused: {ack['status_name']}: {ack['reason']}")
        self._wait_written()
        return slot, resumed

    def _wait_written(self, budget: float = 5.0) -> Info:
        end = self.t.now() + budget
        while True:
            inf = self.info()
            if not inf.writing:
                return inf
            if self.t.now() > end:
                raise MachineError(f"the target was still writing its EEPROM after {budget:g} s")
            self._wait(0.05)

    def activate(self, which: int, wait: float = 5.0) -> Info:
        """Asks for `which` (0 the generated machine, 1 or 2 a slot) and waits
        until the target runs it; a refusal of its image is an error."""
        before = self.info()
        ack = self._one(OP_MACHINE_ACTIVATE, bytes((which,)))
        if ack["status"] == NO_IMAGE:
            raise MachineError(f"slot {which} holds no committed image")
        if ack["status"] != 0:
            raise MachineError(f"ACTIVATE refused: {ack['status_name']}: {ack['reason']}")
        end = self.t.now() + wait
        while True:
            inf = self.info()
            if inf.active == which and inf.pending == NONE:
                self._wait_written()
                return inf
            if inf.pending == NONE and (inf.refused, inf.reason) != (before.refused, before.reason) \
                    and inf.refused == which:
                raise MachineError(f"the target refused the image in slot {which}: {reason_words(inf.reason)}; "
                                   "the machine that runs is unchanged")
            if inf.pending == NONE and inf.active != which:
                raise MachineError(f"the target did not switch to {which}: it runs {inf.active}")
            if self.t.now() > end:  # INFO does not say which of the two it waits for
                raise MachineError(f"not switched after {wait:g} s: the target checks the image first (a slice "
                                   "at each step of the machine's task), then switches when the running machine is "
                                   "in a state in which another may take over ([reload] activate); the activation "
                                   "stays pending and happens then")
            self._wait(0.05)

    def revert(self, wait: float = 5.0) -> tuple[int, Info]:
        """Back to the machine that ran before: the other slot's image when it
        was activated before the running one, else the generated machine."""
        inf = self.info()
        if inf.active == BUILT_IN:
            raise MachineError("the generated machine runs already: nothing to revert to")
        other = inf.slots[2 - inf.active]
        target = other.number if other.status == 2 else BUILT_IN
        return target, self.activate(target, wait)
