"""The serial buses' own pins on a board: the SPI bus (MOSI, MISO, SCK),
which the flight recorder's flash (logcheck.py) and the sensor parts
(sensors.py) share, and the I2C (TWI) bus (SDA, SCL) of the sensor parts.
A board file maps its pins to the MCU's ports (`arduino.ports`); a board
without that map (native) takes the Uno's pins."""

from __future__ import annotations

# (MOSI, MISO, SCK) by MCU, as port and bit
SPI_BUS = {"atmega328p": (("B", 3), ("B", 4), ("B", 5)), "atmega2560": (("B", 2), ("B", 3), ("B", 1))}
SPI_BUS_UNO_PINS = {11: "MOSI", 12: "MISO", 13: "SCK"}
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
