"""fswkit: flight software kit for Arduino-class microcontrollers."""

from fswkit.version import __version__

__all__ = ["__version__"]
