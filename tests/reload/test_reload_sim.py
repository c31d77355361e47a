"""Machines replaced at run time on the simulated Uno (docs/reload.md):
examples/stand (the tank rig with a `[reload]` section) runs its
generated vent controller; the ground uploads examples/stand/tank_700.sm
(the valve opening at 700 instead of 775) over the link and activates it,
and the valve follows the new threshold with no reset. A corrupted image,
one bound to another state vector and one the verifier refuses are each
refused with their reason while the old machine keeps running; an upload
cut short resumes; an activation waits for an allowed state; the board
boots the newest activated image after a power cut, and the generated
machine once reverted; an upload through a link that drops a fifth of the
frames each way completes."""

from __future__ import annotations

import os
import random
import shutil
import struct
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import EXAMPLES, ROOT
from support.simfw import kept_folder

pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                reason="gcc-avr and libsimavr-dev are needed (make setup)")

STAND = EXAMPLES / "stand"
NEW = STAND / "tank_700.sm"
VALVE_PIN = 4  # tank.dio: valveOpen on pin 4


def volts(psi: float) -> float:
    """The transducer's output for a tank pressure (tank.aio: 250 per volt, -125)."""
    return (psi + 125.0) / 250.0


@pytest.fixture(scope="module")
def stand():
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import firmware, load

    app = load(str(STAND), Diagnostics())
    assert app is not None and app.reload is not None
    built = firmware(app, str(kept_folder(STAND, "uno")))  # kept between runs (support.simfw)
    assert built.fits, built.report
    return app, built.artifact


@pytest.fixture(scope="module")
def new_image(stand):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.cli.machine import image_for

    app, _ = stand
    d = Diagnostics()
    built = image_for(app, str(NEW), d)
    assert built is not None, d.render()
    return built[0], built[1]


class Rig:
    """The stand's firmware on a simulated Uno, the tank pressure set on its
    transducer's pin, the ground's machine client on its UART."""

    def __init__(self, app, elf, loss: float = 0.0, seed: int = 1, eeprom: str | None = None):
        from fswkit.autocode.schema import link_plan
        from fswkit.link.layout import from_app
        from fswkit.link.session import Session
        from fswkit.param.client import Lossy, SimTransport
        from fswkit.reload.client import MachineClient
        from fswkit.sim.board import SimBoard

        self.b = SimBoard(elf, "uno", uart="control", sim_limit=600, eeprom=eeprom)
        self.session = Session(from_app(app))
        rnd = random.Random(seed)
        self.up = Lossy(loss, rnd) if loss else None
        self.down = Lossy(loss, rnd) if loss else None
        self.t = SimTransport(self.b, self.session, self.up, self.down)
        self.psi(740)
        while self.session.hello is None and self.b.time < 5:
            self.t.events(0.05)
        assert self.session.hello is not None
        self.c = MachineClient(self.t, link_plan(app).tx_cap, baud=app.baud, timeout=0.3)

    def psi(self, p: float) -> None:
        self.b.set_analog("A0", volts(p))

    def valve_at(self, p: float, settle: float = 0.1) -> bool:
        self.psi(p)
        self.t.events(settle)
        return self.b.digital(VALVE_PIN)

    def close(self) -> None:
        self.b.close()


@pytest.fixture
def rig(stand):
    r = Rig(*stand)
    yield r
    r.close()


def test_the_valve_follows_the_uploaded_threshold_without_a_reset(rig, new_image):
    assert rig.valve_at(740) is False and rig.valve_at(790) is True  # the generated controller: 775
    inf = rig.c.info()
    assert inf.active == 0 and [s.status for s in inf.slots] == [0, 0]
    hellos = rig.session.hellos if hasattr(rig.session, "hellos") else None
    cycles0 = rig.session.health["cycles"] if rig.session.health else 0
    slot, resumed = rig.c.upload(*new_image)
    assert slot == 1 and not resumed
    assert rig.valve_at(740) is False  # committed, not yet running
    inf = rig.c.activate(slot)
    assert inf.active == 1 and inf.slots[0].status == 2 and inf.slots[0].seq == 1
    assert rig.valve_at(740) is True and rig.valve_at(720) is True and rig.valve_at(690) is False
    rig.t.events(1.2)  # a health frame or more since
    assert rig.session.health["cycles"] > cycles0 + 100  # the executor went on counting: no reset
    assert rig.session.health["reset_cause"] == rig.session.hello["reset_cause"]
    if hellos is not None:
        assert rig.session.hellos == hellos
    # and back to the generated machine
    target, inf = rig.c.revert()
    assert target == 0 and inf.active == 0 and [s.status for s in inf.slots] == [1, 0]
    assert rig.valve_at(740) is False and rig.valve_at(790) is True


def _send(rig, data: bytes, crc: int, nmask: int = 1) -> None:
    """BEGIN and every WRITE of `data` (the image, then its `nmask` mask bytes)."""
    from fswkit.autocode.protocol import OP_MACHINE_BEGIN, OP_MACHINE_WRITE
    from fswkit.reload.client import CHUNK

    ack = rig.c._one(OP_MACHINE_BEGIN, struct.pack("<HBH", len(data) - nmask, nmask, crc))
    assert ack["status"] == 0, ack
    for off in range(0, len(data), CHUNK):
        ack = rig.c._one(OP_MACHINE_WRITE, struct.pack("<H", off) + data[off:off + CHUNK])
        assert ack["status"] == 0, ack
        rig.t.events(CHUNK * 0.0035)


def _begin_and_write(rig, data: bytes, crc: int, nmask: int = 1):
    """_send, then COMMIT at once: its acknowledgement."""
    from fswkit.autocode.protocol import OP_MACHINE_COMMIT

    _send(rig, data, crc, nmask)
    return rig.c._one(OP_MACHINE_COMMIT)


def test_a_corrupted_image_is_refused_and_the_old_machine_keeps_running(rig, new_image):
    from fswkit.autocode.protocol import crc16

    image, mask = new_image
    good = image + mask
    bad = bytearray(good)
    bad[60] ^= 0x10  # a byte changed on the way, after the ground computed the CRC
    ack = _begin_and_write(rig, bytes(bad), crc16(good))
    assert ack["status_name"] == "MISMATCH"
    inf = rig.c.info()
    assert inf.active == 0 and [s.status for s in inf.slots] == [0, 0]
    assert rig.valve_at(740) is False and rig.valve_at(790) is True


def test_an_image_of_another_state_vector_is_refused_with_its_reason(rig, stand, new_image, tmp_path):
    """The verifier's reason reaches the ground: reason 4, the schema."""
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.emit.app import real_of
    from fswkit.autocode.emit.bytecode import compile_machine
    from fswkit.autocode.project import load_machine
    from fswkit.reload.client import MachineError

    app, _ = stand
    sv = tmp_path / "other.sv"
    sv.write_text((EXAMPLES / "tank" / "tank.sv").read_text() + "\n[Spare]\nF32 spare\n")
    m = load_machine(str(NEW), Diagnostics(), str(sv))
    assert m is not None
    other = compile_machine(m, real_of(app))
    with pytest.raises(MachineError, match=r"another state vector|schema|verifier reason 4"):
        rig.c.upload(bytes(other), new_image[1])
    inf = rig.c.info()
    assert inf.refused == 1 and inf.reason == 4 and inf.active == 0 and inf.slots[0].status == 0
    assert rig.valve_at(740) is False


def test_an_image_the_verifier_refuses_never_runs(rig, new_image):
    """A jump pointed past the code: the CRC holds (the ground computed it),
    the board's own verifier says no."""
    from fswkit.autocode.protocol import crc16
    from fswkit.autocode.vmverify import REASONS

    image, mask = new_image
    bad = bytearray(image)
    code_size = struct.unpack_from("<H", bad, 26)[0]
    struct.pack_into("<H", bad, 26, code_size + 7)  # the header's code length no longer the image's
    data = bytes(bad) + mask
    ack = _begin_and_write(rig, data, crc16(data))
    assert ack["status_name"] == "BAD_IMAGE" and ack["data"][:1] == bytes((5,)), ack
    assert "lengths" in REASONS[5] or REASONS[5]
    inf = rig.c.info()
    assert inf.refused == 1 and inf.reason == 5 and inf.active == 0
    assert rig.valve_at(740) is False


def _raw(rig, op: int, args: bytes = b"") -> dict:
    """One command and its ack, BUSY included (not tried again)."""
    return rig.c.cmd.run([(op, args)], busy_retry=False)[0]


def _written(rig, data: bytes, crc: int, nmask: int = 1) -> None:
    """_send, and the EEPROM written: COMMIT next."""
    _send(rig, data, crc, nmask)
    while rig.c.info().writing:
        rig.t.events(0.02)


def _commit_until_answered(rig) -> tuple[dict, int]:
    """COMMIT sent again every 20 ms while the board answers BUSY: the
    answer, and how many BUSYs came before it."""
    from fswkit.autocode.protocol import OP_MACHINE_COMMIT

    busy = 0
    while True:
        ack = _raw(rig, OP_MACHINE_COMMIT)
        if ack["status_name"] != "BUSY":
            return ack, busy
        busy += 1
        assert busy < 200, "the check never ended"
        rig.t.events(0.02)


def test_a_commit_is_busy_while_the_board_checks_the_image_then_answers_its_result(rig, new_image):
    """The check (the CRC, then the verifier) runs a slice at each of the
    machine task's steps: the first COMMIT of a whole upload starts it and
    answers BUSY, as do the COMMITs while it runs, and a BEGIN or a WRITE
    meanwhile; the next COMMIT answers OK. Sent again after that (its ack
    lost), COMMIT answers NO_LOAD, as before the checks ran in slices, and
    the slot says the image is stored."""
    from fswkit.autocode.protocol import OP_MACHINE_BEGIN, OP_MACHINE_COMMIT, OP_MACHINE_WRITE, crc16

    image, mask = new_image
    data = image + mask
    _written(rig, data, crc16(data), len(mask))
    assert _raw(rig, OP_MACHINE_COMMIT)["status_name"] == "BUSY"  # the check starts
    begin = struct.pack("<HBH", len(image), len(mask), crc16(data))
    assert _raw(rig, OP_MACHINE_BEGIN, begin)["status_name"] == "BUSY"
    assert _raw(rig, OP_MACHINE_WRITE, struct.pack("<H", 0) + data[:8])["status_name"] == "BUSY"
    ack, busy = _commit_until_answered(rig)
    assert ack["status_name"] == "OK" and busy >= 1, (ack, busy)  # still running after the BEGIN and the WRITE
    while rig.c.info().writing:  # the header
        rig.t.events(0.02)
    assert _raw(rig, OP_MACHINE_COMMIT)["status_name"] == "NO_LOAD"
    inf = rig.c.info()
    assert inf.up_slot == 0 and inf.slots[0].status == 1 and inf.slots[0].crc == crc16(data)
    assert inf.slots[0].length == len(image) and inf.refused == 0
    rig.c.activate(1)
    assert rig.valve_at(740) is True


def test_a_mismatch_leaves_the_upload_open_and_a_write_mends_it(rig, new_image):
    """A COMMIT sent again after MISMATCH checks the bytes again (BUSY, then
    MISMATCH): the answer is not lost. The byte written again, the next
    COMMIT answers OK."""
    from fswkit.autocode.protocol import OP_MACHINE_WRITE, crc16

    image, mask = new_image
    good = image + mask
    bad = bytearray(good)
    bad[60] ^= 0x10
    _written(rig, bytes(bad), crc16(good), len(mask))
    ack, busy = _commit_until_answered(rig)
    assert ack["status_name"] == "MISMATCH" and busy >= 1, (ack, busy)
    ack, busy = _commit_until_answered(rig)  # sent again: its ack lost
    assert ack["status_name"] == "MISMATCH" and busy >= 1, (ack, busy)
    assert rig.c.info().up_slot == 1
    assert rig.c._one(OP_MACHINE_WRITE, struct.pack("<H", 56) + good[56:64])["status"] == 0
    while rig.c.info().writing:
        rig.t.events(0.02)
    ack, _ = _commit_until_answered(rig)
    assert ack["status_name"] == "OK", ack


def test_a_commit_goes_through_with_the_machine_task_disabled(rig, new_image):
    """The checks run at the machine task's steps, and at a COMMIT when no
    step ran one since the one before: with that task disabled (MODE), the
    ground's COMMITs carry the check on and the upload commits; the
    activation waits for the task (its switch is a step of it)."""
    from fswkit.autocode.protocol import OP_MODE

    control = 2  # stand.app's tasks: uplink, sense, control, act, downlink
    assert rig.c._one(OP_MODE, bytes((control, 0)))["status"] == 0
    busy = rig.c.stats.busy
    t0 = rig.t.now()
    slot, resumed = rig.c.upload(*new_image)
    assert slot == 1 and not resumed
    assert rig.c.info().slots[0].status == 1  # stored: committed and verified
    assert rig.c.stats.busy - busy >= 5, "the check took several COMMITs"
    print(f"upload with the machine task disabled: {rig.t.now() - t0:.2f} s simulated, "
          f"{rig.c.stats.busy - busy} BUSY answers")
    assert rig.c._one(OP_MODE, bytes((control, 2)))["status"] == 0
    assert rig.valve_at(740) is False  # the generated controller (775) runs again
    inf = rig.c.activate(slot)
    assert inf.active == 1 and rig.valve_at(740) is True


def test_a_byte_changed_in_the_eeprom_after_the_commit_is_refused_at_the_activation(rig, new_image):
    """The activation checks the slot again (in slices, as soon as ACTIVATE
    arrives): its CRC no longer holds, the generated machine runs on."""
    from fswkit.reload.client import MachineError

    slot, _ = rig.c.upload(*new_image)
    at = 9 + 40  # slot 1's image (the stand's slots start the EEPROM), byte 40
    rig.b.eeprom_write(at, bytes((rig.b.eeprom_read(at, 1)[0] ^ 0x01,)))
    with pytest.raises(MachineError, match="no longer have the CRC"):
        rig.c.activate(slot)
    inf = rig.c.info()
    assert inf.active == 0 and inf.pending == 0xFF and inf.refused == 1 and inf.reason == 0x80
    assert rig.valve_at(740) is False and rig.valve_at(790) is True


def test_an_interrupted_upload_resumes(rig, new_image):
    class Cut(Exception):
        pass

    def stop_after_half(done, total):
        if done >= total // 2:
            raise Cut

    rig.c.on_progress = stop_after_half
    with pytest.raises(Cut):
        rig.c.upload(*new_image)
    inf = rig.c.info()
    assert inf.up_slot == 1 and 0 < inf.up_next < inf.up_len + inf.up_nmask
    rig.c.on_progress = None
    sent = rig.c.stats.sent
    slot, resumed = rig.c.upload(*new_image)
    assert slot == 1 and resumed
    assert rig.c.stats.sent - sent < 16  # the second half only, and the commit
    rig.c.activate(slot)
    assert rig.valve_at(740) is True


def test_an_activation_waits_for_an_allowed_state(rig, new_image):
    """In Abort (not in [reload] activate) the switch waits; the old
    machine runs on."""
    from fswkit.reload.client import MachineError

    slot, _ = rig.c.upload(*new_image)
    assert rig.valve_at(900, settle=0.2) is True  # over 825: Abort (its exit opened the valve)
    with pytest.raises(MachineError, match="stays pending"):
        rig.c.activate(slot, wait=0.5)
    inf = rig.c.info()
    assert inf.pending == slot and inf.active == 0


def test_the_board_boots_the_newest_activated_image_after_a_power_cut(rig, new_image):
    slot, _ = rig.c.upload(*new_image)
    rig.c.activate(slot)
    rig.b.reset("power")
    rig.t.events(0.5)
    inf = rig.c.info()
    assert inf.active == slot and inf.slots[0].status == 2
    assert rig.valve_at(740) is True
    rig.c.activate(0)
    rig.b.reset("power")
    rig.t.events(0.5)
    assert rig.c.info().active == 0 and rig.valve_at(740) is False


def test_an_upload_through_a_lossy_link(stand, new_image):
    r = Rig(*stand, loss=0.2, seed=3)
    try:
        slot, _ = r.c.upload(*new_image)
        r.c.activate(slot)
        assert r.up.dropped > 0 and r.down.dropped > 0 and r.c.stats.resent > 0
        assert r.valve_at(740) is True
    finally:
        r.close()


def test_fsw_machine_on_the_simulated_port(stand):
    """The command a crew types, against `fsw sim`'s pty: list, upload
    --activate, revert; and a machine file the project cannot take is
    refused before any port is opened."""
    app, elf = stand
    p = subprocess.Popen([sys.executable, "-m", "fswkit.cli", "sim", elf, "--board", "uno", "--duration", "60",
                          "--analog", f"A0={volts(740):.3f}"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT, start_new_session=True)
    try:
        port = p.stdout.readline().strip()
        assert port.startswith("/dev/pts/"), p.stderr.read()

        def fsw(*a):
            return subprocess.run([sys.executable, "-m", "fswkit.cli", "machine", str(STAND), *a, "--port", port],
                                  capture_output=True, text=True, cwd=ROOT, timeout=120)

        r = fsw("list")
        assert r.returncode == 0, r.stderr
        assert "the generated `tank` runs" in r.stdout and "slot 1: empty" in r.stdout
        r = fsw("upload", str(NEW), "--activate")
        assert r.returncode == 0, r.stderr
        assert "committed in slot 1, verified by the target" in r.stdout and "slot 1 runs" in r.stdout
        assert "the image in slot 1 runs" in r.stdout
        r = fsw("revert")
        assert r.returncode == 0, r.stderr
        assert "reverted: the generated machine runs" in r.stdout
        r = fsw("upload", str(EXAMPLES / "tank" / "tank_typo.sm"))
        assert r.returncode == 2 and "tank_typo.sm:" in r.stderr and "Traceback" not in r.stderr
    finally:
        p.kill()
        p.wait()


def test_a_power_cut_at_any_eeprom_write_boots_the_old_machine_or_the_new(stand, new_image):
    """Every 17th EEPROM byte write of an upload and its activation, and each
    of the last nine (the header, its magic, the boot order), cut by a power
    loss; `make bench` cuts at every one."""
    from fswkit.reload.sim import power_cuts

    app, elf = stand
    r = power_cuts(elf, "uno", app, *new_image, stride=17, analog={"A0": volts(740)})
    # the image's bytes (but those an erased EEPROM holds already, 0xFF), the
    # header, its magic, the order
    assert r.writes > sum(b != 0xFF for b in new_image[0])
    assert r.bad == []
    assert r.old > 0 and r.new > 0 and r.old + r.new == r.cases


@pytest.mark.parametrize("cut", [1, 2])
def test_a_power_cut_while_both_slots_lose_their_boot_mark_never_boots_the_older_image(stand, new_image, cut):
    """Slot 1 runs the newest image, slot 2 holds one activated before it;
    the crew goes back to the generated machine and the power is cut after
    the first or second EEPROM write of that: the board comes back running
    slot 1's image (what ran before) or the generated machine, never slot
    2's older one."""
    r = Rig(*stand)
    try:
        for _ in range(3):  # slots 1, 2, then 1 again: slot 1 newest, slot 2 older
            slot, _ = r.c.upload(*new_image, restart=True)
            r.c.activate(slot)
        inf = r.c.info()
        assert inf.active == 1 and [s.status for s in inf.slots] == [2, 2] and inf.slots[0].seq > inf.slots[1].seq
        from fswkit.autocode.protocol import OP_MACHINE_ACTIVATE
        from fswkit.link import wire

        r.b.eeprom_cut(cut)
        # ACTIVATE 0 sent once, not again after the cut (a client would resend it)
        r.t.send(wire.uplink(OP_MACHINE_ACTIVATE, r.c.cmd.numbers.take(), b"\x00"))
        while r.b.eeprom_count()[1] == 0 and r.b.time < 600:
            r.t.events(0.01)
        assert r.b.eeprom_count()[1] == 1  # the cut happened
        r.psi(740)
        r.t.events(0.3)
        inf = r.c.info()
        assert inf.active in (1, 0), inf
        assert inf.active == (1 if cut == 1 else 0)  # one status byte written, or both
    finally:
        r.close()


@pytest.mark.parametrize("mask_of", [
    lambda mask: b"",                          # no mask at all
    lambda mask: bytes(len(mask)),             # no state lets the machine go
    lambda mask: mask + b"\xff",               # a byte more than the image's states
], ids=["none", "empty", "long"])
def test_a_state_mask_that_would_hold_the_machine_for_good_is_refused(rig, new_image, mask_of):
    """The board checks the mask the ground sends, as it checks the image:
    one a ground of its own made wrong (none, no state set, a byte too many)
    would leave a machine no state lets go, not even back to the generated
    one, and the EEPROM would keep it across a reflash. BAD_IMAGE with
    reason 17; the generated machine keeps running."""
    from fswkit.autocode.protocol import crc16
    from fswkit.autocode.vmverify import BAD_MASK, REASONS

    image, mask = new_image
    bad = mask_of(mask)
    data = image + bad
    _written(rig, data, crc16(data), len(bad))
    ack, _ = _commit_until_answered(rig)
    assert ack["status_name"] == "BAD_IMAGE" and ack["data"][:1] == bytes((BAD_MASK,)), ack
    assert "mask" in REASONS[BAD_MASK]
    inf = rig.c.info()
    assert inf.refused in (1, 2) and inf.reason == BAD_MASK and inf.active == 0
    assert rig.valve_at(740) is False and rig.valve_at(790) is True


def test_the_activation_order_wraps_and_the_newest_still_boots(rig, new_image):
    """The activation order is 16 bits: after 65,535 activations the newest
    slot's is 0 and the older one's 65,535. The board boots the newest by
    serial-number arithmetic (it booted the older one: 65,535 > 0)."""
    slot, _ = rig.c.upload(*new_image)
    rig.c.activate(slot)
    other, _ = rig.c.upload(*new_image)  # the same image into the other slot, then the newest
    rig.c.activate(other)
    inf = rig.c.info()
    assert {slot, other} == {1, 2} and inf.active == other
    assert inf.slots[other - 1].seq == inf.slots[slot - 1].seq + 1
    while rig.c.info().writing:
        rig.t.events(0.02)
    # the two orders as 65,535 activations later: the older 0xFFFF, the newest 0 (slot headers from
    # EEPROM byte 0, examples/stand's slots of 384 B and a 9-byte header: order u16 at bytes 2..3)
    for n, seq in ((slot, 0xFFFF), (other, 0x0000)):
        rig.b.eeprom_write((n - 1) * (9 + 384) + 2, struct.pack("<H", seq))
    rig.b.reset("power")
    rig.t.events(0.5)
    inf = rig.c.info()
    assert inf.active == other, inf
    assert (inf.slots[slot - 1].seq, inf.slots[other - 1].seq) == (0xFFFF, 0), inf
    rig.c.activate(slot)  # and the next activation comes after both
    inf = rig.c.info()
    assert inf.active == slot and inf.slots[slot - 1].seq == 1, inf


def test_an_image_activated_against_any_order_of_the_other_slot_boots(rig, new_image):
    """The new order is the other slot's plus one, whatever this slot's own
    (a commit sets it 0): taking the later of the two by serial-number
    arithmetic gave 1 against 32,769, which is not after it."""
    slot, _ = rig.c.upload(*new_image)
    rig.c.activate(slot)
    while rig.c.info().writing:
        rig.t.events(0.02)
    rig.b.eeprom_write((slot - 1) * (9 + 384) + 2, struct.pack("<H", 32769))
    rig.b.reset("power")
    rig.t.events(0.5)
    assert rig.c.info().active == slot
    other, _ = rig.c.upload(*new_image)  # committed: its order 0
    rig.c.activate(other)
    while rig.c.info().writing:
        rig.t.events(0.02)
    assert rig.c.info().slots[other - 1].seq == 32770
    rig.b.reset("power")
    rig.t.events(0.5)
    assert rig.c.info().active == other
