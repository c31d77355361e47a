"""Reset causes on the simulated board (harness `reset [CAUSE]`,
SimBoard.reset(cause)): after each reset MCUSR holds exactly that cause's
flag, as the firmware reads it at boot; brown-out, watchdog and external
resets keep SRAM, a power-on leaves pseudo-random bytes there (from the
board's ram_seed: the same seed, the same bytes).

The firmware is tests/sim/reset_probe/probe.c, built here with avr-gcc: at
each boot it prints MCUSR as read in .init3 and an 8-byte pattern kept in
.noinit, then writes the pattern again."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from fswkit.sim.board import RESET_CAUSES, RESET_FLAGS, SimBoard, SimError

pytestmark = pytest.mark.skipif(
    shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
    reason="gcc-avr (to build the probe firmware) and libsimavr-dev are needed (make setup)")

PROBE_C = Path(__file__).resolve().parent / "reset_probe" / "probe.c"
PATTERN = "f53ca7196ed2845b"
BOOT = re.compile(r"boot n=([0-9a-f]{2}) mcusr=([0-9a-f]{2}) kept=([0-9a-f]{16})")


def _build(tmp_path_factory, name: str, *defines: str) -> str:
    elf = tmp_path_factory.mktemp("reset") / f"{name}.elf"
    r = subprocess.run(["avr-gcc", "-mmcu=atmega328p", "-DF_CPU=16000000UL", "-Os", "-Wall", "-Wextra", "-Werror",
                        *defines, "-o", str(elf), str(PROBE_C)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return str(elf)


@pytest.fixture(scope="module")
def probe(tmp_path_factory) -> str:
    return _build(tmp_path_factory, "probe")


def boots(b: SimBoard, seconds: float = 0.01) -> list[tuple[int, int, str]]:
    """The boot lines the probe printed in the next `seconds`: (n, MCUSR, kept bytes)."""
    b.run_for(seconds)
    return [(int(n, 16), int(m, 16), k) for n, m, k in BOOT.findall(b.uart_read().decode())]


def test_each_cause_leaves_its_flag_alone_and_ram_as_a_real_reset_would(probe):
    with SimBoard(probe, "uno", sim_limit=10, wall_limit=30) as b:
        assert boots(b) == [(1, RESET_FLAGS["power"], "00" * 8)]  # simavr's first power-on: zeroed RAM
        n = 1
        for cause in ("brownout", "watchdog", "external", "brownout", "watchdog", "external"):
            b.reset(cause)
            n += 1
            assert boots(b, 0.05) == [(n, RESET_FLAGS[cause], PATTERN)], cause  # one boot: SRAM kept
        b.reset("power")
        [(n, mcusr, kept)] = boots(b, 0.05)
        assert mcusr == RESET_FLAGS["power"] == 0x01
        assert kept != PATTERN and n == 1  # nothing in RAM passes as kept
        assert kept != "00" * 8 and kept != "ff" * 8
        b.reset()  # the default: a brown-out
        assert boots(b) == [(2, RESET_FLAGS["brownout"], PATTERN)]


def test_a_power_cut_is_a_power_on(probe):
    """`eeprom cut`: the power goes right after an EEPROM write; the MCU
    comes back as from a power-on (PORF, RAM not kept), the EEPROM keeping
    the byte."""
    with SimBoard(probe, "uno", sim_limit=10, wall_limit=30) as b:
        boots(b)
        b.eeprom_cut(1)
        b.reset("brownout")  # its boot writes the EEPROM once: the cut
        [(n, mcusr, kept), (n2, mcusr2, kept2)] = boots(b, 0.05)
        assert (n, mcusr, kept) == (2, RESET_FLAGS["brownout"], PATTERN)
        assert mcusr2 == RESET_FLAGS["power"] and kept2 != PATTERN and n2 == 1
        assert b.eeprom_count()[1] == 1 and b.eeprom_read(0, 1) == b"\x01"


def test_the_flags_are_the_atmega328ps():
    assert RESET_CAUSES == ("brownout", "watchdog", "external", "power")
    assert RESET_FLAGS == {"power": 0x01, "external": 0x02, "brownout": 0x04, "watchdog": 0x08}


def test_power_on_ram_is_the_seeds(probe):
    def after_power(seed: int) -> tuple[str, bytes]:
        with SimBoard(probe, "uno", sim_limit=10, wall_limit=30, ram_seed=seed) as b:
            boots(b)
            b.reset("power")
            # the top of RAM as the power-on left it (the probe's stack is a few bytes deep)
            ram = b.peek(0x100, 0x600)
            [(_, _, kept)] = boots(b)
            return kept, ram

    a, ram_a = after_power(7)
    again, ram_again = after_power(7)
    other, ram_other = after_power(8)
    assert a == again and ram_a == ram_again
    assert a != other and ram_a != ram_other
    # pseudo-random, not a fill: most of the 256 byte values occur
    assert len(set(ram_a)) > 200


def test_a_watchdog_reset_restarts_the_watchdog(tmp_path_factory):
    """As on the part: after a watchdog reset the watchdog runs at 16 ms
    with WDRF set; a firmware that clears MCUSR but leaves the watchdog on
    resets again and again (each time with WDRF)."""
    elf = _build(tmp_path_factory, "forgetful", "-DKEEP_WATCHDOG")
    with SimBoard(elf, "uno", sim_limit=10, wall_limit=30) as b:
        assert boots(b, 0.05) == [(1, 0x01, "00" * 8)]  # no watchdog running after a power-on
        b.reset("watchdog")
        seen = boots(b, 0.1)
        assert len(seen) >= 5 and {m for _, m, _ in seen} == {0x08}
        assert [n for n, _, _ in seen] == list(range(2, 2 + len(seen)))  # SRAM kept through each


def test_an_unknown_cause_is_refused(probe):
    with SimBoard(probe, "uno", sim_limit=10, wall_limit=30) as b:
        with pytest.raises(ValueError, match="brownout, watchdog, external, power"):
            b.reset("lightning")
        with pytest.raises(SimError, match=r"usage: reset \[brownout\|watchdog\|external\|power\]"):
            b.command("reset lightning")
        with pytest.raises(SimError, match="usage: reset"):
            b.command("reset power now")
