"""Opening the serial port (pyserial): a device (/dev/ttyACM0, a pty) or a
pyserial URL (socket://host:port, loop://)."""

from __future__ import annotations


class PortError(Exception):
    pass


def open_port(name: str, baud: int):
    try:
        import serial
    except ImportError:
        raise PortError("pyserial is not installed: run `make setup` (or pip install pyserial)") from None
    try:
        return serial.serial_for_url(name, baudrate=baud, timeout=0.05, write_timeout=2)
    except (serial.SerialException, ValueError, OSError) as e:
        raise PortError(f"cannot open {name}: {e}") from None


def port_errors():
    """The exceptions a port raises when it goes away (a yanked cable)."""
    import serial

    return (serial.SerialException, OSError)
