"""The serial buses' own pins on a board: the SPI bus (MOSI, MISO, SCK),
which the flight recorder's flash (logcheck.py) and the sensor parts
(sensors.py) share, and the I2C (TWI) bus (SDA, SCL) of the sensor parts.
A board file maps its pins to the MCU's ports (`arduino.ports`); a board
without that map (native) takes the Uno's pins."""

from __future__ import annotations

# (MOSI, MISO, SCK) by MCU, as port and bit
SPI_BUS = {"atmega328p": (("B", 3), ("B", 4), ("B", 5)), "atmega2560": (("B", 2), ("B", 3), ("B", 1))}
SPI_BUS_UNO_PINS = {11: "MOSI", 12: "MISO", 13: "SCK"}
# The SPI's SS by MCU: as master the runtime makes it an output and drives
# it high (psl_arduino.cpp spi_bus_begin) as the log or the parts begin,
# before the channels are set up, so only a chip select may have it
SPI_SS = {"atmega328p": ("B", 2), "atmega2560": ("B", 0)}
SPI_SS_UNO_PIN = 10
# (SDA, SCL) by MCU, as port and bit
I2C_BUS = {"atmega328p": (("C", 4), ("C", 5)), "atmega2560": (("D", 1), ("D", 0))}
I2C_BUS_UNO_PINS = {18: "SDA", 19: "SCL"}


def _pins(board, bus, uno: dict[int, str], names: tuple[str, ...]) -> dict[int, str]:
    if bus is None or not board.ports:
        return dict(uno)
    by_port = {pb: pin for pin, pb in board.ports.items()}
    return {by_port[pb]: name for pb, name in zip(bus, names) if pb in by_port}


def spi_bus(board) -> dict[int, str]:
    """The board's SPI bus pins: pin -> MOSI / MISO / SCK."""
    return _pins(board, SPI_BUS.get(board.mcu), SPI_BUS_UNO_PINS, ("MOSI", "MISO", "SCK"))


def i2c_bus(board) -> dict[int, str]:
    """The board's I2C bus pins: pin -> SDA / SCL."""
    return _pins(board, I2C_BUS.get(board.mcu), I2C_BUS_UNO_PINS, ("SDA", "SCL"))


def spi_ss(board) -> int | None:
    """The board's SPI SS pin, which an SPI master drives."""
    pb = SPI_SS.get(board.mcu)
    if pb is None or not board.ports:
        return SPI_SS_UNO_PIN
    return next((pin for pin, p in board.ports.items() if p == pb), None)


def spi_channel_problem(board, channels) -> tuple[object, str] | None:
    """(channel, why) for the first channel on a pin the SPI bus, once in
    use, takes: MOSI, MISO or SCK (the bus drives or samples them), or SS
    (driven high at boot: an input there reads the MCU's own output, an
    output, a pyro channel's first of all, goes high at boot). None when
    there is none."""
    bus = spi_bus(board)
    ss = spi_ss(board)
    for c in channels:
        if c.pin_number in bus:
            return c, f"the SPI bus's {bus[c.pin_number]}"
        if c.pin_number == ss:
            return c, SS_WHY
    return None


SS_WHY = ("the SPI's SS, which the firmware drives high at boot, before the channels are set up, as the bus's "
          "master must (an input there would read the MCU's own output, an output would go high at boot); only a "
          "chip select may have it")
