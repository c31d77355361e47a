"""A test sketch's build and its line protocol on a SimBoard's UART0
(tests/sim's probes: spiflash_probe, twi_probe): lines read as simulated
time advances."""

from __future__ import annotations

import subprocess
from pathlib import Path


def build_probe(source: Path, out_dir: Path) -> str:
    """A probe sketch compiled for the simulated Uno (avr-gcc, warnings as
    errors); the ELF's path."""
    elf = out_dir / "probe.elf"
    r = subprocess.run(["avr-gcc", "-mmcu=atmega328p", "-DF_CPU=16000000UL", "-Os", "-Wall", "-Wextra", "-Werror",
                        "-o", str(elf), str(source)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return str(elf)


class UartProbe:
    """Reads the probe's lines, stepping the board's simulated clock."""

    def __init__(self, board):
        self.b = board
        self.buf = b""

    def line(self, limit_s: float = 2.0, step_s: float = 0.002) -> str:
        deadline = self.b.cycle + self.b.cycles_for(limit_s)
        while b"\n" not in self.buf:
            assert self.b.cycle < deadline, f"no line from the probe in {limit_s} s: {self.buf!r}"
            self.b.step(self.b.cycles_for(step_s))
            self.buf += self.b.uart_read()
        line, self.buf = self.buf.split(b"\n", 1)
        return line.decode()
