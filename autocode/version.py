"""The kit's version: the single source of truth for the Python package,
the firmware runtime's version handshake and the library manifests."""

__version__ = "0.1.0"
