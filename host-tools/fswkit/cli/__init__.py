"""The `fsw` command line: thin commands over the rooms. `main` (cli/main.py)
parses and dispatches; each command module parses nothing more and calls
into its room: front.py (check, test, graph, skeleton, gen), target.py
(build, flash, ports), sim.py (sim), ground.py (monitor, cmd, log2csv,
replay, plot), new.py (new)."""

from fswkit.cli.main import main

__all__ = ["main"]
