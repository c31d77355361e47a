"""The harness as the kit's one simavr program: the `batch` step (what a
co-simulation step did in five commands, in one), its command table, and
the free-run modes the firmware suites and the differential tests run their
ELFs with (`-u stdout`, `-x done|unity`)."""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import subprocess

import pytest

from conftest import ROOT
from support.simfw import c_elf, halt_uno, probe_uno, spin_uno, tank_uno  # noqa: F401,F811

from fswkit.sim.board import Batch, SimBoard, SimError, harness

pytestmark = pytest.mark.skipif(
    shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
    reason="gcc-avr and libsimavr-dev are needed (make setup)")

MS = 16000  # cycles per millisecond at 16 MHz

# A bare program that prints TEXT on UART0 (2 Mbaud), then stops itself; the
# padding leaves while the text's last byte is on the wire.
PRINT_C = r"""
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
static void put(const char* s) {
    for (; *s; ++s) {
        while ((UCSR0A & (1 << UDRE0)) == 0) {}
        UDR0 = *s;
    }
}
int main(void) {
    UBRR0 = 0;
    UCSR0A = 1 << U2X0;
    UCSR0B = 1 << TXEN0;
    UCSR0C = 3 << UCSZ00;
    put(TEXT);
    put("\n\n\n");
    cli();
    sleep_enable();
    sleep_cpu();
    for (;;) {}
}
"""


def _print_elf(name: str, text: str) -> str:
    return c_elf(name, PRINT_C.replace("TEXT", '"' + text.replace("\n", "\\n") + '"'))


# ---- batch ------------------------------------------------------------------------------

def _steps_one_command_at_a_time(b: SimBoard, plan) -> list[Batch]:
    out = []
    for until, analog, digital in plan:
        for pin, volts in analog.items():
            b.set_analog(pin, volts)
        for pin, level in digital.items():
            b.set_digital(pin, level)
        r = b.until(until)
        out.append(Batch(r, b.edges(), b.uart_read()))
    return out


def test_batch_is_the_five_commands_of_a_step_in_one(probe_uno):
    """Pin 8 mirrors input pin 7 and the UART says hello: a batch step gives
    the same run results, edges (to the cycle) and bytes as setting the
    inputs, `until`, `edges` and `uart` one command at a time."""
    plan = [(k * MS, {"A0": 1.0 + k / 10}, {7: bool(k % 3)}) for k in range(1, 40)]
    results = []
    for one_by_one in (False, True):
        with SimBoard(probe_uno, "uno", sim_limit=5, wall_limit=30) as b:
            b.watch(8)
            if one_by_one:
                results.append(_steps_one_command_at_a_time(b, plan))
            else:
                results.append([b.batch(until, analog, digital) for until, analog, digital in plan])
            # at the target or at most one instruction past it (docs/sim.md: the board stops between
            # instructions; the longest takes 5 cycles, an interrupt's entry 4 more)
            assert plan[-1][0] <= b.cycle < plan[-1][0] + 9, b.cycle
    batched, single = results
    assert batched == single
    assert b"".join(s.uart for s in batched) == b"probe ready\n"
    edges = [e for s in batched for e in s.edges]
    assert len(edges) > 20 and all(e.pin == 8 for e in edges)
    assert all(s.run.stop == "target" for s in batched)


def test_batch_drives_the_tank_valve(tank_uno):
    with SimBoard(tank_uno, "uno", analog={"A0": 3.0}, sim_limit=5, wall_limit=30) as b:
        b.watch(4)
        s = b.batch(50 * MS)
        assert s.edges == [] and s.run.cycle >= 50 * MS
        s = b.batch(100 * MS, analog={"A0": 3.7})  # 800 psi: the valve opens within a 10 ms cycle
        assert [(e.pin, e.level) for e in s.edges] == [(4, True)]
        assert 50 * MS < s.edges[0].cycle <= 70 * MS
        assert s.uart  # the tank's telemetry, on the control channel


def test_batch_checks_every_input_before_applying_any(spin_uno):
    with SimBoard(spin_uno, "uno", sim_limit=1) as b:
        for bad in ("batch 100 0=100 Z9=1", "batch 100 16=5", "batch 100 D8=1", "batch 100 D2=2", "batch x",
                    "batch 100 0=2000000", "batch 100 D2"):
            with pytest.raises(SimError, match="usage: batch"):
                b.command(bad)
        assert b.info()["cycle"] == "0"  # nothing ran
        assert b.batch(0).run.stop == "target"


def test_the_command_table(spin_uno):
    with SimBoard(spin_uno, "uno", sim_limit=1) as b:
        with pytest.raises(SimError) as e:
            b.command("bogus")
        names = re.search(r"\((.*)\)", str(e.value)).group(1).split()
        assert names == ["info", "step", "until", "go", "batch", "adc", "din", "ports", "watch", "edges", "uart",
                         "send", "peek", "stop", "reset", "prof", "eeprom", "flash", "sched", "part", "batch?", "guard",
                         "quit"]
        with pytest.raises(SimError, match="more than 64 words"):
            b.command("info" + " x" * 64)
        assert b.info()["mcu"] == "atmega328p"
    # docs/sim.md has a row for every command
    doc = (ROOT / "docs" / "sim.md").read_text()
    for name in names:
        assert re.search(r"^\| `" + re.escape(name) + r"[ `]", doc, re.M), name


def test_co_simulation_speaks_through_simboard_only():
    src = (ROOT / "host-tools" / "fswkit" / "plant" / "cosim.py").read_text()
    assert ".command(" not in src and ".exchange(" not in src
    assert not re.search(r"[\"'](until|step|adc|din|watch|batch) |[\"'](edges|uart|ports)[\"']", src)


# ---- free runs --------------------------------------------------------------------------

def _free(*args: str, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([harness(), *args], capture_output=True, timeout=60, **kw)


def test_uart_to_standard_output_reads_nothing(probe_uno):
    r = _free("-u", "stdout", "-t", "0.05", probe_uno, input=b"not for the board")
    assert r.returncode == 0, r.stderr
    assert r.stdout == b"probe ready\n"


def test_exit_status_done(halt_uno, spin_uno):
    assert _free("-x", "done", halt_uno).returncode == 0
    r = _free("-x", "done", "-t", "0.01", spin_uno)
    assert r.returncode == 3 and b"stopped (sim-limit)" in r.stderr
    assert _free("-t", "0.01", spin_uno).returncode == 0  # -x crash, the default


@pytest.mark.parametrize("text,status", [
    ("== suite\n12 passed, 0 failed", 0),
    ("3 passed, 1 failed", 1),
    ("0 passed, 0 failed", 1),
    ("1 passed, 1 failed\n2 passed, 0 failed", 0),  # the last summary counts
    ("2 passed, 0 failed\n1 passed, 1 failed", 1),
    ("2 passed, 0 failed tail", 1),  # not a summary line
    ("no summary", 1),
])
def test_exit_status_unity(text, status):
    elf = _print_elf("unity-" + hashlib.sha256(text.encode()).hexdigest()[:10], text)
    r = _free("-u", "stdout", "-x", "unity", "-t", "1", elf)
    assert r.returncode == status, r.stderr
    assert r.stdout.decode().startswith(text)
    if "passed" not in text:
        assert b'no "N passed, N failed" line' in r.stderr


def test_free_run_options_are_checked(spin_uno):
    assert _free("-x", "maybe", spin_uno).returncode == 2
    assert _free("-c", "-x", "done", spin_uno).returncode == 2
    assert _free("-c", "-u", "stdout", spin_uno).returncode == 2
