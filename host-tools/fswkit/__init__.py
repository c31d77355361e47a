"""fswkit: flight software kit for Arduino-class microcontrollers."""

from fswkit.autocode.version import __version__

__all__ = ["__version__"]
