"""Fewer runs of Python's cyclic garbage collector while the front end
reads configs.

Lexing, parsing and checking make many small objects (tokens, syntax and
model nodes) that live on and hold hardly any cycles. At the collector's
default thresholds (a young collection every 700 allocations, an older one
every 10 of those) a long config has the collector walk that growing heap,
and every object the process already holds, again and again: about half
the CPU of reading a 40,000-line machine inside a test process, for
nothing found. `fewer_collections` sets a young collection every 100,000
allocations for as long as it is entered (`fsw` runs each of its
commands in it too), then puts the caller's thresholds back. Collections still
run, and an explicit `gc.collect()` is untouched: only how often the
collector looks changes, never what a load returns or reports.

Re-entrant and safe across threads: the thresholds are set when the first
reader enters and restored when the last one leaves; thresholds that are
already as high (a command of `fsw`) are left alone."""

from __future__ import annotations

import gc
import threading
from contextlib import contextmanager

THRESHOLDS = (100_000, 50, 100)

_lock = threading.Lock()
_depth = 0
_saved: tuple[int, ...] | None = None


@contextmanager
def fewer_collections():
    global _depth, _saved
    with _lock:
        if _depth == 0:
            current = gc.get_threshold()
            _saved = current if current[0] < THRESHOLDS[0] else None
            if _saved is not None:
                gc.set_threshold(*THRESHOLDS)
        _depth += 1
    try:
        yield
    finally:
        with _lock:
            _depth -= 1
            if _depth == 0 and _saved is not None:
                gc.set_threshold(*_saved)
                _saved = None
