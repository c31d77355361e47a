"""Sensor tapes: real flights as `time_s,pressure_pa,accel_g` (fswkit sensor
tape v1, docs/tapes.md). tape.py reads, checks and writes a tape and reads
its `.truth.toml`; formats.py converts the logs of commercial altimeters
(AltOS, CATS, Featherweight Raven, Eggtimer, Missile Works RRC3) into tapes.
Every malformed input is a TapeError carrying located messages
(`PATH:LINE:COL: message`)."""

from fswkit.tape.tape import (COLUMNS, MAGIC, MAX_TAPE, Tape, TapeError, Truth, format_tape,
                              isa_altitude, isa_pressure, parse_tape, read_tape, read_truth,
                              truth_path, write_tape)

__all__ = ["COLUMNS", "MAGIC", "MAX_TAPE", "Tape", "TapeError", "Truth", "format_tape", "isa_altitude",
           "isa_pressure", "parse_tape", "read_tape", "read_truth", "truth_path", "write_tape"]
