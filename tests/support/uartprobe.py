"""A test sketch's line protocol on a SimBoard's UART0 (tests/sim's probes:
spiflash_probe, twi_probe): lines read as simulated time advances."""

from __future__ import annotations


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
