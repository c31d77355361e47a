"""The simulated board's SPI NOR flash (harness -s/-S, SimBoard(spi_flash=,
flash_file=)) as firmware sees it through the AVR's SPI, and the EEPROM
file (-E, eeprom_file=).

The firmware is tests/sim/spiflash_probe/probe.c, built here with avr-gcc:
it runs a script of SPI transactions sent over UART0 and answers with the
bytes shifted in (see its header). simavr 1.6 shifts an SPI byte in 100 us,
whatever the clock divider, so a status poll takes about 0.2 ms: the page
program's 0.4 ms is bracketed with single status reads timed by the probe."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from support.uartprobe import UartProbe, build_probe
from fswkit.sim.board import SimBoard, SimError, harness

pytestmark = pytest.mark.skipif(
    shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
    reason="gcc-avr (to build the probe firmware) and libsimavr-dev are needed (make setup)")

PROBE_C = Path(__file__).resolve().parent / "spiflash_probe" / "probe.c"
TICK = 0.5e-6  # the probe's Timer1 tick
MIB = 1 << 20


@pytest.fixture(scope="module")
def probe(tmp_path_factory) -> str:
    return build_probe(PROBE_C, tmp_path_factory.mktemp("spiflash"))


def op(code: int, addr: int | None = None, data: bytes = b"", read: int = 0) -> str:
    """One transaction's step: the opcode, a 24-bit address, data, `read` dummy bytes."""
    return f"{code:02x}" + (f"{addr:06x}" if addr is not None else "") + data.hex() + "ff" * read


def tail(step: str, n: int) -> bytes:
    """The last n bytes a transaction shifted in."""
    return bytes.fromhex(step)[-n:]


def status_of(step: str) -> tuple[int, float]:
    """An S step's result: (status register 1, seconds since the clock started)."""
    assert step[0] == "S", step
    return int(step[1:3], 16), int(step[3:9], 16) * TICK


def wait_of(step: str) -> float:
    """A W step's result: seconds from the clock's start to the poll that saw BUSY clear."""
    assert step[0] == "W", step
    return int(step[1:9], 16) * TICK


def sample_at(seconds: float) -> str:
    return f"S{round(seconds / TICK):08x}"


class Probe(UartProbe):
    """Talks to probe.c on a SimBoard's UART0, advancing simulated time."""

    def __init__(self, board: SimBoard):
        super().__init__(board)

    def boot(self) -> list[str]:
        line = self.line()
        assert line.startswith("boot "), line
        return line[5:].split(",")

    def send(self, *steps: str) -> None:
        self.b.uart_write((",".join(steps) + "\n").encode())

    def run(self, *steps: str, limit_s: float = 2.0, step_s: float = 0.002) -> list[str]:
        self.send(*steps)
        out = self.line(limit_s, step_s).split(",")
        assert len(out) == len(steps)
        return out


def board(elf: str, **kw) -> SimBoard:
    return SimBoard(elf, "uno", sim_limit=120, wall_limit=120, **kw)


# ---- the chip as firmware sees it -----------------------------------------------------

def test_boot_script_reads_the_id_programs_and_erases(probe):
    """The probe's own script: JEDEC ID, write enable, a page program seen
    busy and polled, read back, a sector erase seen busy and polled (45 ms
    typical), read back erased."""
    with board(probe, spi_flash="B2") as b:
        r = Probe(b).boot()
        assert tail(r[0], 3) == bytes([0xEF, 0x40, 0x17])  # Winbond, W25Q..JV, 2^23 bytes
        assert tail(r[2], 1) == b"\x02"  # WEL after 06h
        st, t = status_of(r[4])
        assert st == 0x03 and t < 0.4e-3  # BUSY and WEL right after the program's CS rose
        assert 0.4e-3 <= wait_of(r[5]) < 0.4e-3 + 0.25e-3  # seen clear at the first poll after 0.4 ms
        assert tail(r[6], 1) == b"\x00"  # WEL cleared by the program's end
        assert tail(r[7], 16) == bytes.fromhex("0123456789abcdeffedcba9876543210")
        st, _ = status_of(r[10])
        assert st == 0x03
        assert 45e-3 * 0.8 <= wait_of(r[11]) <= 45e-3 * 1.2
        assert tail(r[12], 16) == b"\xff" * 16
        info = b.flash_info()
        assert info["jedec"] == bytes([0xEF, 0x40, 0x17]) and info["size"] == 8 * MIB and info["cs"] == "B2"
        assert (info["programs"], info["erases"], info["busy"], info["wel"]) == (1, 1, False, False)
        assert b.flash_read(0, 4096) == b"\xff" * 4096


def test_page_program_is_busy_for_0_4_ms(probe):
    """A single status read just before and just after 0.4 ms from the CS
    rise that started a page program: busy, then done (so 0.4 ms +-20 %)."""
    with board(probe, spi_flash="B2") as b:
        p = Probe(b)
        p.boot()
        _, t = status_of(p.run("05", sample_at(1e-3))[1])
        cost = t - 1e-3  # how long a status read takes here
        samples = []
        for i, target in enumerate((0.34e-3, 0.38e-3, 0.42e-3, 0.46e-3)):
            r = p.run("06", op(0x02, 0x10000 + 256 * i, b"\x00" * 4), sample_at(max(target - cost, 0)),
                      "W00000000")
            samples.append(status_of(r[2]))
        for (st, t), target in zip(samples, (0.34e-3, 0.38e-3, 0.42e-3, 0.46e-3)):
            assert abs(t - target) < 0.01e-3, (t, target)  # read when asked
            assert st & 1 == (1 if target < 0.4e-3 else 0), (hex(st), t)
        assert b.flash_read(0x10000, 4) == b"\x00" * 4


@pytest.mark.parametrize("code, size, seconds", [(0x20, 4096, 45e-3), (0x52, 32768, 120e-3),
                                                 (0xD8, 65536, 150e-3)])
def test_erases_take_the_datasheet_times(probe, code, size, seconds):
    with board(probe, spi_flash="B2") as b:
        p = Probe(b)
        p.boot()
        base = 0x100000
        b.flash_write(base - 1, b"\x00" * (size + 2))
        # an address inside the sector or block: it is aligned down
        r = p.run("06", op(code, base + size // 2 + 5), "W00000000", limit_s=2, step_s=0.01)
        assert seconds * 0.8 <= wait_of(r[2]) <= seconds * 1.2
        assert b.flash_read(base - 1, size + 2) == b"\x00" + b"\xff" * size + b"\x00"


def test_chip_erase_scales_with_size(probe):
    """20 s typical for 8 MiB: 2.5 s for a 1 MiB chip (the W25Q80's class)."""
    with board(probe, spi_flash="B2:1048576") as b:
        p = Probe(b)
        p.boot()
        b.flash_write(MIB - 4096, b"\x00" * 4096)
        b.flash_write(0x5000, b"\x12" * 4)
        r = p.run("06", "c7", "05ff", "W00000000", limit_s=5, step_s=0.05)
        assert tail(r[2], 1) == b"\x03"
        assert 2.5 * 0.8 <= wait_of(r[3]) <= 2.5 * 1.2
        assert b.flash_read(MIB - 4096, 4096) == b"\xff" * 4096 and b.flash_read(0x5000, 4) == b"\xff" * 4
        r = p.run("06", "60", "W00000000", limit_s=5, step_s=0.05)  # the other opcode
        assert 2.0 <= wait_of(r[2]) <= 3.0


@pytest.mark.parametrize("size, cap", [(MIB, 0x14), (16 * MIB, 0x18), (65536, 0x10)])
def test_ids_follow_the_size(probe, size, cap):
    with board(probe, spi_flash=f"B2:{size}") as b:
        p = Probe(b)
        assert tail(p.boot()[0], 3) == bytes([0xEF, 0x40, cap])
        r = p.run(op(0x9F, read=3), op(0x90, 0, read=4), op(0x90, 1, read=2), op(0xAB, 0, read=2))
        assert tail(r[0], 3) == bytes([0xEF, 0x40, cap])
        assert tail(r[1], 4) == bytes([0xEF, cap - 1, 0xEF, cap - 1])  # address 0: manufacturer first
        assert tail(r[2], 2) == bytes([cap - 1, 0xEF])
        assert tail(r[3], 2) == bytes([cap - 1, cap - 1])
        assert b.flash_info()["size"] == size


def test_programming_only_clears_bits_and_wraps_in_the_page(probe):
    with board(probe, spi_flash="B2") as b:
        p = Probe(b)
        p.boot()
        b.flash_write(0x3000, bytes([0x0F, 0x0F, 0x0F, 0x0F, 0x3C]))
        r = p.run("06", op(0x02, 0x3000, b"\xf0" * 5), "W00000000", op(0x03, 0x3000, read=6))
        assert tail(r[3], 6) == bytes([0, 0, 0, 0, 0x30, 0xFF])
        assert b.flash_read(0x3000, 6) == bytes([0, 0, 0, 0, 0x30, 0xFF])
        # 32 bytes from column 0xF0: the last 16 wrap to the page's start
        data = bytes(range(32))
        p.run("06", op(0x02, 0x40F0, data), "W00000000")
        assert b.flash_read(0x40F0, 16) == data[:16]
        assert b.flash_read(0x4000, 16) == data[16:]
        assert b.flash_read(0x4010, 0xE0) == b"\xff" * 0xE0 and b.flash_read(0x4100, 16) == b"\xff" * 16
        # more than a page: the first bytes are overwritten by the later ones
        p.run("06", op(0x02, 0x5000, b"\xaa" * 4 + b"\xff" * 252 + b"\x55" * 2), "W00000000")
        assert b.flash_read(0x5000, 4) == bytes([0x55, 0x55, 0xAA, 0xAA])


def test_reads_are_continuous_and_wrap_at_the_end(probe):
    with board(probe, spi_flash="B2") as b:
        p = Probe(b)
        p.boot()
        end = 8 * MIB
        b.flash_write(end - 2, b"\x11\x22")
        b.flash_write(0, b"\x33\x44")
        r = p.run(op(0x03, end - 2, read=4), op(0x0B, end - 1, read=1 + 3), op(0x03, 0x1000000 - 2, read=2))
        assert tail(r[0], 4) == bytes.fromhex("11223344")
        assert tail(r[1], 3) == bytes.fromhex("223344")  # fast read: a dummy byte first
        assert tail(r[2], 2) == bytes.fromhex("1122")  # address bits above the array are ignored


def test_program_and_erase_need_write_enable(probe):
    with board(probe, spi_flash="B2") as b:
        p = Probe(b)
        p.boot()
        b.flash_write(0x6000, b"\x5a" * 4)
        before = b.flash_info()
        r = p.run(op(0x02, 0x6000, b"\x00" * 4), "S00000000", op(0x20, 0x6000), "S00000000",
                  "06", "04", op(0x02, 0x6000, b"\x00" * 4), "S00000000", op(0x03, 0x6000, read=4))
        assert status_of(r[1])[0] == 0 and status_of(r[3])[0] == 0 and status_of(r[7])[0] == 0  # never busy
        assert tail(r[8], 4) == b"\x5a" * 4
        after = b.flash_info()
        assert (after["programs"], after["erases"]) == (before["programs"], before["erases"])
        # a write enable of other than 8 bits is no write enable
        r = p.run("0600", "05ff", "06", "05ff", op(0x02, 0x6000, b"\x00" * 4), "W00000000", "05ff")
        assert tail(r[1], 1) == b"\x00" and tail(r[3], 1) == b"\x02" and tail(r[6], 1) == b"\x00"
        assert b.flash_read(0x6000, 4) == b"\x00" * 4
        assert b.flash_info()["programs"] == before["programs"] + 1


def test_commands_are_ignored_while_busy(probe):
    """During a 45 ms sector erase: the status reads answer, every other
    command is ignored (no ID, no data, no write disable, no program)."""
    with board(probe, spi_flash="B2") as b:
        p = Probe(b)
        p.boot()
        b.flash_write(0x7000, b"\x5a" * 4)
        r = p.run("06", op(0x20, 0x8000), op(0x9F, read=3), op(0x03, 0x7000, read=4), "04",
                  "06", op(0x02, 0x7000, b"\x00" * 4), "05ff", "35ff", "W00000000",
                  op(0x03, 0x7000, read=4), "05ff", op(0x9F, read=3))
        assert tail(r[2], 3) == b"\xff" * 3
        assert tail(r[3], 4) == b"\xff" * 4
        assert tail(r[7], 1) == b"\x03"  # still busy, WEL kept: the 04h was ignored
        assert tail(r[8], 1) == b"\x00"
        assert 45e-3 * 0.8 <= wait_of(r[9]) <= 45e-3 * 1.2
        assert tail(r[10], 4) == b"\x5a" * 4  # the program sent while busy did nothing
        assert tail(r[11], 1) == b"\x00"
        assert tail(r[12], 3) == bytes([0xEF, 0x40, 0x17])
        assert b.flash_info()["programs"] == 1  # the boot script's only


def test_power_down_ignores_all_but_release(probe):
    with board(probe, spi_flash="B2") as b:
        p = Probe(b)
        p.boot()
        r = p.run("b9", op(0x9F, read=3), "05ff", op(0xAB, 0, read=1), op(0x9F, read=3))
        assert tail(r[1], 3) == b"\xff" * 3 and tail(r[2], 1) == b"\xff"
        assert tail(r[3], 1) == b"\x16"
        assert tail(r[4], 3) == bytes([0xEF, 0x40, 0x17])


# ---- files -------------------------------------------------------------------------------

def test_flash_file_keeps_the_bytes_between_runs(probe, tmp_path):
    f = tmp_path / "flash.bin"
    with board(probe, spi_flash="B2", flash_file=str(f)) as b:
        p = Probe(b)
        p.boot()
        p.run("06", op(0x02, 0x20000, b"persist"), "W00000000")
        assert not f.exists()  # written at exit
    assert f.stat().st_size == 8 * MIB
    assert f.read_bytes()[0x20000:0x20008] == b"persist\xff"
    with board(probe, spi_flash="B2", flash_file=str(f)) as b:
        assert b.flash_read(0x20000, 7) == b"persist"
        p = Probe(b)
        p.boot()
        assert tail(p.run(op(0x03, 0x20000, read=7))[0], 7) == b"persist"
        b.flash_write(0x7FFFF0, b"end")
    assert f.read_bytes()[0x7FFFF0:0x7FFFF3] == b"end"
    assert f.read_bytes()[0x20000:0x20007] == b"persist"


def test_a_file_of_another_size_is_refused(probe, tmp_path):
    f = tmp_path / "small.bin"
    f.write_bytes(b"\x00" * 1000)
    with pytest.raises(SimError, match="holds 1000 bytes"):
        board(probe, spi_flash="B2", flash_file=str(f))
    for opts in (["-s", "B2", "-S", str(f)], ["-E", str(f)]):
        r = subprocess.run([harness(), "-c"] + opts + [probe], input="quit\n", capture_output=True, text=True,
                           timeout=30)
        assert r.returncode == 2, r
        assert "holds 1000 bytes" in r.stderr and "another chip or board" in r.stderr
        assert r.stdout == ""  # no greeting: it stopped before running anything
    assert f.read_bytes() == b"\x00" * 1000  # left as it was


def test_eeprom_file_keeps_the_eeprom_between_runs(probe, tmp_path):
    f = tmp_path / "eeprom.bin"
    with board(probe, eeprom_file=str(f)) as b:
        assert b.eeprom_read(16, 4) == b"\xff" * 4  # simavr's blank EEPROM
        b.eeprom_write(16, b"kept")
        b.run_for(0.01)
    assert f.stat().st_size == 1024  # the ATmega328P's EEPROM
    with board(probe, eeprom_file=str(f)) as b:
        assert b.eeprom_read(16, 4) == b"kept"
        b.eeprom_write(20, b"!")
    assert f.read_bytes()[16:21] == b"kept!"
    with board(probe) as b:  # without the file: blank again
        assert b.eeprom_read(16, 4) == b"\xff" * 4


# ---- power cuts ---------------------------------------------------------------------------

def _cut_during(probe: str, setup, steps: tuple[str, ...]) -> tuple[SimBoard, dict]:
    """Runs `steps` with a flash cut armed for their first program or erase;
    returns the board (the probe rebooted) and the chip's state just after the cut."""
    b = board(probe, spi_flash="B2")
    p = Probe(b)
    p.boot()
    setup(b)
    b.flash_cut(1)
    assert b.flash_info()["armed"]
    p.send(*steps)
    for _ in range(2000):  # until the cut: the probe's boot script starts over later
        b.step(b.cycles_for(0.0002))
        info = b.flash_info()
        if info["cuts"]:
            break
    assert info["cuts"] == 1, info
    p.buf += b.uart_read()
    assert p.boot()  # the AVR reset: its boot script ran again, not the rest of the line
    return b, info


def _leading(data: bytes, value: int) -> int:
    return len(data) - len(data.lstrip(bytes([value])))


def test_flash_cut_leaves_a_page_half_programmed_and_resets(probe):
    ks = []
    for _ in range(2):
        b, info = _cut_during(probe, lambda b: None, ("06", op(0x02, 0x30000, b"\x00" * 256)))
        with b:
            assert (info["busy"], info["wel"], info["armed"]) == (False, False, False)
            page = b.flash_read(0x30000, 256)
            k = _leading(page, 0x00)
            assert 0 < k < 256 and page == b"\x00" * k + b"\xff" * (256 - k)
            ks.append(k)
    assert ks[0] == ks[1]  # the same operation count gives the same cut


def test_flash_cut_leaves_a_sector_half_erased(probe):
    def setup(b):
        b.flash_write(0x40000, b"\x00" * 4096)

    b, info = _cut_during(probe, setup, ("06", op(0x20, 0x40000)))
    with b:
        assert not info["busy"] and not info["wel"]
        sector = b.flash_read(0x40000, 4096)
        k = _leading(sector, 0xFF)
        assert 0 < k < 4096 and sector == b"\xff" * k + b"\x00" * (4096 - k)
        assert b.flash_read(0x41000, 4) == b"\xff" * 4


def test_flash_commands_check_their_input(probe):
    with board(probe) as b:
        with pytest.raises(SimError, match="no SPI flash"):
            b.flash_info()
    with pytest.raises(SimError, match="power of two"):
        board(probe, spi_flash="B2:1000")
    with pytest.raises(SimError, match="port and bit"):
        board(probe, spi_flash="Z9")
    with board(probe, spi_flash="B2:65536") as b:
        with pytest.raises(SimError, match="flash read"):
            b.flash_read(65530, 8)
        with pytest.raises(SimError, match="beyond"):
            b.flash_write(65535, b"ab")
        b.flash_write(100, b"\x00\x01")
        b.flash_erase()
        assert b.flash_read(100, 2) == b"\xff\xff"
        with pytest.raises(SimError, match="flash cut N"):
            b.command("flash cut 0")
